// What a run did: the one-line summary and the JSON statistics file.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

class vtkFieldData;
class vtkMovingLightRadiosity;

namespace mlr::cli
{

struct Options;

/// One frame of the written series.
struct FrameRecord
{
  double time = 0;
  std::string file;    ///< the .vtu, as named in the .pvd
  std::string picture; ///< the .png, or empty
  std::array<double, 3> lightPosition{};
};

/// "30 frames, 12912 elements (3228 patches), 600000 paths/frame, 15.3 M rays (...), 1.16 s
/// (...), predicted speed-up of reuse 2.4x" from the filter's statistics field data.
std::string summaryLine(vtkFieldData* statistics);

/// Writes the inputs, the filter's settings, the statistics and the frames as JSON.
/// Throws std::runtime_error.
void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics,
  const std::vector<FrameRecord>& frames);

} // namespace mlr::cli
