#include "Report.h"

#include "CommandLine.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkStringArray.h"

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

std::string jsonString(const std::string& text)
{
  std::ostringstream out;
  out << '"';
  for (unsigned char c : text)
  {
    if (c == '"' || c == '\\')
    {
      out << '\\' << c;
    }
    else if (c < 0x20)
    {
      out << "\\u" << std::hex << std::setw(4) << std::setfill('0') << int(c) << std::dec;
    }
    else
    {
      out << c;
    }
  }
  out << '"';
  return out.str();
}

std::string jsonNumber(double x)
{
  if (!std::isfinite(x))
  {
    return "null";
  }
  std::ostringstream out;
  out << std::setprecision(12) << x;
  return out.str();
}

std::string jsonTriple(const double* v)
{
  return "[" + jsonNumber(v[0]) + ", " + jsonNumber(v[1]) + ", " + jsonNumber(v[2]) + "]";
}
}

std::string summaryLine(vtkFieldData* statistics)
{
  const double rays = value(statistics, "ShootingRays") + value(statistics, "ShadowRays") +
    value(statistics, "GatheringRays");
  std::ostringstream s;
  s << value(statistics, "Frames") << " frames, " << value(statistics, "Elements")
    << " elements (" << value(statistics, "Patches") << " patches), "
    << value(statistics, "PathsPerFrame") << " paths/frame, " << millions(rays) << " rays ("
    << millions(value(statistics, "ShootingRays")) << " shooting, "
    << millions(value(statistics, "ShadowRays")) << " shadow, "
    << millions(value(statistics, "GatheringRays")) << " gathering), "
    << seconds(value(statistics, "SecondsTotal")) << " (remeshing "
    << seconds(value(statistics, "SecondsRemeshing")) << ", shooting "
    << seconds(value(statistics, "SecondsShooting")) << ", gathering "
    << seconds(value(statistics, "SecondsGathering")) << "), predicted speed-up of reuse "
    << std::fixed << std::setprecision(1) << value(statistics, "PredictedSpeedup") << "x";
  return s.str();
}

void writeStatisticsJson(const std::filesystem::path& path, const Options& options,
  vtkMovingLightRadiosity* filter, vtkFieldData* statistics,
  const std::vector<FrameRecord>& frames)
{
  const std::string builtIn = "built-in Cornell box";
  std::ofstream out(path);
  out << "{\n";
  out << "  \"scene\": " << jsonString(options.scene.empty() ? builtIn : options.scene) << ",\n";
  out << "  \"light\": " << jsonString(options.light.empty() ? builtIn : options.light) << ",\n";
  out << "  \"trajectory\": "
      << jsonString(!options.trajectory.empty()
             ? options.trajectory
             : (options.from ? "straight line" : (options.scene.empty() ? builtIn : "")))
      << ",\n";
  out << "  \"output\": " << jsonString(options.output) << ",\n";
  out << "  \"settings\": {\n"
      << "    \"lightPower\": " << jsonTriple(filter->GetLightPower()) << ",\n"
      << "    \"paths\": " << filter->GetNumberOfPaths() << ",\n"
      << "    \"gatherRatio\": " << jsonNumber(filter->GetGatheringRatio()) << ",\n"
      << "    \"survival\": " << jsonNumber(filter->GetFirstBounceSurvival()) << ",\n"
      << "    \"reuseShooting\": " << (filter->GetReuseShooting() ? "true" : "false") << ",\n"
      << "    \"reuseGathering\": " << (filter->GetReuseGathering() ? "true" : "false") << ",\n"
      << "    \"patchSize\": " << jsonNumber(filter->GetPatchSize()) << ",\n"
      << "    \"seed\": " << filter->GetSeed() << ",\n"
      << "    \"threads\": " << filter->GetNumberOfThreads() << ",\n"
      << "    \"twoSided\": " << (filter->GetTwoSided() ? "true" : "false") << "\n"
      << "  },\n";

  // Every statistic the filter reports, except those that describe one frame.
  static const std::set<std::string> perFrame = { "FrameIndex", "LightPosition",
    "LightTranslation", "SolveCount", "TimeValue" };
  out << "  \"statistics\": {";
  const char* separator = "\n";
  for (int i = 0; statistics && i < statistics->GetNumberOfArrays(); ++i)
  {
    vtkAbstractArray* array = statistics->GetAbstractArray(i);
    if (!array || !array->GetName() || perFrame.count(array->GetName()) ||
      array->GetNumberOfTuples() != 1 || array->GetNumberOfComponents() != 1)
    {
      continue;
    }
    out << separator << "    " << jsonString(array->GetName()) << ": ";
    if (auto* strings = vtkStringArray::SafeDownCast(array))
    {
      out << jsonString(strings->GetValue(0));
    }
    else if (auto* numbers = vtkDataArray::SafeDownCast(array))
    {
      out << jsonNumber(numbers->GetComponent(0, 0));
    }
    else
    {
      out << "null";
    }
    separator = ",\n";
  }
  out << "\n  },\n";

  out << "  \"frames\": [";
  separator = "\n";
  for (const FrameRecord& frame : frames)
  {
    out << separator << "    {\"time\": " << jsonNumber(frame.time)
        << ", \"file\": " << jsonString(frame.file);
    if (!frame.picture.empty())
    {
      out << ", \"picture\": " << jsonString(frame.picture);
    }
    out << ", \"lightPosition\": " << jsonTriple(frame.lightPosition.data()) << "}";
    separator = ",\n";
  }
  out << "\n  ]\n}\n";
  out.close();
  if (!out)
  {
    throw std::runtime_error("cannot write the statistics file '" + path.string() + "'");
  }
}

} // namespace mlr::cli
