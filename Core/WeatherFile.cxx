#include "WeatherFile.h"

#include "Error.h"
#include "PhotometricParsing.h"
#include "Plural.h"
#include "RegularFile.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <sstream>
#include <string_view>
#include <tuple>

namespace mlr
{

namespace
{
constexpr std::size_t HeaderLines = 8;
constexpr std::size_t Year = 8760, LeapYear = 8784;
/// The first field of each header line after LOCATION, in the order EnergyPlus writes them
/// (compared without case; HOLIDAYS/DAYLIGHT SAVING is also spelled ...SAVINGS).
constexpr const char* HeaderNames[HeaderLines - 1] = { "DESIGN CONDITIONS",
  "TYPICAL/EXTREME PERIODS", "GROUND TEMPERATURES", "HOLIDAYS/DAYLIGHT SAVING", "COMMENTS 1",
  "COMMENTS 2", "DATA PERIODS" };
/// Irradiances the EPW data dictionary marks missing are 9999 or more; no hour's mean
/// sunlight on the ground comes near 2000 W/m^2 (the solar constant is 1361).
constexpr double MissingIrradiance = 9999, MaximumIrradiance = 2000;
constexpr std::size_t GlobalHorizontalField = 13, DirectNormalField = 14,
                      DiffuseHorizontalField = 15;

const char* const MonthNames[12] = { "January", "February", "March", "April", "May", "June", "July",
  "August", "September", "October", "November", "December" };

int daysIn(int month, bool leap)
{
  static const int days[] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
  return month == 2 && leap ? 29 : days[month - 1];
}

std::string_view trim(std::string_view text)
{
  const auto blank = [](char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n'; };
  while (!text.empty() && blank(text.front()))
  {
    text.remove_prefix(1);
  }
  while (!text.empty() && blank(text.back()))
  {
    text.remove_suffix(1);
  }
  return text;
}

std::vector<std::string_view> splitFields(std::string_view line)
{
  std::vector<std::string_view> fields;
  std::size_t start = 0;
  for (;;)
  {
    const std::size_t comma = line.find(',', start);
    fields.push_back(
      trim(line.substr(start, comma == std::string_view::npos ? comma : comma - start)));
    if (comma == std::string_view::npos)
    {
      return fields;
    }
    start = comma + 1;
  }
}

std::string uppercase(std::string_view text)
{
  std::string result(text);
  for (char& c : result)
  {
    c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  }
  return result;
}

/// Shows at most 40 characters of a field in a message.
std::string shown(std::string_view text)
{
  std::string result(text.substr(0, 40));
  for (char& c : result)
  {
    if (static_cast<unsigned char>(c) < 32 || static_cast<unsigned char>(c) > 126)
    {
      c = '?';
    }
  }
  return text.size() > 40 ? result + "..." : result;
}

/// Messages about one line of the file.
struct Where
{
  const std::string& name;
  std::size_t line;

  [[noreturn]] void fail(const std::string& what) const
  {
    throw Error(
      "the weather file " + this->name + ", line " + std::to_string(this->line) + ": " + what);
  }

  /// Field `index` (0-based; messages count from 1) as a finite number.
  double number(
    const std::vector<std::string_view>& fields, std::size_t index, const char* what) const
  {
    if (index >= fields.size())
    {
      std::ostringstream s;
      s << "has " << fields.size() << " fields, but field " << index + 1 << " (" << what
        << ") is needed: give every field of the EPW format, separated by commas";
      this->fail(s.str());
    }
    // The one number syntax of the project's readers: decimal only ("0x1F4" is text), and the
    // same in every locale, where strtod took hexadecimal and a locale's decimal comma.
    double value = 0;
    if (!photometry::parseNumber(photometry::trim(fields[index]), value))
    {
      std::ostringstream s;
      s << "field " << index + 1 << " (" << what << ") is '" << shown(fields[index])
        << "': give a number";
      this->fail(s.str());
    }
    return value;
  }

  /// A number within [minimum, maximum].
  double inRange(const std::vector<std::string_view>& fields, std::size_t index, const char* what,
    double minimum, double maximum, const char* unit) const
  {
    const double value = this->number(fields, index, what);
    if (!(value >= minimum && value <= maximum))
    {
      std::ostringstream s;
      s << "the " << what << " is " << value << unit << ": give " << minimum << unit << " to "
        << maximum << unit;
      this->fail(s.str());
    }
    return value;
  }

  /// A whole number within [minimum, maximum].
  int whole(const std::vector<std::string_view>& fields, std::size_t index, const char* what,
    int minimum, int maximum) const
  {
    const double value = this->number(fields, index, what);
    if (!(value >= minimum && value <= maximum) || value != std::floor(value))
    {
      std::ostringstream s;
      s << "the " << what << " is " << value << ": give a whole number from " << minimum << " to "
        << maximum;
      this->fail(s.str());
    }
    return static_cast<int>(value);
  }

  /// An irradiance, W/m^2; NaN for the EPW's missing values.
  double irradiance(
    const std::vector<std::string_view>& fields, std::size_t index, const char* what) const
  {
    const double value = this->number(fields, index, what);
    if (value >= MissingIrradiance)
    {
      return std::numeric_limits<double>::quiet_NaN();
    }
    if (!(value >= 0 && value <= MaximumIrradiance))
    {
      std::ostringstream s;
      s << "the " << what << " is " << value
        << " Wh/m^2: give 0 to 2000 (no hour of sunlight comes near 2000), or 9999 for a "
           "missing value";
      this->fail(s.str());
    }
    return value;
  }
};

/// The lines of `text` without their line ends; a UTF-8 byte order mark is dropped.
std::vector<std::string_view> splitLines(std::string_view text)
{
  if (text.substr(0, 3) == "\xEF\xBB\xBF")
  {
    text.remove_prefix(3);
  }
  std::vector<std::string_view> lines;
  std::size_t start = 0;
  while (start < text.size())
  {
    const std::size_t end = text.find('\n', start);
    std::string_view line =
      text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start);
    if (!line.empty() && line.back() == '\r')
    {
      line.remove_suffix(1);
    }
    lines.push_back(line);
    if (end == std::string_view::npos)
    {
      break;
    }
    start = end + 1;
  }
  while (!lines.empty() && trim(lines.back()).empty())
  {
    lines.pop_back();
  }
  return lines;
}
}

WeatherFile parseWeatherFile(const std::string& text, const std::string& name)
{
  if (text.size() > MaximumWeatherFileBytes)
  {
    throw Error("the weather file " + name + " has " + std::to_string(text.size()) +
      " bytes, more than the 32 MiB a year of hourly EPW records could need");
  }
  if (text.find('\0') != std::string::npos)
  {
    throw Error("the weather file " + name +
      " holds a zero byte: give an EnergyPlus weather file (.epw), which is text");
  }
  const std::vector<std::string_view> lines = splitLines(text);
  if (lines.size() < HeaderLines)
  {
    throw Error("the weather file " + name + " has " + std::to_string(lines.size()) +
      " lines, fewer than the 8 header lines of an EnergyPlus weather file (LOCATION, DESIGN "
      "CONDITIONS, ... DATA PERIODS) before its hours");
  }
  WeatherFile file;
  file.name = name;
  {
    const Where where{ name, 1 };
    const std::vector<std::string_view> fields = splitFields(lines[0]);
    if (uppercase(fields[0]) != "LOCATION")
    {
      where.fail("starts with '" + shown(fields[0]) +
        "', not LOCATION: give an EnergyPlus weather file (.epw)");
    }
    file.city = std::string(fields.size() > 1 ? fields[1] : std::string_view());
    file.latitude = where.inRange(fields, 6, "latitude", -90, 90, " degrees");
    file.longitude = where.inRange(fields, 7, "longitude", -180, 180, " degrees");
    file.timeZoneHours = where.inRange(fields, 8, "time zone", -12, 14, " hours from UTC");
    file.elevation = where.inRange(fields, 9, "elevation", -1000, 9999.9, " m");
  }
  for (std::size_t k = 1; k < HeaderLines; ++k)
  {
    const Where where{ name, k + 1 };
    const std::vector<std::string_view> fields = splitFields(lines[k]);
    const std::string expected = HeaderNames[k - 1];
    if (uppercase(fields[0]).compare(0, expected.size(), expected) != 0)
    {
      where.fail("starts with '" + shown(fields[0]) + "' where the header line " + expected +
        " belongs: an EnergyPlus weather file has 8 header lines, LOCATION, DESIGN "
        "CONDITIONS, TYPICAL/EXTREME PERIODS, GROUND TEMPERATURES, HOLIDAYS/DAYLIGHT SAVINGS, "
        "COMMENTS 1, COMMENTS 2 and DATA PERIODS");
    }
    if (expected == "DATA PERIODS" && fields.size() > 2 &&
      where.number(fields, 2, "records per hour") != 1)
    {
      where.fail("the file has " + shown(fields[2]) +
        " records per hour: give an hourly file (1 record per hour)");
    }
  }

  const std::size_t records = lines.size() - HeaderLines;
  // The calendar is known from the count; an hour missing or repeated shows as the first
  // line out of order, a file cut short as too few hours.
  const bool leap = records >= LeapYear;
  file.hours.reserve(std::min(records, LeapYear));
  int month = 1, day = 1, hour = 1;
  for (std::size_t k = 0; k < records; ++k)
  {
    const Where where{ name, HeaderLines + k + 1 };
    if (k == LeapYear || month > 12)
    {
      where.fail(std::string("the year ended on the line before, December 31 hour 24, but the "
                             "file goes on: a year of EPW records is 8760 hours (8784 in a "
                             "leap year, with February 29") +
        (leap ? "" : "; this file has fewer than 8784 lines") + ")");
    }
    const std::string_view line = lines[HeaderLines + k];
    if (trim(line).empty())
    {
      where.fail("the line is empty: give one line per hour, without blank lines");
    }
    const std::vector<std::string_view> fields = splitFields(line);
    WeatherHour h;
    h.line = HeaderLines + k + 1;
    h.year = where.whole(fields, 0, "year", 1, 9999);
    h.month = where.whole(fields, 1, "month", 1, 12);
    h.day = where.whole(fields, 2, "day", 1, daysIn(h.month, true));
    h.hour = where.whole(fields, 3, "hour", 1, 24);
    where.inRange(fields, 4, "minute", 0, 60, "");
    h.globalHorizontal =
      where.irradiance(fields, GlobalHorizontalField, "global horizontal irradiance");
    h.directNormal = where.irradiance(fields, DirectNormalField, "direct normal irradiance");
    h.diffuseHorizontal =
      where.irradiance(fields, DiffuseHorizontalField, "diffuse horizontal irradiance");
    if (h.month != month || h.day != day || h.hour != hour)
    {
      std::ostringstream s;
      s << "gives " << MonthNames[h.month - 1] << " " << h.day << " hour " << h.hour << " where "
        << MonthNames[month - 1] << " " << day << " hour " << hour
        << " belongs: give every hour of the year once, in order (" << (leap ? 8784 : 8760)
        << " hours, February 29 " << (leap ? "included" : "left out") << ")";
      where.fail(s.str());
    }
    file.hours.push_back(h);
    if (++hour > 24)
    {
      hour = 1;
      if (++day > daysIn(month, leap))
      {
        day = 1;
        ++month;
      }
    }
  }
  if (records != Year && records != LeapYear)
  {
    std::ostringstream s;
    s << "the weather file " << name << " has " << records << " hourly lines";
    if (records > 0)
    {
      const WeatherHour& h = file.hours.back();
      s << " (lines 9 to " << lines.size() << "), the last " << MonthNames[h.month - 1] << " "
        << h.day << " hour " << h.hour;
    }
    s << ": give a whole year, 8760 hours (8784 in a leap year) to December 31 hour 24";
    throw Error(s.str());
  }
  return file;
}

WeatherFile readWeatherFile(const std::string& path)
{
  const std::string text = readRegularFile(path,
    { "weather file", "an .epw file", MaximumWeatherFileBytes,
      "the 32 MiB a year of hourly EPW records could need" });
  return parseWeatherFile(text, path);
}

std::vector<WeatherFrame> weatherFrames(const WeatherFile& file, const WeatherSelection& s)
{
  for (const auto& [month, day, which] : { std::make_tuple(s.firstMonth, s.firstDay, "first"),
         std::make_tuple(s.lastMonth, s.lastDay, "last") })
  {
    if (month < 1 || month > 12 || day < 1 || day > daysIn(month, true))
    {
      std::ostringstream m;
      m << "the " << which << " date " << month << "-" << day
        << " does not exist: give MM-DD (01-01 to 12-31)";
      throw Error(m.str());
    }
  }
  if (s.firstHour < 0 || s.lastHour > 23 || s.firstHour > s.lastHour)
  {
    throw Error("the hours are " + std::to_string(s.firstHour) + " to " +
      std::to_string(s.lastHour) +
      ": give clock hours from 0 to 23, the first not after the last (8-16 is 08:00 to 17:00)");
  }
  if (file.hours.size() != Year && file.hours.size() != LeapYear)
  {
    throw Error("the weather file " + file.name + " has " + std::to_string(file.hours.size()) +
      " hours: it needs 8760 (8784 in a leap year)");
  }
  const Horizon horizon = horizonOf(s.north, s.up);
  const int first = s.firstMonth * 32 + s.firstDay, last = s.lastMonth * 32 + s.lastDay;
  const bool wraps = last < first;
  const std::size_t n = file.hours.size();
  std::vector<WeatherFrame> frames;
  std::size_t inRange = 0; // the chosen dates and hours, night included
  // With a wrap, the days from the first date to December 31 come first, then January's.
  for (int part = 0; part < (wraps ? 2 : 1); ++part)
  {
    for (std::size_t k = 0; k < n; ++k)
    {
      const WeatherHour& h = file.hours[k];
      const int key = h.month * 32 + h.day;
      const bool chosen =
        !wraps ? key >= first && key <= last : (part == 0 ? key >= first : key <= last);
      const int clockHour = h.hour - 1;
      if (!chosen || clockHour < s.firstHour || clockHour > s.lastHour)
      {
        continue;
      }
      ++inRange;
      WeatherFrame f;
      f.seriesHour = static_cast<double>(k + (part == 1 ? n : 0));
      f.dayOfYear = static_cast<int>(k / 24) + 1;
      f.clockHour = clockHour;
      f.sun = sunAt(file.latitude, file.longitude, h.year, h.month, h.day, clockHour + 0.5,
        file.timeZoneHours, horizon);
      if (!(f.sun.elevationDegrees > 0) && !s.includeNight)
      {
        continue;
      }
      if (std::isnan(h.directNormal) || std::isnan(h.diffuseHorizontal))
      {
        throw Error("the weather file " + file.name + ", line " + std::to_string(h.line) +
          ": the " + (std::isnan(h.directNormal) ? "direct normal" : "diffuse horizontal") +
          " irradiance of a chosen hour is missing (9999 or more): fill it in, or choose dates and "
          "hours without it");
      }
      f.directNormal = h.directNormal;
      f.diffuseHorizontal = h.diffuseHorizontal;
      f.globalHorizontal = h.globalHorizontal;
      f.line = h.line;
      frames.push_back(f);
    }
  }
  if (frames.empty())
  {
    std::ostringstream m;
    m << "no hour of the weather file " << file.name << " is chosen: the dates " << s.firstMonth
      << "-" << s.firstDay << " to " << s.lastMonth << "-" << s.lastDay << " and clock hours "
      << s.firstHour << " to " << s.lastHour << " hold ";
    const bool february29 =
      (s.firstMonth == 2 && s.firstDay == 29) || (s.lastMonth == 2 && s.lastDay == 29);
    if (inRange == 0 && n == Year && february29)
    {
      m << "no hour of the file, which has no February 29 (its year is not a leap year): "
           "choose other dates";
    }
    else
    {
      m << (inRange == 0 ? "no hour of the file" : "only night (the sun below the horizon)")
        << ": widen them" << (inRange == 0 ? "" : " or include the night");
    }
    throw Error(m.str());
  }
  return frames;
}

std::string irradianceClosureWarning(
  const WeatherFile& file, const std::vector<WeatherFrame>& frames)
{
  // Measured files close to a few percent (hourly means against the sun at mid-hour); a time
  // zone of the wrong sign (Paris at -1) gives 21%, the shipped synthetic year 0.3%.
  constexpr double HighSunDegrees = 10, MostDeparture = 0.15;
  constexpr std::size_t FewestHours = 10;
  double departure = 0, global = 0;
  std::size_t hours = 0;
  for (const WeatherFrame& f : frames)
  {
    if (f.sun.elevationDegrees > HighSunDegrees && std::isfinite(f.globalHorizontal))
    {
      const double sine = std::sin(f.sun.elevationDegrees * M_PI / 180);
      departure += std::abs(f.globalHorizontal - (f.directNormal * sine + f.diffuseHorizontal));
      global += f.globalHorizontal;
      ++hours;
    }
  }
  if (hours < FewestHours || !(global > 0) || departure <= MostDeparture * global)
  {
    return {};
  }
  std::ostringstream s;
  s << "the weather file " << file.name << ": over " << hours
    << " chosen hours with the sun above 10 degrees, its global horizontal irradiance departs by "
    << std::lround(100 * departure / global)
    << "% from its direct normal times the sine of the sun's elevation plus its diffuse "
       "horizontal: the sun computed for its place (longitude "
    << formatNumber(file.longitude) << ") and time zone (" << formatNumber(file.timeZoneHours)
    << " h, east of Greenwich positive) may be hours off; check the LOCATION line";
  return s.str();
}

std::string directNormalAboveTheSunWarning(
  const WeatherFile& file, const std::vector<WeatherFrame>& frames)
{
  std::size_t count = 0;
  const WeatherFrame* first = nullptr;
  for (const WeatherFrame& f : frames)
  {
    if (f.directNormal > MostDirectNormalIrradiance)
    {
      first = first ? first : &f;
      ++count;
    }
  }
  if (!first)
  {
    return {};
  }
  return "the weather file " + file.name + ": " + countOf(count, "chosen hour") +
    (count == 1 ? " gives" : " give") +
    " a direct normal irradiance above the sun's outside the atmosphere (" +
    formatNumber(MostDirectNormalIrradiance) + " W/m^2), the first " +
    formatNumber(first->directNormal) + " W/m^2 on line " + std::to_string(first->line) +
    ": check that its columns are read as the EPW orders them (field 15 is the direct normal "
    "irradiance) and that its unit is Wh/m^2";
}

} // namespace mlr
