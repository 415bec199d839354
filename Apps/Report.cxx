#include "Report.h"

#include "CommandLine.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkStringArray.h"
#include "vtkType.h"

#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <cmath>
#include <fstream>
#include <iomanip>
#include <set>
#include <sstream>
#include <stdexcept>

namespace mlr::cli
{

namespace
{
double value(vtkFieldData* data, const char* name)
{
  vtkDataArray* array = data ? data->GetArray(name) : nullptr;
  return array && array->GetNumberOfTuples() > 0 ? array->GetComponent(0, 0) : 0.0;
}

std::string millions(double count)
{
  std::ostringstream s;
  s << std::fixed << std::setprecision(count >= 1e7 ? 1 : 2) << count / 1e6 << " M";
  return s.str();
}

std::string seconds(double s)
{
  std::ostringstream out;
  out << std::fixed << std::setprecision(s >= 10 ? 1 : 2) << s << " s";
  return out.str();
}

/// A number, or null for NaN and infinities (JSON has none); integers stay integers.
nlohmann::ordered_json jsonNumber(double x, bool integral = false)
{
  if (!std::isfinite(x))
  {
    return nullptr;
  }
  if (integral)
  {
    return static_cast<long long>(x);
  }
  return x;
}

nlohmann::ordered_json jsonTriple(const double* v)
{
  return { jsonNumber(v[0]), jsonNumber(v[1]), jsonNumber(v[2]) };
}
}

std::string summaryLine(vtkFieldData* statistics)
{
  const double rays = value(statistics, "ShootingRays") + value(statistics, "ShadowRays") +
    value(statistics, "GatheringRays");
  std::ostringstream s;
  s << value(statistics, "Frames") << " frames, " << value(statistics, "Elements") << " elements ("
    << value(statistics, "Patches") << " patches), " << value(statistics, "PathsPerFrame")
    << " paths/frame, " << millions(rays) << " rays ("
    << millions(value(statistics, "ShootingRays")) << " shooting, "
    << millions(value(statistics, "ShadowRays")) << " shadow, "
    << millions(value(statistics, "GatheringRays")) << " gathering), "
    << seconds(value(statistics, "SecondsTotal")) << " (remeshing "
    << seconds(value(statistics, "SecondsRemeshing")) << ", shooting "
    << seconds(value(statistics, "SecondsShooting")) << ", gathering "
    << seconds(value(statistics, "SecondsGathering")) << "), predicted speed-up of reuse "
    << std::fixed << std::setprecision(1) << value(statistics, "PredictedSpeedup") << "x";
  if (statistics && statistics->GetArray("SensorGatheringRays"))
  {
    s << "; sensors " << millions(value(statistics, "SensorShadowRays")) << " shadow, "
      << millions(value(statistics, "SensorGatheringRays")) << " gathering rays, "
      << seconds(value(statistics, "SecondsSensors"));
  }
  return s.str();
}

std::string errorLine(vtkFieldData* statistics)
{
  vtkDataArray* p95 = statistics ? statistics->GetArray("RelativeErrorP95") : nullptr;
  vtkDataArray* median = statistics ? statistics->GetArray("RelativeErrorMedian") : nullptr;
  auto* stoppedBy =
    statistics ? vtkStringArray::SafeDownCast(statistics->GetAbstractArray("StoppedBy")) : nullptr;
  if (!p95 || !median || !stoppedBy || p95->GetNumberOfTuples() == 0 ||
    median->GetNumberOfTuples() != p95->GetNumberOfTuples() || stoppedBy->GetNumberOfValues() == 0)
  {
    return {};
  }
  vtkIdType worst = 0;
  for (vtkIdType f = 1; f < p95->GetNumberOfTuples(); ++f)
  {
    worst = p95->GetComponent(f, 0) > p95->GetComponent(worst, 0) ? f : worst;
  }
  double medianOfWorst = median->GetComponent(worst, 0);
  const auto rounds = static_cast<long long>(value(statistics, "ErrorRounds"));
  std::ostringstream s;
  s << std::setprecision(3) << "relative error of the lit elements: median " << 100 * medianOfWorst
    << "%, p95 " << 100 * p95->GetComponent(worst, 0) << "% (frame " << worst << ", the worst)";
  const double target = value(statistics, "TargetRelativeError");
  if (target > 0)
  {
    s << ", target " << 100 * target << "%";
  }
  s << ", " << static_cast<long long>(value(statistics, "ErrorBatches")) << " batches in " << rounds
    << (rounds == 1 ? " round" : " rounds") << ", stopped by " << stoppedBy->GetValue(0);
  return s.str();
}

void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics, const std::vector<FrameRecord>& frames,
  const StageTimes& stages)
{
  const std::string builtIn = "built-in Cornell box";
  nlohmann::ordered_json json;
  json["scene"] = options.scene.empty() ? builtIn : options.scene;
  // What lit the scene: a light file, a material of the scene, the sun, or the scene's own
  // emissive surfaces.
  json["light"] = !options.light.empty() ? options.light
    : options.lightMaterial              ? "material " + *options.lightMaterial
    : options.usesSun()                  ? std::string("sun")
    : options.sceneLightsItself()        ? std::string("scene emission")
                                         : builtIn;
  json["trajectory"] = !options.trajectory.empty()
    ? options.trajectory
    : (options.from                        ? "straight line"
          : options.sunPath                ? "sun path"
          : !options.weather.empty()       ? "weather " + options.weather
          : !options.sunDirections.empty() ? options.sunDirections
                                           : (options.scene.empty() ? builtIn : ""));
  if (options.sky)
  {
    json["sky"] = *options.sky;
  }
  json["output"] = options.output;
  json["settings"] = {
    { "lightPower", jsonTriple(filter->GetLightPower()) },
    { "paths", filter->GetNumberOfPaths() },
    { "gatherRatio", jsonNumber(filter->GetGatheringRatio()) },
    { "survival", jsonNumber(filter->GetFirstBounceSurvival()) },
    { "reuseShooting", filter->GetReuseShooting() != 0 },
    { "balanceFrames", filter->GetBalanceFrames() != 0 },
    { "reuseGathering", filter->GetReuseGathering() != 0 },
    { "patchSize", jsonNumber(filter->GetPatchSize()) },
    { "seed", filter->GetSeed() },
    { "threads", filter->GetNumberOfThreads() },
    { "twoSided", filter->GetTwoSided() != 0 },
    { "errorBatches", filter->GetErrorBatches() },
    { "targetError", jsonNumber(filter->GetTargetRelativeError()) },
    { "timeLimit", jsonNumber(filter->GetTimeLimit()) },
    { "framesPerChunk", filter->GetFramesPerChunk() },
  };

  // Every statistic the filter reports, except those that describe one frame.
  static const std::set<std::string> perFrame = { "FrameIndex", "LightPosition", "LightTranslation",
    "SolveCount", "TimeValue" };
  nlohmann::ordered_json values = nlohmann::ordered_json::object();
  for (int i = 0; statistics && i < statistics->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* array = statistics->GetAbstractArray(i);
    if (!array || !array->GetName() || perFrame.count(array->GetName()) ||
      array->GetNumberOfTuples() != 1 || array->GetNumberOfComponents() != 1)
    {
      continue;
    }
    nlohmann::ordered_json& value = values[array->GetName()];
    if (auto* strings = vtkStringArray::SafeDownCast(array))
    {
      value = strings->GetValue(0);
    }
    else if (auto* numbers = vtkDataArray::SafeDownCast(array))
    {
      const int type = numbers->GetDataType();
      value = jsonNumber(numbers->GetComponent(0, 0), type != VTK_FLOAT && type != VTK_DOUBLE);
    }
  }
  json["statistics"] = values;
  // The error estimate's figures per frame.
  for (const char* name : { "RelativeErrorMedian", "RelativeErrorP95", "LitElements" })
  {
    if (vtkDataArray* array = statistics ? statistics->GetArray(name) : nullptr)
    {
      nlohmann::ordered_json perFrameValues = nlohmann::ordered_json::array();
      for (vtkIdType f = 0; f < array->GetNumberOfTuples(); ++f)
      {
        perFrameValues.push_back(jsonNumber(array->GetComponent(f, 0),
          array->GetDataType() != VTK_FLOAT && array->GetDataType() != VTK_DOUBLE));
      }
      json["errorEstimate"][name] = perFrameValues;
    }
  }
  json["timing"] = {
    { "secondsReading", jsonNumber(stages.reading) },
    { "secondsRemeshing", jsonNumber(stages.remeshing) },
    { "secondsSolving", jsonNumber(stages.solving) },
    { "secondsWriting", jsonNumber(stages.writing) },
    { "secondsRendering", jsonNumber(stages.rendering) },
    { "secondsTotal", jsonNumber(stages.total) },
  };
  // The peak resident memory of this process (the solve runs here; reading in a child).
  struct rusage usage = {};
  getrusage(RUSAGE_SELF, &usage);
  json["memory"] = { { "peakResidentBytes", jsonNumber(1024.0 * usage.ru_maxrss, true) } };

  nlohmann::ordered_json records = nlohmann::ordered_json::array();
  for (const FrameRecord& frame : frames)
  {
    nlohmann::ordered_json record = { { "time", jsonNumber(frame.time) }, { "file", frame.file } };
    if (!frame.picture.empty())
    {
      record["picture"] = frame.picture;
    }
    record["lightPosition"] = jsonTriple(frame.lightPosition.data());
    records.push_back(record);
  }
  json["frames"] = records;

  std::ofstream out(path);
  // File names need not be UTF-8: bytes that are not are replaced, not an exception.
  out << json.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  out.close();
  if (!out)
  {
    throw std::runtime_error("cannot write the statistics file '" + path.string() + "'");
  }
}

} // namespace mlr::cli
