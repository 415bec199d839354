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

/// Wall-clock seconds of the stages of a run.
struct StageTimes
{
  double reading = 0;   ///< reading and checking the input files
  double remeshing = 0; ///< the filter's remeshing of the scene
  double solving = 0;   ///< the rest of the filter's first update: the solve of all frames
  double writing = 0;   ///< converting and writing the .vtu frames and the .pvd
  double rendering = 0; ///< the pictures of --png
  double total = 0;     ///< from the start until the statistics are written
};

/// "30 frames, 12912 elements (3228 patches), 600000 paths/frame, 15.3 M rays (...), 1.16 s
/// (...), predicted speed-up of reuse 2.4x" from the filter's statistics field data.
std::string summaryLine(vtkFieldData* statistics);

/// "relative error of the lit elements: median 0.81%, p95 2.3% (frame 4), 16 batches in 1
/// round, stopped by batches": the worst frame's figures, from the error estimate's field data;
/// empty without an error estimate.
std::string errorLine(vtkFieldData* statistics);

/// Writes the inputs, the filter's settings, the statistics, the stages' times and the frames
/// as JSON.
/// Throws std::runtime_error.
void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics, const std::vector<FrameRecord>& frames,
  const StageTimes& stages);

} // namespace mlr::cli
