#include "CommandLine.h"

#include "OutputTransaction.h"
#include "SeriesWriter.h"

#include "vtkMovingLightRadiosity.h"

#include "Chunks.h"
#include "Error.h"
#include "Photometry.h"

#include <vtk_cli11.h>

#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <sstream>
#include <vector>

namespace mlr::cli
{

namespace
{
/// The filter's SkyModel of a --sky name.
int skyModelIndex(const std::string& name)
{
  const char* names[] = { "uniform", "cie-overcast", "cie-clear", "perez" };
  for (int i = 0; i < 4; ++i)
  {
    if (name == names[i])
    {
      return vtkMovingLightRadiosity::UNIFORM_SKY + i;
    }
  }
  throw UsageError("--sky is '" + name + "': give uniform, cie-overcast, cie-clear or perez");
}

std::string lowercase(std::string text)
{
  for (char& c : text)
  {
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  }
  return text;
}

bool endsWith(const std::string& text, const std::string& suffix)
{
  return text.size() >= suffix.size() &&
    lowercase(text.substr(text.size() - suffix.size())) == suffix;
}

double parseNumber(const std::string& option, const std::string& text)
{
  errno = 0;
  char* end = nullptr;
  const double value = std::strtod(text.c_str(), &end);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE || !std::isfinite(value))
  {
    throw UsageError(option + " needs a number, not '" + text + "'");
  }
  return value;
}

long long parseInteger(const std::string& option, const std::string& text)
{
  errno = 0;
  char* end = nullptr;
  const long long value = std::strtoll(text.c_str(), &end, 10);
  if (text.empty() || end != text.c_str() + text.size() || errno == ERANGE)
  {
    throw UsageError(option + " needs a whole number, not '" + text + "'");
  }
  return value;
}

/// The comma-separated fields of text, empty ones included.
std::vector<std::string> split(const std::string& text)
{
  std::vector<std::string> fields(1);
  for (char c : text)
  {
    if (c == ',')
    {
      fields.emplace_back();
    }
    else
    {
      fields.back() += c;
    }
  }
  return fields;
}

/// Three numbers, as `shape` ("X,Y,Z", "R,G,B") names them.
Triple parseThree(const std::string& option, const std::string& text, const std::string& shape)
{
  const std::vector<std::string> fields = split(text);
  if (fields.size() != 3)
  {
    throw UsageError(option + " needs three numbers " + shape + ", not '" + text + "'");
  }
  return { parseNumber(option, fields[0]), parseNumber(option, fields[1]),
    parseNumber(option, fields[2]) };
}

Triple parseTriple(const std::string& option, const std::string& text)
{
  return parseThree(option, text, "X,Y,Z");
}

/// HH:MM (00:00 to 24:00) as hours.
double parseClock(const std::string& option, const std::string& text)
{
  int hours = -1, minutes = -1;
  char colon = 0;
  std::istringstream in(text);
  in >> hours >> colon >> minutes;
  if (!in || colon != ':' || in.peek() != std::char_traits<char>::eof() || hours < 0 ||
    minutes < 0 || minutes > 59 || hours > 24 || (hours == 24 && minutes > 0) || text.size() > 5)
  {
    throw UsageError(option + " has the time '" + text + "': give HH:MM from 00:00 to 24:00");
  }
  return hours + minutes / 60.0;
}

SunPathSpec parseSunPath(const std::string& option, const std::string& text)
{
  const std::vector<std::string> fields = split(text);
  if (fields.size() != 6)
  {
    throw UsageError(option + " is '" + text +
      "': give LAT,LON,YYYY-MM-DD,HH:MM,HH:MM,MINUTES (e.g. 48.85,2.35,2024-06-21,06:00,21:00,15)");
  }
  SunPathSpec spec;
  spec.latitude = parseNumber(option + " (latitude)", fields[0]);
  spec.longitude = parseNumber(option + " (longitude)", fields[1]);
  {
    char dash1 = 0, dash2 = 0;
    std::istringstream in(fields[2]);
    in >> spec.year >> dash1 >> spec.month >> dash2 >> spec.day;
    if (!in || dash1 != '-' || dash2 != '-' || in.peek() != std::char_traits<char>::eof() ||
      fields[2].size() != 10)
    {
      throw UsageError(option + " has the date '" + fields[2] + "': give YYYY-MM-DD");
    }
  }
  spec.startHour = parseClock(option, fields[3]);
  spec.endHour = parseClock(option, fields[4]);
  spec.stepMinutes = parseNumber(option + " (minutes between frames)", fields[5]);
  return spec;
}

/// --dates MM-DD,MM-DD: both days included.
std::array<int, 4> parseDates(const std::string& option, const std::string& text)
{
  static const int days[] = { 31, 29, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
  const std::vector<std::string> fields = split(text);
  std::array<int, 4> dates{};
  for (std::size_t k = 0; k < 2 && fields.size() == 2; ++k)
  {
    char dash = 0;
    std::istringstream in(fields[k]);
    in >> dates[2 * k] >> dash >> dates[2 * k + 1];
    const int month = dates[2 * k], day = dates[2 * k + 1];
    if (!in || dash != '-' || in.peek() != std::char_traits<char>::eof() || fields[k].size() != 5 ||
      month < 1 || month > 12 || day < 1 || day > days[month - 1])
    {
      throw UsageError(option + " has the date '" + fields[k] +
        "': give MM-DD,MM-DD, days that exist (e.g. 06-01,08-31; 12-01,02-28 wraps over the "
        "new year)");
    }
  }
  if (fields.size() != 2)
  {
    throw UsageError(option + " is '" + text + "': give the first and last days, MM-DD,MM-DD");
  }
  return dates;
}

/// --hours H-H: clock hours 0 to 23, each the hour starting then.
std::array<int, 2> parseHours(const std::string& option, const std::string& text)
{
  const std::size_t dash = text.find('-');
  const auto hour = [&](const std::string& part)
  {
    const long long h = dash == std::string::npos || part.empty() || part.size() > 2 ||
        part.find_first_not_of("0123456789") != std::string::npos
      ? -1
      : std::stoll(part);
    if (h < 0 || h > 23)
    {
      throw UsageError(option + " is '" + text +
        "': give FIRST-LAST, clock hours from 0 to 23, each the hour that starts then (8-16 "
        "is 08:00 to 17:00)");
    }
    return static_cast<int>(h);
  };
  const std::array<int, 2> hours = { hour(text.substr(0, dash)),
    hour(dash == std::string::npos ? "" : text.substr(dash + 1)) };
  if (hours[0] > hours[1])
  {
    throw UsageError(option + " is '" + text + "': give the first hour first (8-16)");
  }
  return hours;
}

std::string parseWeather(const std::string& option, const std::string& text)
{
  if (!endsWith(text, ".epw"))
  {
    throw UsageError(option + " is '" + text + "': give an EnergyPlus weather file (.epw)");
  }
  return text;
}

std::string asGiven(const std::string&, const std::string& text)
{
  return text;
}

/// R,G,B, or one number: a white light of that power per channel.
Triple parsePower(const std::string& option, const std::string& text)
{
  if (text.find(',') != std::string::npos)
  {
    return parseThree(option, text, "R,G,B");
  }
  const double power = parseNumber(option, text);
  return { power, power, power };
}

/// HALF_ANGLE or HALF_ANGLE,SOFT_EDGE, degrees.
std::array<double, 2> parseSpot(const std::string& option, const std::string& text)
{
  const std::vector<std::string> fields = split(text);
  if (fields.size() > 2)
  {
    throw UsageError(option + " needs HALF_ANGLE_DEG[,SOFT_EDGE_DEG], not '" + text + "'");
  }
  return { parseNumber(option, fields[0]),
    fields.size() == 2 ? parseNumber(option, fields[1]) : 0.0 };
}

/// HEIGHT,SPACING of --work-plane: a height of 0 or more and a spacing above 0.
std::array<double, 2> parseWorkPlane(const std::string& option, const std::string& text)
{
  const std::vector<std::string> fields = split(text);
  if (fields.size() != 2)
  {
    throw UsageError(option + " is '" + text + "': give HEIGHT,SPACING in scene units (0.8,0.5)");
  }
  const std::array<double, 2> plane = { parseNumber(option, fields[0]),
    parseNumber(option, fields[1]) };
  if (!(plane[0] >= 0) || !(plane[1] > 0))
  {
    throw UsageError(option + " is '" + text +
      "': the height above the floor must be 0 or more and the spacing above 0");
  }
  return plane;
}

/// A photometric file, by its extension (the filter reads it).
std::string parseDistribution(const std::string& option, const std::string& text)
{
  if (!endsWith(text, ".ies") && !endsWith(text, ".ldt"))
  {
    throw UsageError(
      option + " is '" + text + "': give an IES LM-63 file (.ies) or a EULUMDAT file (.ldt)");
  }
  return text;
}

std::string parseReuse(const std::string& option, const std::string& text)
{
  if (text != "none" && text != "gathering" && text != "shooting" && text != "both")
  {
    throw UsageError(option + " is '" + text + "': give none, gathering, shooting or both");
  }
  return text;
}

std::string parseOutput(const std::string& option, const std::string& text)
{
  if (!endsWith(text, ".pvd") || text.size() <= 4 || endsWith(text, "/.pvd"))
  {
    throw UsageError(option + " is '" + text + "': give a file name ending in .pvd");
  }
  return text;
}

std::string stem(const std::string& path)
{
  const std::size_t slash = path.find_last_of('/');
  std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  const std::size_t dot = name.find_last_of('.');
  return dot == std::string::npos || dot == 0 ? name : name.substr(0, dot);
}

/// `path` made absolute, with its symbolic links resolved as far as it exists.
std::filesystem::path resolved(const std::filesystem::path& path)
{
  std::error_code error;
  const std::filesystem::path absolute =
    std::filesystem::absolute(path.empty() ? std::filesystem::path(".") : path, error);
  std::filesystem::path real = std::filesystem::weakly_canonical(absolute, error);
  return error ? absolute.lexically_normal() : real;
}

/**
 * Refuses a --stats file that is one of the files the run writes or replaces: the series,
 * its frames, the sensors' series (which a run without sensors removes) or the pictures. The
 * statistics would be staged under the same name as one of them, and the commit would fail
 * halfway, after the earlier series was replaced.
 */
void checkStatsHasItsOwnName(const Options& o)
{
  namespace fs = std::filesystem;
  if (o.stats.empty())
  {
    return;
  }
  const fs::path stats = resolved(o.stats);
  const std::string name = stats.filename().string();
  const fs::path collection = o.output;
  const SeriesNaming naming(collection, 1);
  const fs::path sensors = sensorsCollectionOf(collection);
  const SeriesNaming sensorNaming(sensors, 1);
  const bool besideSeries = stats.parent_path() == resolved(naming.directory);
  std::string what;
  if (stats == resolved(collection))
  {
    what = "the series of --output '" + o.output + "'";
  }
  else if (besideSeries && isSeriesFile(name, naming.framePrefix(), ".vtu"))
  {
    what =
      "a frame of the series of --output '" + o.output + "' (" + naming.framePrefix() + "NNNN.vtu)";
  }
  else if (stats == resolved(sensors) ||
    (besideSeries && isSeriesFile(name, sensorNaming.framePrefix(), ".vtp")))
  {
    what = "a file of the sensors' series of --output '" + o.output + "' (" +
      sensors.filename().string() + ", " + sensorNaming.framePrefix() + "NNNN.vtp)";
  }
  else if (!o.png.empty() &&
    (stats == resolved(o.png) ||
      (stats.parent_path() == resolved(o.png) && isSeriesFile(name, naming.framePrefix(), ".png"))))
  {
    what = "the folder of --png '" + o.png + "' or one of its pictures";
  }
  if (!what.empty())
  {
    throw UsageError("--stats '" + o.stats + "' is " + what +
      ": give the statistics a file of their own, e.g. --stats " +
      (naming.directory / (naming.stem + ".json")).string());
  }
}

template <typename T>
void checkRange(const std::string& option, T value, T minimum, T maximum)
{
  if (value < minimum || value > maximum)
  {
    std::ostringstream s;
    s << option << " is " << value << ": give a value from " << minimum << " to " << maximum;
    throw UsageError(s.str());
  }
}

/// `value` of `option` within the range the filter accepts for `property`.
template <typename T>
void checkPropertyRange(const std::string& option, T value, const char* property)
{
  double range[2] = { 0, 0 };
  vtkMovingLightRadiosity::GetPropertyRange(property, range);
  checkRange<T>(option, value, static_cast<T>(range[0]), static_cast<T>(range[1]));
}
}

bool Options::sceneIsYUp() const
{
  return endsWith(this->scene, ".gltf") || endsWith(this->scene, ".glb");
}

Triple Options::zenith() const
{
  return this->up.value_or(this->sceneIsYUp() ? Triple{ 0, 1, 0 } : Triple{ 0, 0, 1 });
}

Triple Options::northDirection() const
{
  // With --up given, north keeps its Z-up default, whatever the format.
  return this->north.value_or(
    this->sceneIsYUp() && !this->up ? Triple{ 0, 0, -1 } : Triple{ 0, 1, 0 });
}

Options parseCommandLine(int argc, const char* const* argv)
{
  Options o;
  o.defaultRun = argc <= 1;
  CLI::App app;
  // --help prints helpText(), which says more about each option than CLI11's listing would.
  app.set_help_flag();
  const CLI::Option* help = app.add_flag("-h,--help", o.help);
  const CLI::Option* point = app.add_flag("--point-light", o.pointLight);
  const CLI::Option* night = app.add_flag("--night", o.night);
  const CLI::Option* luminaire = app.add_flag("--luminaire", o.luminaire);
  const CLI::Option* equalShares = app.add_flag("--equal-shares", o.equalShares);
  // Unknown options, arguments and repeated options are reported below, in the project's words.
  app.allow_extras();
  app.option_defaults()->multi_option_policy(CLI::MultiOptionPolicy::TakeLast);

  // Every option takes one value, read by `read(name, value)`. Numbers keep the project's readers:
  // CLI11 2.0 takes nan, inf and 1e999 as numbers, reads whole numbers in base 0 (010 is 8,
  // 0x10 is 16) and saturates those that overflow, and its conversion errors do not say which
  // option failed.
  const auto needsValue = [&app](const std::string& name)
  {
    const CLI::Option* option = app.get_option_no_throw(name);
    const std::string what = option ? option->get_type_name() : "";
    return UsageError(name + " needs a value: " + name + " " + what);
  };
  const auto option = [&](const std::string& name, const char* value, auto& into, auto read)
  {
    app
      .add_option_function<std::string>(name,
        [name, value, &into, read, &needsValue](const std::string& text)
        {
          if (text.empty())
          {
            throw needsValue(name);
          }
          // CLI11 takes the word after an option as its value whatever it is: `--stats --help`
          // would solve and write a file named --help.
          if (text.rfind("--", 0) == 0)
          {
            const std::string type = value;
            const bool path = type.find("FILE") != std::string::npos ||
              type.find("DIR") != std::string::npos || type.find("PATH") != std::string::npos;
            throw UsageError(std::string(needsValue(name).what()) + ", not the option '" + text +
              "'" + (path ? " (a file whose name starts with -- is ./" + text + ")" : ""));
          }
          into = read(name, text);
        })
      ->type_name(value);
  };
  option("--scene", "FILE", o.scene, asGiven);
  option("--light", "FILE", o.light, asGiven);
  option("--trajectory", "FILE", o.trajectory, asGiven);
  option("--from", "X,Y,Z", o.from, parseTriple);
  option("--to", "X,Y,Z", o.to, parseTriple);
  option("--frames", "N", o.frames, parseInteger);
  option("--light-material", "NAME", o.lightMaterial, asGiven);
  option("--aim", "X,Y,Z", o.aim, parseTriple);
  option("--sun-directions", "FILE", o.sunDirections, asGiven);
  option("--sun-path", "LAT,LON,YYYY-MM-DD,HH:MM,HH:MM,MINUTES", o.sunPath, parseSunPath);
  option("--sun-irradiance", "W/m2", o.sunIrradiance, parseNumber);
  option("--time-zone", "HOURS", o.timeZone, parseNumber);
  option("--north", "X,Y,Z", o.north, parseTriple);
  option("--up", "X,Y,Z", o.up, parseTriple);
  option("--sky", "uniform|cie-overcast|cie-clear|perez", o.sky, asGiven);
  option("--sky-diffuse-horizontal", "W_PER_M2", o.skyDiffuseHorizontal, parseNumber);
  option("--weather", "FILE.epw", o.weather, parseWeather);
  option("--dates", "MM-DD,MM-DD", o.dates, parseDates);
  option("--hours", "FIRST-LAST", o.hours, parseHours);
  option("--light-power", "R,G,B", o.lightPower, parsePower);
  option("--light-distribution", "FILE.ies|FILE.ldt", o.lightDistribution, parseDistribution);
  option("--spot", "HALF_ANGLE_DEG[,SOFT_EDGE_DEG]", o.spot, parseSpot);
  option("--light-lumens", "LM", o.lightLumens, parseNumber);
  option("--paths", "N", o.paths, parseInteger);
  option("--gather-ratio", "K", o.gatherRatio, parseNumber);
  option("--survival", "L", o.survival, parseNumber);
  option("--reuse", "none|gathering|shooting|both", o.reuse, parseReuse);
  option("--patch-size", "H", o.patchSize, parseNumber);
  option("--seed", "S", o.seed, parseInteger);
  option("--threads", "T", o.threads, parseInteger);
  option("--memory-limit", "MIB", o.memoryLimit, parseInteger);
  option("--frames-per-chunk", "C", o.framesPerChunk, parseInteger);
  option("--chunk-overlap", "M", o.chunkOverlap, parseInteger);
  option("--error-batches", "B", o.errorBatches, parseInteger);
  option("--target-error", "FRACTION", o.targetError, parseNumber);
  option("--time-limit", "SECONDS", o.timeLimit, parseNumber);
  option("--luminous-efficacy", "LM_PER_W", o.luminousEfficacy, parseNumber);
  option("--sensors", "FILE.vtp", o.sensors, asGiven);
  option("--work-plane", "HEIGHT,SPACING", o.workPlane, parseWorkPlane);
  option("--da-threshold", "LX", o.daThreshold, parseNumber);
  option("--sensor-rays", "N", o.sensorRays, parseInteger);
  option("--output", "PATH.pvd", o.output, parseOutput);
  option("--stats", "FILE.json", o.stats, asGiven);
  option("--png", "DIR", o.png, asGiven);

  // CLI11 reads `--paths= 5` as `--paths 5` and `--help=no` as no --help: both stay errors.
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    const std::string name = arg.substr(0, arg.find('='));
    const CLI::Option* given = app.get_option_no_throw(name);
    if ((given == help || given == point || given == night || given == luminaire ||
          given == equalShares) &&
      name.size() < arg.size())
    {
      throw UsageError(name + " takes no value");
    }
    if (given && name.size() + 1 == arg.size())
    {
      throw needsValue(name);
    }
  }
  try
  {
    app.parse(argc, argv);
  }
  catch (const CLI::ArgumentMismatch&)
  {
    // Thrown when the arguments ran out before an option's value: the option is the last one.
    throw needsValue(argv[argc - 1]);
  }
  catch (const CLI::ParseError& e)
  {
    throw UsageError(e.what());
  }
  if (!app.remaining().empty())
  {
    const std::string arg = app.remaining().front();
    if (arg.rfind("--", 0) != 0)
    {
      throw UsageError("unexpected argument '" + arg + "': every option starts with --");
    }
    throw UsageError("unknown option " + arg.substr(0, arg.find('=')));
  }
  for (const CLI::Option* given : app.get_options())
  {
    if (given->count() > 1 && given != help && given != point && given != night &&
      given != luminaire && given != equalShares)
    {
      throw UsageError(given->get_name() + " is given twice");
    }
  }
  if (o.help)
  {
    return o;
  }

  if (o.lightMaterial)
  {
    if (!o.light.empty() || o.usesSun())
    {
      throw UsageError("--light-material takes the light from the scene: give it without "
                       "--light, --sun-directions and --sun-path");
    }
    if (o.usesEmbeddedScene())
    {
      throw UsageError("--light-material needs --scene FILE (an .obj with its .mtl, a .gltf, "
                       ".glb or .ply with materials)");
    }
  }
  if (o.pointLight && (!o.light.empty() || o.lightMaterial || o.usesSun()))
  {
    throw UsageError("--point-light is a light of its own: give it without --light, "
                     "--light-material, --sun-directions and --sun-path");
  }
  if (o.luminaire && (o.pointLight || !o.light.empty() || o.lightMaterial || o.usesSun()))
  {
    throw UsageError("--luminaire is a light of its own: give it without --point-light, "
                     "--light, --light-material, --sun-directions and --sun-path");
  }
  if (o.luminaire && o.lightDistribution.empty())
  {
    throw UsageError("--luminaire emits from a photometric file's luminous opening: give "
                     "--light-distribution FILE.ies|FILE.ldt");
  }
  if (o.usesSun() && (!o.lightDistribution.empty() || o.spot || o.lightLumens))
  {
    throw UsageError("--light-distribution, --spot and --light-lumens are for a light, not "
                     "the sun");
  }
  if (!o.lightDistribution.empty() && o.spot)
  {
    throw UsageError("give either --light-distribution FILE or --spot HALF_ANGLE_DEG, not both");
  }
  if (o.spot &&
    !((*o.spot)[0] > 0 && (*o.spot)[0] <= 180 && (*o.spot)[1] >= 0 && (*o.spot)[1] <= 180))
  {
    throw UsageError("--spot is " + mlr::formatNumber((*o.spot)[0]) + "," +
      mlr::formatNumber((*o.spot)[1]) +
      ": give a half angle above 0 and at most 180 degrees and a soft edge from 0 to 180");
  }
  if (o.lightLumens && !(*o.lightLumens > 0 && *o.lightLumens <= mlr::MaximumLightPower))
  {
    throw UsageError("--light-lumens is " + mlr::formatNumber(*o.lightLumens) +
      ": give the luminaire's luminous flux in lumens, above 0 and at most " +
      mlr::formatNumber(mlr::MaximumLightPower));
  }
  if (!o.sunDirections.empty() && o.sunPath)
  {
    throw UsageError("give either --sun-directions FILE or --sun-path ..., not both");
  }
  if (!o.weather.empty())
  {
    if (!o.sunDirections.empty() || o.sunPath)
    {
      throw UsageError("--weather gives the sun of its hours: give it without --sun-directions "
                       "and --sun-path");
    }
    if (o.timeZone || o.sunIrradiance || o.skyDiffuseHorizontal)
    {
      throw UsageError("--weather gives its time zone and each hour's irradiances: give it "
                       "without --time-zone, --sun-irradiance and --sky-diffuse-horizontal");
    }
    if (!o.sky)
    {
      o.sky = "perez";
    }
  }
  else if (o.dates || o.hours || o.night)
  {
    throw UsageError("--dates, --hours and --night choose the hours of --weather FILE.epw");
  }
  if (!o.sensors.empty() && o.workPlane)
  {
    throw UsageError("--sensors and --work-plane both give the sensors: give one of them");
  }
  if (o.daThreshold && !o.usesSensors())
  {
    throw UsageError("--da-threshold is for the sensors' DaylightAutonomy: give --sensors "
                     "FILE.vtp or --work-plane HEIGHT,SPACING too");
  }
  if (o.sensorRays && !o.usesSensors())
  {
    throw UsageError("--sensor-rays is for the sensors: give --sensors FILE.vtp or "
                     "--work-plane HEIGHT,SPACING too");
  }
  if (o.usesSun())
  {
    if (!o.light.empty() || !o.trajectory.empty() || o.from || o.to || o.aim || o.lightPower)
    {
      throw UsageError("the sun replaces the light: --sun-directions, --sun-path and --weather "
                       "go without --light, --trajectory, --from/--to, --aim and --light-power");
    }
    if (o.usesEmbeddedScene())
    {
      throw UsageError("the sun needs --scene FILE: the built-in Cornell box is closed");
    }
  }
  else if (o.sunIrradiance)
  {
    throw UsageError("--sun-irradiance needs --sun-directions FILE or --sun-path ...");
  }
  if (!o.sunPath && o.weather.empty() && (o.timeZone || o.north))
  {
    throw UsageError("--time-zone and --north need --sun-path ... (--north also --weather)");
  }
  if (!o.sunPath && o.sunDirections.empty() && !o.sky && o.lightDistribution.empty() &&
    !o.workPlane && o.up)
  {
    throw UsageError("--up needs --sun-path ..., --sun-directions FILE, --weather FILE.epw, "
                     "--sky MODEL, "
                     "--light-distribution FILE (whose TILT table it sets the vertical of) or "
                     "--work-plane HEIGHT,SPACING");
  }
  if (o.sunIrradiance && !(*o.sunIrradiance >= 0 && std::isfinite(*o.sunIrradiance)))
  {
    throw UsageError("--sun-irradiance is " + mlr::formatNumber(*o.sunIrradiance) +
      ": give the irradiance on a surface facing the sun in W/m^2, 0 or above (1000 by "
      "default; 0 keeps the sun's frames for the sky with no direct sun)");
  }
  if (o.sky)
  {
    const int model = skyModelIndex(*o.sky);
    if ((model == vtkMovingLightRadiosity::CIE_CLEAR_SKY ||
          model == vtkMovingLightRadiosity::PEREZ_SKY) &&
      !o.usesSun())
    {
      throw UsageError("--sky " + *o.sky +
        " follows the sun: give --sun-directions FILE, --sun-path ... or --weather FILE.epw, or "
        "choose --sky uniform or cie-overcast");
    }
    if (o.usesEmbeddedScene())
    {
      throw UsageError("the sky needs --scene FILE: the built-in Cornell box is closed");
    }
    // The filter solves a sky with the sun and the scene's emission, without its area and
    // point lights: they would be dropped without a word.
    const char* light = !o.light.empty() ? "--light"
      : o.lightMaterial                  ? "--light-material"
      : o.pointLight                     ? "--point-light"
      : o.luminaire                      ? "--luminaire"
                                         : nullptr;
    if (light)
    {
      throw UsageError(std::string(light) +
        " with --sky: a sky lights the scene beside the sun or alone, and the solve would leave "
        "the light out; give one or the other");
    }
  }
  else if (o.skyDiffuseHorizontal)
  {
    throw UsageError("--sky-diffuse-horizontal needs --sky MODEL");
  }
  if (o.luminousEfficacy && (o.sky || o.usesSun()))
  {
    throw UsageError(std::string("--luminous-efficacy with ") +
      (!o.weather.empty() ? "--weather"
          : o.sky         ? "--sky"
                          : "the sun") +
      ": daylight's Illuminance takes each frame's Perez daylight efficacy (field data "
      "LuminousEfficacy), not this one; leave --luminous-efficacy out");
  }
  if (o.skyDiffuseHorizontal &&
    !(*o.skyDiffuseHorizontal >= 0 && std::isfinite(*o.skyDiffuseHorizontal)))
  {
    throw UsageError("--sky-diffuse-horizontal is " + mlr::formatNumber(*o.skyDiffuseHorizontal) +
      ": give the sky's diffuse horizontal irradiance in W/m^2, 0 or above (100 by default)");
  }
  if (!o.trajectory.empty() && (o.from || o.to))
  {
    throw UsageError("give either --trajectory FILE or --from X,Y,Z --to X,Y,Z, not both");
  }
  if (o.from.has_value() != o.to.has_value())
  {
    throw UsageError("--from and --to go together: give both ends of the light's path");
  }
  if (o.frames && !o.from)
  {
    throw UsageError("--frames needs --from and --to (a trajectory file has its own frames)");
  }
  if (o.from && !o.frames)
  {
    o.frames = 30;
  }
  if (o.sceneLightsItself())
  {
    // Whether the scene emits is known once it is read (main checks it then). The filter has
    // no light to give these to: they would be ignored.
    const char* given = !o.trajectory.empty() ? "--trajectory"
      : o.from                                ? "--from"
      : o.aim                                 ? "--aim"
      : o.lightPower                          ? "--light-power"
      : o.lightLumens                         ? "--light-lumens"
      : o.spot                                ? "--spot"
      : !o.lightDistribution.empty()          ? "--light-distribution"
                                              : nullptr;
    if (given)
    {
      throw UsageError(std::string(given) +
        " is for a light, and the scene has none (--trajectory, --from, --to, --aim, "
        "--light-power, --light-lumens, --spot and --light-distribution are for a light): " +
        (o.sky ? "leave it out (the sky alone lights the scene, in one frame; --sky drops "
                 "lights)"
               : "give --light FILE, --light-material NAME or --point-light, or leave it out "
                 "(without a light the scene's own emissive surfaces light it, in one frame)"));
    }
  }
  else if (!o.usesEmbeddedScene() && !o.usesSun())
  {
    if (o.trajectory.empty() && !o.from)
    {
      throw UsageError("--scene needs the light's path: --trajectory FILE or --from X,Y,Z "
                       "--to X,Y,Z [--frames N]");
    }
  }
  if (o.output.empty())
  {
    o.output =
      "output/" + (o.usesEmbeddedScene() ? std::string("cornell") : stem(o.scene)) + ".pvd";
  }
  if (o.defaultRun)
  {
    o.png = "output/png";
  }
  checkStatsHasItsOwnName(o);
  return o;
}

void configureFilter(const Options& o, vtkMovingLightRadiosity* filter)
{
  if (o.lightPower)
  {
    for (double p : *o.lightPower)
    {
      checkRange("--light-power", p, 0.0, mlr::MaximumLightPower);
    }
    if (o.lightLumens &&
      mlr::luminance(mlr::Rgb((*o.lightPower)[0], (*o.lightPower)[1], (*o.lightPower)[2])) <= 0)
    {
      throw UsageError("--light-lumens takes the light's colour from --light-power, which is " +
        mlr::formatNumber((*o.lightPower)[0]) + "," + mlr::formatNumber((*o.lightPower)[1]) + "," +
        mlr::formatNumber((*o.lightPower)[2]) +
        ", black: give a colour (1,1,1 for white) or leave --light-power out");
    }
    filter->SetLightPower(o.lightPower->data());
  }
  if (o.lightMaterial)
  {
    filter->SetLightMaterial(o.lightMaterial->c_str());
    // An explicit --light-power wins over the material's emission.
    filter->SetLightPowerFromMaterial(!o.lightPower.has_value());
  }
  if (o.pointLight)
  {
    filter->SetLightTypeToPoint();
  }
  if (o.luminaire)
  {
    filter->SetLightTypeToLuminaire();
  }
  // Up decides a TILT table's angles, the sky's zenith and which suns are below the horizon.
  if (!o.lightDistribution.empty() || o.usesSun() || o.sky)
  {
    filter->SetUp(o.zenith().data());
  }
  if (!o.lightDistribution.empty())
  {
    filter->SetLightDistributionFile(o.lightDistribution.c_str());
    // Precedence: --light-lumens, then --light-power's (or the material's) watts, then the
    // file's own flux.
    filter->SetLightFluxFromFile(!o.lightLumens && !o.lightPower && !o.lightMaterial);
  }
  if (o.spot)
  {
    filter->SetSpotHalfAngle((*o.spot)[0]);
    filter->SetSpotSoftEdge((*o.spot)[1]);
  }
  if (o.lightLumens)
  {
    filter->SetLightFluxLumens(*o.lightLumens);
  }
  if (o.aim)
  {
    filter->SetAimAtPoint(true);
    filter->SetAimPoint(o.aim->data());
  }
  if (o.usesSun())
  {
    filter->SetLightTypeToDirectional();
    filter->SetSunIrradiance(o.sunIrradiance.value_or(1000.0));
  }
  if (o.sky)
  {
    filter->SetSkyModel(skyModelIndex(*o.sky));
    filter->SetSkyDiffuseHorizontal(o.skyDiffuseHorizontal.value_or(100.0));
  }
  if (o.paths)
  {
    checkPropertyRange<long long>("--paths", *o.paths, "NumberOfPaths");
    filter->SetNumberOfPaths(static_cast<vtkIdType>(*o.paths));
  }
  if (o.gatherRatio)
  {
    checkPropertyRange("--gather-ratio", *o.gatherRatio, "GatheringRatio");
    filter->SetGatheringRatio(*o.gatherRatio);
  }
  if (o.survival)
  {
    checkPropertyRange("--survival", *o.survival, "FirstBounceSurvival");
    filter->SetFirstBounceSurvival(*o.survival);
  }
  if (o.reuse)
  {
    filter->SetReuseShooting(*o.reuse == "shooting" || *o.reuse == "both");
    filter->SetReuseGathering(*o.reuse == "gathering" || *o.reuse == "both");
  }
  if (o.equalShares)
  {
    if (o.reuse && *o.reuse != "shooting" && *o.reuse != "both")
    {
      throw UsageError("--equal-shares shares the reused shooting paths among the positions: "
                       "give it with --reuse shooting or both, or leave it out");
    }
    filter->SetBalanceFrames(0);
  }
  if (o.patchSize)
  {
    checkPropertyRange("--patch-size", *o.patchSize, "PatchSize");
    filter->SetPatchSize(*o.patchSize);
  }
  if (o.seed)
  {
    checkPropertyRange<long long>("--seed", *o.seed, "Seed");
    filter->SetSeed(static_cast<int>(*o.seed));
  }
  if (o.threads)
  {
    checkPropertyRange<long long>("--threads", *o.threads, "NumberOfThreads");
    filter->SetNumberOfThreads(static_cast<int>(*o.threads));
  }
  if (o.memoryLimit)
  {
    checkRange<long long>("--memory-limit", *o.memoryLimit, 1, VTK_INT_MAX);
    filter->SetMemoryLimit(static_cast<int>(*o.memoryLimit));
  }
  if (o.framesPerChunk)
  {
    checkPropertyRange<long long>("--frames-per-chunk", *o.framesPerChunk, "FramesPerChunk");
    filter->SetFramesPerChunk(static_cast<int>(*o.framesPerChunk));
  }
  if (o.chunkOverlap)
  {
    checkPropertyRange<long long>("--chunk-overlap", *o.chunkOverlap, "ChunkOverlap");
    filter->SetChunkOverlap(static_cast<int>(*o.chunkOverlap));
  }
  if (const std::string problem =
        mlr::chunkSettingsProblem(static_cast<std::uint64_t>(o.framesPerChunk.value_or(0)),
          static_cast<std::uint64_t>(o.chunkOverlap.value_or(0)), "--frames-per-chunk",
          "--chunk-overlap");
      !problem.empty())
  {
    throw UsageError(problem);
  }
  if (o.paths && *o.paths < o.errorBatches.value_or(filter->GetErrorBatches()))
  {
    throw UsageError("--paths " + std::to_string(*o.paths) + " cannot make " +
      std::to_string(o.errorBatches.value_or(filter->GetErrorBatches())) +
      " error batches: give at least as many paths as --error-batches, or fewer batches");
  }
  if (o.errorBatches)
  {
    checkPropertyRange<long long>("--error-batches", *o.errorBatches, "ErrorBatches");
    filter->SetErrorBatches(static_cast<int>(*o.errorBatches));
  }
  if (o.targetError)
  {
    if (!(*o.targetError == 0 || (*o.targetError >= 1e-4 && *o.targetError < 1)))
    {
      std::ostringstream s;
      s << "--target-error is " << *o.targetError
        << ": give the relative error to reach as a fraction, e.g. 0.02 for 2% (at least "
           "0.0001 and below 1: the batches' relative error is at most 1), or 0 for none";
      throw UsageError(s.str());
    }
    if (*o.targetError > 0 && o.errorBatches && *o.errorBatches < 2)
    {
      throw UsageError("--target-error needs an error estimate: give --error-batches 2 or more");
    }
    filter->SetTargetRelativeError(*o.targetError);
  }
  if (o.timeLimit)
  {
    if (!(*o.timeLimit >= 0 && std::isfinite(*o.timeLimit)))
    {
      std::ostringstream s;
      s << "--time-limit is " << *o.timeLimit << ": give a number of seconds, or 0 for none";
      throw UsageError(s.str());
    }
    if (!o.targetError || !(*o.targetError > 0))
    {
      throw UsageError("--time-limit bounds the rounds of --target-error: give a target too");
    }
    filter->SetTimeLimit(*o.timeLimit);
  }
  if (o.luminousEfficacy)
  {
    // Above 0 and at most 683: range messages say "from ... to", which would let 0 through.
    if (!(*o.luminousEfficacy > 0 && *o.luminousEfficacy <= 683))
    {
      std::ostringstream s;
      s << "--luminous-efficacy is " << *o.luminousEfficacy
        << ": give the light's luminous efficacy in lm/W, above 0 and at most 683 (179 for "
           "white light)";
      throw UsageError(s.str());
    }
    filter->SetLuminousEfficacy(*o.luminousEfficacy);
  }
  if (o.daThreshold)
  {
    checkRange("--da-threshold", *o.daThreshold, 0.0, 1e9);
    filter->SetDaylightAutonomyThreshold(*o.daThreshold);
  }
  if (o.sensorRays)
  {
    checkPropertyRange<long long>("--sensor-rays", *o.sensorRays, "SensorRays");
    filter->SetSensorRays(static_cast<int>(*o.sensorRays));
  }
  if (o.from)
  {
    checkPropertyRange<long long>("--frames", *o.frames, "NumberOfPositions");
    filter->SetPathStart(o.from->data());
    filter->SetPathEnd(o.to->data());
    // --from is where a --light-material lamp starts too, not where the scene has it.
    filter->SetPathFromLightMaterial(false);
    filter->SetNumberOfPositions(static_cast<int>(*o.frames));
  }
}

std::string helpText()
{
  return R"(Usage: moving-light-radiosity [OPTIONS]

Computes the radiosity of a scene lit by a light that moves along a path, all light
positions at once with reuse of paths, and writes the animation as a .pvd + .vtu series
(one unstructured grid per frame with the cell arrays Radiosity, DirectRadiosity,
IndirectRadiosity, EmittedRadiosity, RadiosityFront/RadiosityBack, Irradiance (the light
arriving, W/m^2), Illuminance (lx), their IrradianceFront/IrradianceBack and
IlluminanceFront/IlluminanceBack of each side, Reflectance, PatchId, Color, the display
colour, and the scene's own cell arrays such as MaterialId, and the point arrays Radiosity,
Irradiance, Illuminance, Color and ScenePointId on points split along creases for smooth
shading).

Without any option it runs the built-in example: the Cornell box with its ceiling light
moving through 30 positions along a diagonal just below the ceiling, and writes
output/cornell.pvd, output/cornell_0000.vtu ... and output/png/cornell_0000.png ...
under the current directory.

Scene and light:
  --scene FILE          surfaces to light: .vtp .vtu .vtk .obj .gltf .glb .ply .stl; a
                        cell array Reflectance (RGB or grey, in [0,1)) gives their colour,
                        else grey 0.5; .obj (with its .mtl), .gltf, .glb and .ply files
                        bring their materials: Kd or baseColorFactor is the reflectance
                        (1 or more clamped to 0.99 with a warning), Ke or emissiveFactor
                        the emission (default: the built-in Cornell box)
  --light FILE          the light's polygons, emitting along their normals (default: the
                        Cornell box's ceiling light). A --scene given without --light,
                        --light-material or the sun is lit by its own emissive surfaces
                        alone, in one frame
  --light-material NAME the polygons of this material of the scene (an .obj's usemtl, a
                        glTF material) are the light, taken out of the scene; without
                        --light-power its power is the material's emission, pi Ke area
                        (Ke read as radiance, as path tracers do). Other emissive
                        materials stay in the scene and emit in every frame
  --light-power R,G,B   power of each light in W, per channel, or one number for all
                        (default 100,100,100), at most 1e30
                        A cell array LightId groups the polygons into several lights, each
                        of this power unless a cell array LightPower (RGB, W) gives its own.
  --point-light         a point light instead of --light's polygons: it sits at the
                        trajectory's points (or moves from --from to --to), of power
                        --light-power, its nadir -z unless a Normal or Orientation turns it
  --light-distribution FILE.ies|FILE.ldt
                        every light emits with this luminous intensity distribution (IES
                        LM-63 or EULUMDAT), its nadir along an area light's normal (C = 0
                        along its first edge) or a point light's -z (C = 0 along +x);
                        without --light-lumens, --light-power or --light-material the light
                        emits the file's own flux, else only its shape is used (default:
                        diffuse, Lambertian).
                        An IES TILT=INCLUDE table scales each position's power by its factor
                        at that position's tilt from straight down (-up, see --up)
  --luminaire           the --light-distribution file's luminaire as an area light of its
                        luminous opening (seen from below), placed and turned as
                        --point-light is; a file without an opening gives a point light
  --spot HALF_ANGLE_DEG[,SOFT_EDGE_DEG]
                        a spot instead: uniform within the half angle of the nadir, falling
                        to zero over the soft edge beyond it (default soft edge 0)
  --light-lumens LM     the luminous flux of every light in lumens (at most 1e30), instead of
                        the watts of --light-power, whose colour it keeps: watts of
                        luminance = LM over the luminous efficacy (179 lm/W by default)
                        Scene cells with a cell array Emission (RGB or grey, W/m^2) emit
                        from their front side in every frame, and reflect too.
Light path (the positions of the light's area centroid, one per frame):
  --trajectory FILE     the points of a .vtp .vtu .vtk .obj .ply .stl file, in order (with
                        several lights: one polyline per light in LightId order; one point
                        for a light that does not move). Point arrays: Time (frame times,
                        else 0, 1, 2, ...), Normal (the light's emission direction in that
                        frame), Orientation (quaternion w,x,y,z, wins over Normal), Power
                        (a factor on the light's power in that frame; 0 is off)
  --from X,Y,Z --to X,Y,Z [--frames N]
                        a straight path in N frames (default 30)
  --aim X,Y,Z           in every frame, turn the light to face this point
The sun (a directional light, instead of --light; needs --scene; --north and --up also
apply to --weather):
  --sun-directions FILE the points of a file are directions towards the sun, one per frame
                        (any length but 0); point arrays Time and Power as above; a
                        direction below the horizon (across --up) is a dark frame, with a
                        warning
  --sun-path LAT,LON,YYYY-MM-DD,HH:MM,HH:MM,MINUTES
                        the sun seen from latitude LAT, longitude LON (degrees, north and
                        east positive) on that day, from the first clock time to the
                        second every MINUTES (solar positions from libnova); frames with
                        the sun below the horizon are kept, dark, and the series' times
                        are the clock times in hours
  --time-zone HOURS     the clock times' offset from UTC (default 0: UTC; e.g. 2 for CEST)
  --north X,Y,Z         the scene's north (default 0,1,0; 0,0,-1 for a glTF scene
                        without --up)
  --up X,Y,Z            the scene's zenith, also the sky's and the vertical a TILT table
                        measures the luminaire's tilt from (default 0,0,1; 0,1,0 for a
                        .gltf or .glb scene, which the glTF standard makes Y-up)
  --sun-irradiance W/m2 on a surface facing the sun (default 1000; 0: no direct sun, the
                        frames and the sky's sun kept)
  --weather FILE.epw    the hours of an EnergyPlus weather file as frames: the sun at the
                        file's place, in its time zone, at the middle of each hour, with
                        the hour's direct normal irradiance, and a Perez sky (unless --sky
                        says otherwise) of its diffuse horizontal irradiance and date. The
                        series' times are hours of the year: 0 is January 1 00:00-01:00
  --dates MM-DD,MM-DD   the first and last days of --weather, both included; 12-01,01-31
                        wraps over the new year, January counting on from 8760 (default
                        01-01,12-31)
  --hours FIRST-LAST    the clock hours of each day, 0 to 23, each the hour starting then:
                        8-16 is 08:00 to 17:00 (default 0-23)
  --night               also the hours whose sun is below the horizon at their middle
                        (left out by default), dark but for the sky
The sky (beside the sun or alone, not with a light; needs --scene; nothing lights from
below the horizon):
  --sky MODEL           uniform, cie-overcast, cie-clear or perez; cie-clear (CIE type 12)
                        and perez (Perez all-weather) follow each frame's sun, perez from
                        its direct normal irradiance (--sun-irradiance times Power)
  --sky-diffuse-horizontal W_PER_M2
                        what the sky gives an unobstructed horizontal surface (default 100)
Solver:
  --paths N             effective shooting paths per frame (default 600000)
  --gather-ratio K      final-gathering rays per frame, as a multiple of N (default 1)
  --survival L          probability that a path continues after its first hit (default 0.25)
  --reuse MODE          none, gathering, shooting or both (default both)
  --equal-shares        reused paths: as many from every light position, instead of more
                        from the positions the others cover worst (the ends)
  --patch-size H        target patch edge length in scene units (default: about 3000 patches)
  --seed S              seed of the random numbers (default 0)
  --threads T           worker threads, 0 for every core (default 0)
  --memory-limit MIB    refuse, before allocating, a solve (or reading a file) estimated to
                        need more memory than this (default: half the physical memory)
  --frames-per-chunk C  solve the frames in chunks of C consecutive frames (at least 2), each
                        a full-reuse solve blended with the next over --chunk-overlap frames
                        around each seam: memory depends on C, not on the frame count
                        (default 0: every frame at once when that fits --memory-limit, else
                        the longest chunks that do)
  --chunk-overlap M     with chunks, each also solves M positions beyond its frames on each
                        side, and each seam blends the two chunks over those 2M frames: the
                        flicker at a seam falls as 1/M, each chunk solves C + 2M positions
                        (default 0: C/8, at least 1; at most C/2)
  --error-batches B     solve as B independent batches of N/B paths: their spread gives
                        every element's standard error, RadiosityStdError (default 16;
                        1: no error estimate)
  --target-error FRACTION
                        add rounds of batches until the 95th percentile of the lit
                        elements' relative error is at most this in every frame (0.02 is
                        2%; default 0, off)
  --time-limit SECONDS  with --target-error: start no more batches after this long; in
                        chunks, what is left of it is shared among the chunks still to
                        solve (the result then depends on the machine's speed)
Sensors (measuring points that receive light but neither block nor reflect it):
  --sensors FILE.vtp    the points of a file, each with the point array Normals (the
                        direction its measuring side faces)
  --work-plane HEIGHT,SPACING
                        a grid of sensors facing up over every upward-facing face (within
                        5 degrees of --up: floors, and roofs), HEIGHT above it, SPACING
                        apart on a lattice at (i + 1/2) SPACING, inside the polygons; also
                        over the faces facing down that see a light, or the sky, from
                        above (a room modelled with outward normals), without that room's
                        roof
  --sensor-rays N       rays each sensor casts over its hemisphere (16 to 1000000, default
                        512), and an eighth as many points it samples on each area
                        light: raise it for less noise on the sensors
  --da-threshold LX     the illuminance DaylightAutonomy counts the frames at or above
                        (default 300). The sensors' series is PATH_sensors.pvd with
                        PATH_sensors_0000.vtp ... (point arrays Irradiance, Illuminance per
                        frame; DaylightAutonomy, UDILow, UDIUseful, UDIHigh, DirectSunHours
                        over all frames)
Output:
  --luminous-efficacy LM_PER_W
                        lumens per watt of the light, which turn the Irradiance arrays
                        (W/m^2) into Illuminance (lx for a scene in metres); above 0 and at
                        most 683 (default 179, white light); not with the sun or a sky,
                        whose Illuminance takes each frame's Perez daylight efficacy
  --output PATH.pvd     the series; frames go next to it as PATH_0000.vtu ...
                        (default output/cornell.pvd, or output/SCENE.pvd with --scene)
  --stats FILE.json     also write the options, the light as solved, times and solver
                        statistics as JSON (a name of its own: not the series, its frames,
                        its sensors' series or its pictures)
  --png DIR             also render one picture per frame into DIR, as ParaView shows the
                        frame: the point array Color, unlit, and the light where it is in
                        that frame (needs an X display; without DISPLAY the program starts
                        a private Xvfb)
  --help                show this text

Files are written under temporary names and renamed once all are complete: a failure
leaves any earlier series untouched. Exit status: 0 on success, 1 when the inputs cannot
be read or solved, 2 for a bad command line.

Under mpiexec (mpiexec -n R moving-light-radiosity ...) the R processes solve together:
with at least R chunks each takes whole chunks and writes their frames as they are solved,
else they split the paths and rank 0 writes. The series is the one process's, bit for bit.
Rank 0 reports for all. Not with --png, --sensors or --work-plane; give each rank one
thread per core it owns (--threads).
)";
}

} // namespace mlr::cli
