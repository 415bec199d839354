// What a run did: the one-line summary and the JSON statistics file.
#pragma once

#include "vtkSmartPointer.h"
#include "vtkType.h"

#include <array>
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

class vtkFieldData;
class vtkMovingLightRadiosity;
class vtkPolyData;

namespace mlr::cli
{

struct Options;

/// One frame of the written series.
struct FrameRecord
{
  double time = 0;
  std::string file;                      ///< the .vtu, as named in the .pvd
  std::string picture;                   ///< the .png, or empty
  std::array<double, 3> lightPosition{}; ///< field data LightPosition: the first light's
  std::array<double, 3> sunDirection{};  ///< field data SunDirection, towards the sun
  double luminousEfficacy = 0;           ///< field data LuminousEfficacy, lm/W
  std::array<double, 3> lightPower{};    ///< field data LightPower: every light's, W per channel
  double lightLuminousFlux = 0;          ///< field data LightLuminousFlux, lm
};

/// Wall-clock seconds of the stages of a run.
struct StageTimes
{
  double reading = 0;   ///< reading and checking the input files
  double remeshing = 0; ///< the filter's remeshing of the scene
  double solving = 0;   ///< the rest of the filter's first update: the solve of all frames
  double writing = 0;   ///< converting and writing the .vtu frames and the .pvd
  double rendering = 0; ///< the pictures of --png
  double total = 0;     ///< from the start until the statistics are written (the renames after
                        ///< them take milliseconds): printed and in --stats alike
};

/// "30 frames, 12912 elements (3228 patches), 600000 paths/frame, 15.3 M rays (...), solve
/// 1.16 s (...), predicted speed-up of reuse 2.4x" from the filter's statistics field data:
/// the solve alone (timeLine() gives the whole run).
std::string summaryLine(vtkFieldData* statistics);

/// "33.6 s in all: reading 0.02 s, remeshing 0.05 s, solving 11.2 s, writing 22.3 s": the
/// run from its start to its statistics, and its stages (secondsTotal and the others of
/// --stats).
std::string timeLine(const StageTimes& stages);

/// "relative error of the lit elements: median 0.81%, p95 2.3% (frame 4), 16 batches in 1
/// round, stopped by batches": the worst frame's figures, from the error estimate's field data;
/// empty without an error estimate. With sensors, a second line gives theirs ("relative error
/// of the lit sensors: median 0.9%, p95 1.6% (frame 2, the worst)").
std::string errorLine(vtkFieldData* statistics);

/// The filter's Light output in one frame: the lights as solved (area lights' polygons, point
/// lights' vertices), each cell with its Power and LuminousFlux.
struct PosedLight
{
  vtkSmartPointer<vtkPolyData> light; ///< null or empty without area lights
};

/// Writes the inputs, the light as solved, the sensors, the filter's settings, the
/// statistics, the stages' times and the frames as JSON.
/// Throws std::runtime_error.
void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics, const std::vector<FrameRecord>& frames,
  const StageTimes& stages, const PosedLight& posedLight, vtkIdType sensorCount);

} // namespace mlr::cli
