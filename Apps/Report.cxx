#include "Report.h"

#include "CommandLine.h"
#include "SeriesWriter.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"
#include "vtkType.h"

#include <nlohmann/json.hpp>

#include <sys/resource.h>

#include <cmath>
#include <cstdio>
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

/// The per-frame values of a field array: one number per frame (integers stay integers).
nlohmann::ordered_json perFrameJson(vtkDataArray* array)
{
  const bool integral = array->GetDataType() != VTK_FLOAT && array->GetDataType() != VTK_DOUBLE;
  nlohmann::ordered_json values = nlohmann::ordered_json::array();
  for (vtkIdType f = 0; f < array->GetNumberOfTuples(); ++f)
  {
    values.push_back(jsonNumber(array->GetComponent(f, 0), integral));
  }
  return values;
}

nlohmann::ordered_json jsonTriple(const double* v)
{
  return { jsonNumber(v[0]), jsonNumber(v[1]), jsonNumber(v[2]) };
}

/// The frame of the largest p95 relative error (the first on ties) with its median and p95,
/// as the elements' and the sensors' lines both give it.
std::string worstFrameText(const char* what, vtkDataArray* median, vtkDataArray* p95)
{
  vtkIdType worst = 0;
  for (vtkIdType f = 1; f < p95->GetNumberOfTuples(); ++f)
  {
    worst = p95->GetComponent(f, 0) > p95->GetComponent(worst, 0) ? f : worst;
  }
  std::ostringstream s;
  s << std::setprecision(3) << "relative error of the lit " << what << ": median "
    << 100 * median->GetComponent(worst, 0) << "%, p95 " << 100 * p95->GetComponent(worst, 0)
    << "% (frame " << worst << ", the worst)";
  return s.str();
}
}

namespace
{
/// The light as solved: its kind, files and settings, and its power, from the filter's field
/// data per frame (`LightPower`, `LightLuminousFlux`: every light's Power and flux in that
/// frame) and its Light output (whether a luminaire emits from an opening). Nothing is derived
/// here: lumens, a file's flux, TILT factors and the Trajectory's Power are the filter's to
/// apply.
nlohmann::ordered_json lightingJson(const Options& o, vtkMovingLightRadiosity* filter,
  const PosedLight& posed, const std::vector<FrameRecord>& frames)
{
  nlohmann::ordered_json j;
  const bool sky = o.sky.has_value();
  const bool areaKinds = !o.usesSun() && !o.sceneLightsItself() && !o.pointLight;
  j["kind"] = o.usesSun()   ? "sun"
    : sky                   ? "sky"
    : o.sceneLightsItself() ? "scene emission"
    : o.pointLight          ? "point light"
    : o.luminaire           ? "luminaire"
    : o.lightMaterial       ? "material"
                            : "area light";
  if (o.luminaire)
  {
    j["emitsFrom"] = posed.light && posed.light->GetNumberOfPolys() > 0
      ? "the file's luminous opening"
      : "a point (no opening in the file)";
  }
  if (!o.light.empty())
  {
    j["file"] = o.light;
  }
  else if (o.lightMaterial)
  {
    j["material"] = *o.lightMaterial;
  }
  else if (areaKinds && !o.luminaire && o.usesEmbeddedScene())
  {
    j["file"] = "built-in Cornell box light";
  }
  if (!o.lightDistribution.empty())
  {
    j["distributionFile"] = o.lightDistribution;
  }
  if (o.spot)
  {
    j["spot"] = { { "halfAngleDegrees", jsonNumber((*o.spot)[0]) },
      { "softEdgeDegrees", jsonNumber((*o.spot)[1]) } };
  }
  if (o.aim)
  {
    j["aim"] = jsonTriple(o.aim->data());
  }

  if (!o.usesSun() && !sky && !o.sceneLightsItself())
  {
    if (!frames.empty())
    {
      // The brightest frame (the first of equals): a light dimmed, switched off or tilted
      // away in some frames is reported at what it emits at its brightest, and each frame
      // at its own (frames[].powerW).
      std::size_t brightest = 0;
      for (std::size_t f = 1; f < frames.size(); ++f)
      {
        if (frames[f].lightLuminousFlux > frames[brightest].lightLuminousFlux)
        {
          brightest = f;
        }
      }
      j["powerW"] = jsonTriple(frames[brightest].lightPower.data());
      j["powerFrame"] = brightest;
      j["lumens"] = jsonNumber(frames[brightest].lightLuminousFlux);
    }
    j["powerFrom"] = o.lightLumens     ? "--light-lumens"
      : filter->GetLightFluxFromFile() ? "the distribution file's flux"
      : o.lightPower                   ? "--light-power"
      : o.lightMaterial                ? "the material's emission (pi Ke area)"
                                       : "the Light's LightPower cells, else 100 W per channel";
    j["luminousEfficacy"] = jsonNumber(filter->GetLuminousEfficacy());
  }
  else if (!sky && !o.usesSun())
  {
    j["luminousEfficacy"] = jsonNumber(filter->GetLuminousEfficacy());
  }
  else
  {
    j["luminousEfficacy"] = "per frame (frames[].luminousEfficacy): Perez daylight efficacy";
  }

  if (o.usesSun())
  {
    nlohmann::ordered_json sun;
    if (!o.weather.empty())
    {
      const std::array<int, 4> d = o.dates.value_or(std::array<int, 4>{ 1, 1, 12, 31 });
      const std::array<int, 2> h = o.hours.value_or(std::array<int, 2>{ 0, 23 });
      char dates[16];
      std::snprintf(dates, sizeof dates, "%02d-%02d,%02d-%02d", d[0], d[1], d[2], d[3]);
      sun["weather"] = { { "file", o.weather }, { "dates", dates }, { "hours", { h[0], h[1] } },
        { "night", o.night } };
      sun["irradianceWPerM2"] = "per hour: the file's direct normal irradiance";
    }
    else
    {
      if (o.sunPath)
      {
        const SunPathSpec& p = *o.sunPath;
        char date[16];
        std::snprintf(date, sizeof date, "%04d-%02d-%02d", p.year, p.month, p.day);
        sun["path"] = { { "latitude", jsonNumber(p.latitude) },
          { "longitude", jsonNumber(p.longitude) }, { "date", date },
          { "startHour", jsonNumber(p.startHour) }, { "endHour", jsonNumber(p.endHour) },
          { "stepMinutes", jsonNumber(p.stepMinutes) },
          { "timeZone", jsonNumber(o.timeZone.value_or(0.0)) } };
      }
      else
      {
        sun["directionsFile"] = o.sunDirections;
      }
      sun["irradianceWPerM2"] = jsonNumber(filter->GetSunIrradiance());
    }
    const Triple north = o.northDirection();
    sun["north"] = jsonTriple(north.data());
    j["sun"] = sun;
  }
  if (sky)
  {
    nlohmann::ordered_json skyJson = { { "model", *o.sky } };
    if (o.weather.empty())
    {
      skyJson["diffuseHorizontalWPerM2"] = jsonNumber(filter->GetSkyDiffuseHorizontal());
    }
    else
    {
      skyJson["diffuseHorizontalWPerM2"] = "per hour: the file's diffuse horizontal irradiance";
    }
    j["sky"] = skyJson;
  }
  if (o.usesSun() || sky || !o.lightDistribution.empty() || o.workPlane)
  {
    const Triple up = o.zenith();
    j["up"] = jsonTriple(up.data());
  }
  return j;
}
}

std::string summaryLine(vtkFieldData* statistics)
{
  const double rays = value(statistics, "ShootingRays") + value(statistics, "ShadowRays") +
    value(statistics, "GatheringRays");
  // Counts with every digit: a stream shows a double of 1,000,000 as "1e+06".
  const auto count = [&](const char* name)
  { return static_cast<long long>(value(statistics, name)); };
  const long long frames = count("Frames");
  std::ostringstream s;
  s << frames << (frames == 1 ? " frame, " : " frames, ") << count("Elements") << " elements ("
    << count("Patches") << " patches), " << count("PathsPerFrame") << " paths/frame, "
    << millions(rays) << " rays (" << millions(value(statistics, "ShootingRays")) << " shooting, "
    << millions(value(statistics, "ShadowRays")) << " shadow, "
    << millions(value(statistics, "GatheringRays")) << " gathering), solve "
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

std::string timeLine(const StageTimes& stages)
{
  std::ostringstream s;
  s << seconds(stages.total) << " in all: reading " << seconds(stages.reading) << ", remeshing "
    << seconds(stages.remeshing) << ", solving " << seconds(stages.solving) << ", writing "
    << seconds(stages.writing);
  if (stages.rendering > 0)
  {
    s << ", pictures " << seconds(stages.rendering);
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
  const auto rounds = static_cast<long long>(value(statistics, "ErrorRounds"));
  std::ostringstream s;
  s << std::setprecision(3) << worstFrameText("elements", median, p95);
  const double target = value(statistics, "TargetRelativeError");
  if (target > 0)
  {
    s << ", target " << 100 * target << "%";
  }
  s << ", " << static_cast<long long>(value(statistics, "ErrorBatches")) << " batches in " << rounds
    << (rounds == 1 ? " round" : " rounds") << ", stopped by " << stoppedBy->GetValue(0);
  vtkDataArray* sensorP95 = statistics->GetArray("SensorRelativeErrorP95");
  vtkDataArray* sensorMedian = statistics->GetArray("SensorRelativeErrorMedian");
  if (sensorP95 && sensorMedian && sensorP95->GetNumberOfTuples() > 0 &&
    sensorMedian->GetNumberOfTuples() == sensorP95->GetNumberOfTuples())
  {
    s << "\n" << worstFrameText("sensors", sensorMedian, sensorP95);
  }
  return s.str();
}

void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics, const std::vector<FrameRecord>& frames,
  const StageTimes& stages, const PosedLight& posedLight, vtkIdType sensorCount)
{
  const std::string builtIn = "built-in Cornell box";
  nlohmann::ordered_json json;
  json["scene"] = options.scene.empty() ? builtIn : options.scene;
  const nlohmann::ordered_json lighting = lightingJson(options, filter, posedLight, frames);
  // What lit the scene: a light file, a material of the scene, a luminaire, the sun, the sky,
  // or the scene's own emissive surfaces ("lighting" says more).
  const std::string kind = lighting["kind"].get<std::string>();
  json["light"] = !options.light.empty() ? options.light
    : options.lightMaterial              ? "material " + *options.lightMaterial
    : kind == "area light"               ? builtIn
                                         : kind;
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
  json["lighting"] = lighting;
  if (options.usesSensors())
  {
    nlohmann::ordered_json sensors;
    if (!options.sensors.empty())
    {
      sensors["file"] = options.sensors;
    }
    else
    {
      sensors["workPlane"] = { { "height", jsonNumber((*options.workPlane)[0]) },
        { "spacing", jsonNumber((*options.workPlane)[1]) } };
    }
    sensors["count"] = sensorCount;
    sensors["rays"] = filter->GetSensorRays();
    sensors["daylightAutonomyThresholdLx"] = jsonNumber(filter->GetDaylightAutonomyThreshold());
    // Their error estimate's figures per frame, as the elements' (errorEstimate below).
    for (const auto& [name, key] :
      { std::make_pair("SensorRelativeErrorMedian", "relativeErrorMedian"),
        std::make_pair("SensorRelativeErrorP95", "relativeErrorP95"),
        std::make_pair("LitSensors", "litSensors") })
    {
      if (vtkDataArray* array = statistics ? statistics->GetArray(name) : nullptr)
      {
        sensors["errorEstimate"][key] = perFrameJson(array);
      }
    }
    json["sensors"] = sensors;
  }
  json["settings"] = {
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
    { "chunkOverlap", filter->GetChunkOverlap() },
  };
  if (lighting.contains("powerW"))
  {
    // The power solved, not the LightPower property, which lumens, a material or a file's
    // flux replace.
    json["settings"]["lightPower"] = lighting["powerW"];
  }

  // Every statistic the filter reports, except those that describe one frame.
  static const std::set<std::string> perFrame = { "FrameIndex", "LightPosition", "LightTranslation",
    "LightPower", "LightLuminousFlux", "SolveCount", "TimeValue" };
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
      json["errorEstimate"][name] = perFrameJson(array);
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
    // The sun's and the sky's frames have no light position, and a scene's own emission
    // does not move.
    if (options.usesSun())
    {
      record["sunDirection"] = jsonTriple(frame.sunDirection.data());
    }
    else if (!options.sky && !options.sceneLightsItself())
    {
      record["lightPosition"] = jsonTriple(frame.lightPosition.data());
      record["powerW"] = jsonTriple(frame.lightPower.data());
      record["lumens"] = jsonNumber(frame.lightLuminousFlux);
    }
    if (options.sky || options.usesSun())
    {
      record["luminousEfficacy"] = jsonNumber(frame.luminousEfficacy);
    }
    records.push_back(record);
  }
  json["frames"] = records;

  std::ofstream out(path);
  // File names need not be UTF-8: bytes that are not are replaced, not an exception.
  out << json.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  out.close();
  if (!out)
  {
    failedWrite("the statistics file", path);
  }
}

} // namespace mlr::cli
