// Weather files: the hourly sun and sky of a year at a place, read from an EnergyPlus weather
// file (.epw), and the hours of it chosen as frames (Documentation/Method.md, "The sky").
#pragma once

#include "SunPath.h"
#include "Vec3.h"

#include <cstddef>
#include <string>
#include <vector>

namespace mlr
{

/// One hour of a weather file, as the file gives it.
struct WeatherHour
{
  int year = 0, month = 0, day = 0;
  int hour = 0; ///< 1 to 24: the hour ENDING at this clock time (1 is 00:00 to 01:00)
  /// Irradiances, W/m^2: the file's Wh/m^2 over the hour, its mean. NaN where the file marks
  /// the value missing (9999 or more).
  double globalHorizontal = 0, directNormal = 0, diffuseHorizontal = 0;
  std::size_t line = 0; ///< its line in the file, from 1
};

/// An EnergyPlus weather file: its place and its 8760 (or 8784, a leap year) hours in order.
struct WeatherFile
{
  std::string name; ///< the file, as messages name it
  std::string city;
  double latitude = 0;      ///< degrees, north positive
  double longitude = 0;     ///< degrees, east positive
  double timeZoneHours = 0; ///< the file's clock (standard time) minus UTC
  double elevation = 0;     ///< metres
  std::vector<WeatherHour> hours;

  bool leapYear() const { return this->hours.size() == 8784; }
};

/// The largest weather file read: a year of hourly EPW records is about 1.7 MB.
constexpr std::size_t MaximumWeatherFileBytes = 32u << 20;

/**
 * Parses the text of an EPW file: the LOCATION line (latitude, longitude, time zone,
 * elevation), the seven other header lines (DESIGN CONDITIONS ... DATA PERIODS, each checked
 * to be there) and 8760 or 8784 hourly lines, each at least to its diffuse horizontal
 * irradiance (field 16), in calendar order from January 1, hour 1. Throws mlr::Error naming
 * `name`, the line and what to fix: a missing line or field, text where a number belongs, a
 * value out of its range (a latitude beyond +-90, a negative irradiance, a month, day or hour
 * that does not exist or is out of order), a wrong number of hours, a text over
 * MaximumWeatherFileBytes.
 */
WeatherFile parseWeatherFile(const std::string& text, const std::string& name);

/// Reads and parses a regular file of at most MaximumWeatherFileBytes; throws mlr::Error.
WeatherFile readWeatherFile(const std::string& path);

/// Which hours of a weather file become frames.
struct WeatherSelection
{
  /// The first and last days, both included; a last day before the first wraps over the new
  /// year (12-01 to 01-31 is December and January). February 29 exists in any file (in a
  /// file of 8760 hours it selects nothing of its own).
  int firstMonth = 1, firstDay = 1, lastMonth = 12, lastDay = 31;
  /// The first and last clock hours of each day, 0 to 23, each naming the hour that starts
  /// then (8 is 08:00 to 09:00, the file's hour 9); first <= last.
  int firstHour = 0, lastHour = 23;
  /// Also the hours whose sun is below the horizon at their middle.
  bool includeNight = false;
  Vec3 north{ 0, 1, 0 }; ///< the scene's north, horizontal
  Vec3 up{ 0, 0, 1 };    ///< the scene's zenith
};

/// One chosen hour: its sun at the middle of the hour and its irradiances.
struct WeatherFrame
{
  /// Hours from January 1 00:00 to the start of this hour (0 is Jan 1 00:00 to 01:00), plus
  /// the year's hours (8760 or 8784) for the days after a selection wrapped over the new year,
  /// so that the frames' times increase.
  double seriesHour = 0;
  int dayOfYear = 1; ///< 1 to 365 (366)
  int clockHour = 0; ///< 0 to 23: the hour starts at this clock time
  SunPosition sun;   ///< at clockHour + 0.5, the file's time zone
  double directNormal = 0, diffuseHorizontal = 0, globalHorizontal = 0; ///< W/m^2
  std::size_t line = 0;                                                 ///< of the hour in the file
};

/**
 * The hours of `file` within the selection, in the selection's order, with the sun seen from
 * the file's place at the middle of each hour. Throws mlr::Error for a date or hour that does
 * not exist, a north that is not horizontal, a chosen hour whose direct normal or diffuse
 * horizontal irradiance the file marks missing (naming its line), and a selection that keeps
 * no hour.
 */
std::vector<WeatherFrame> weatherFrames(const WeatherFile& file, const WeatherSelection& selection);

/**
 * A warning when the chosen hours' irradiances disagree with their sun: over the hours whose
 * sun stands above 10 degrees and whose global horizontal irradiance is known (10 at least),
 * the global departs from the direct normal times the sine of the elevation plus the diffuse
 * horizontal by more than 15% of it, as when the file's time zone or longitude is wrong (a
 * sign flipped shifts every hour's sun by hours). Empty when they agree or too few hours count.
 */
std::string irradianceClosureWarning(
  const WeatherFile& file, const std::vector<WeatherFrame>& frames);

/// The sun's direct normal irradiance outside the atmosphere at its nearest (January):
/// the solar constant, 1361 W/m^2, times (1 + 0.034). No hour on the ground exceeds it.
constexpr double MostDirectNormalIrradiance = 1408;

/**
 * A warning when chosen hours give a direct normal irradiance above the sun's outside the
 * atmosphere (MostDirectNormalIrradiance), naming how many and the file line of the first:
 * a column taken for another, or a unit that is not W/m^2. Empty when none does.
 */
std::string directNormalAboveTheSunWarning(
  const WeatherFile& file, const std::vector<WeatherFrame>& frames);

} // namespace mlr
