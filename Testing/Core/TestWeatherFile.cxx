// EnergyPlus weather files: the reader on a good year and on each kind of malformed file (its
// message naming the line), the hours chosen as frames, their sun against sunPath, and the
// day of the year in the Perez sky.
#include "CoreChecks.h"
#include "Sky.h"
#include "SunPath.h"
#include "WeatherFile.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <unistd.h>
#include <vector>

using namespace mlr;
using mlr::checks::expectError;

namespace
{
const int DaysIn[] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };

/// The 8 header lines of a weather file at Paris in UTC+1.
std::string header()
{
  return "LOCATION,Paris,IDF,FRA,test,071560,48.85,2.35,1.0,35.0\n"
         "DESIGN CONDITIONS,0\n"
         "TYPICAL/EXTREME PERIODS,0\n"
         "GROUND TEMPERATURES,0\n"
         "HOLIDAYS/DAYLIGHT SAVINGS,No,0,0,0\n"
         "COMMENTS 1,none\n"
         "COMMENTS 2,none\n"
         "DATA PERIODS,1,1,Data,Sunday,1/1,12/31\n";
}

/// One data line: the irradiances encode the hour, GHI = index, DNI = 500 + hour, DHI = day.
std::string record(int year, int month, int day, int hour, std::size_t index)
{
  std::ostringstream s;
  s << year << "," << month << "," << day << "," << hour << ",60,*9,10.0,5.0,70,101325,0,0,300,"
    << index % 1000 << "," << 500 + hour << "," << day
    << ",0,0,0,9999,180,2.0,5,5,9999,77777,9,999999999,15,0.1,0,88,0.2,0,1\n";
  return s.str();
}

/// A whole year of data lines (8784 hours in a leap year), line k of the data being the
/// file's line 9 + k.
std::vector<std::string> year(bool leap)
{
  std::vector<std::string> lines;
  for (int month = 1; month <= 12; ++month)
  {
    const int days = DaysIn[month - 1] + (leap && month == 2 ? 1 : 0);
    for (int day = 1; day <= days; ++day)
    {
      for (int hour = 1; hour <= 24; ++hour)
      {
        lines.push_back(record(leap ? 2024 : 2023, month, day, hour, lines.size()));
      }
    }
  }
  return lines;
}

std::string join(const std::vector<std::string>& lines)
{
  std::string text = header();
  for (const std::string& line : lines)
  {
    text += line;
  }
  return text;
}

/// The data line at file line `line` (9 is the first hour) with field `field` (0-based)
/// replaced by `value`.
std::string withField(int line, std::size_t field, const std::string& value)
{
  std::vector<std::string> lines = year(false);
  std::string& l = lines[static_cast<std::size_t>(line - 9)];
  std::vector<std::string> fields(1);
  for (char c : l.substr(0, l.size() - 1))
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
  fields[field] = value;
  l.clear();
  for (std::size_t k = 0; k < fields.size(); ++k)
  {
    l += (k ? "," : "") + fields[k];
  }
  l += "\n";
  return join(lines);
}

void expectLineError(const std::string& text, int line, const std::string& words)
{
  expectError([&] { parseWeatherFile(text, "t.epw"); },
    "the weather file t.epw, line " + std::to_string(line) + ": ");
  expectError([&] { parseWeatherFile(text, "t.epw"); }, words);
}
}

TEST(WeatherFile, ReadsTheLocationAndEveryHour)
{
  const WeatherFile file = parseWeatherFile(join(year(false)), "t.epw");
  EXPECT_EQ(file.city, "Paris");
  EXPECT_DOUBLE_EQ(file.latitude, 48.85);
  EXPECT_DOUBLE_EQ(file.longitude, 2.35);
  EXPECT_DOUBLE_EQ(file.timeZoneHours, 1.0);
  EXPECT_DOUBLE_EQ(file.elevation, 35.0);
  ASSERT_EQ(file.hours.size(), 8760u);
  EXPECT_FALSE(file.leapYear());
  const WeatherHour& h = file.hours[4000];
  EXPECT_EQ(h.line, 4009u);
  EXPECT_EQ(h.month, 6);
  EXPECT_EQ(h.day, 16);
  EXPECT_EQ(h.hour, 17);
  // Fields 14, 15 and 16 (from 1): global horizontal, direct normal, diffuse horizontal.
  EXPECT_DOUBLE_EQ(h.globalHorizontal, 0);
  EXPECT_DOUBLE_EQ(h.directNormal, 517);
  EXPECT_DOUBLE_EQ(h.diffuseHorizontal, 16);

  const WeatherFile leap = parseWeatherFile(join(year(true)), "t.epw");
  ASSERT_EQ(leap.hours.size(), 8784u);
  EXPECT_TRUE(leap.leapYear());
  EXPECT_EQ(leap.hours[59 * 24].month, 2);
  EXPECT_EQ(leap.hours[59 * 24].day, 29);

  // Line ends of Windows, a byte order mark and blank lines at the end are read too.
  std::string windows = "\xEF\xBB\xBF";
  for (char c : join(year(false)))
  {
    windows += c == '\n' ? std::string("\r\n") : std::string(1, c);
  }
  EXPECT_EQ(parseWeatherFile(windows + "\r\n\r\n", "t.epw").hours.size(), 8760u);
  // Missing values (9999 and up) are NaN.
  const WeatherFile missing = parseWeatherFile(withField(20, 14, "9999"), "t.epw");
  EXPECT_TRUE(std::isnan(missing.hours[11].directNormal));
  EXPECT_FALSE(std::isnan(missing.hours[11].diffuseHorizontal));
}

TEST(WeatherFile, MalformedFilesAreRefusedAtTheirLine)
{
  // The header.
  std::string text = join(year(false));
  expectLineError("PLACE" + text.substr(8), 1, "not LOCATION");
  expectLineError(
    "LOCATION,Paris,IDF,FRA,test,071560,95,2.35,1.0,35.0" + text.substr(text.find('\n')), 1,
    "latitude is 95");
  expectLineError(
    "LOCATION,Paris,IDF,FRA,test,071560,48.85,east,1.0,35.0" + text.substr(text.find('\n')), 1,
    "field 8 (longitude) is 'east': give a number");
  expectLineError("LOCATION,Paris,IDF,FRA,test,071560,48.85,2.35" + text.substr(text.find('\n')), 1,
    "field 9 (time zone) is needed");
  {
    std::string noComments = text;
    const std::size_t at = noComments.find("COMMENTS 2");
    noComments.erase(at, noComments.find('\n', at) + 1 - at);
    expectLineError(noComments, 7, "where the header line COMMENTS 2 belongs");
  }
  {
    std::string halfHours = text;
    halfHours.replace(halfHours.find("DATA PERIODS,1,1"), 16, "DATA PERIODS,1,2");
    expectLineError(halfHours, 8, "2 records per hour");
  }
  // The hours: fields missing, text, ranges, order.
  expectLineError(withField(100, 15, "12;"), 100, "field 16 (diffuse horizontal irradiance)");
  expectLineError(withField(101, 14, "-3"), 101, "direct normal irradiance is -3");
  expectLineError(withField(102, 13, "2500"), 102, "global horizontal irradiance is 2500");
  expectLineError(withField(103, 1, "13"), 103, "month is 13");
  expectLineError(withField(104, 2, "32"), 104, "day is 32");
  expectLineError(withField(105, 3, "0"), 105, "hour is 0");
  expectLineError(withField(106, 3, "7.5"), 106, "hour is 7.5");
  expectLineError(withField(107, 3, "99"), 107, "hour is 99");
  expectLineError(withField(108, 0, "1995x"), 108, "field 1 (year) is '1995x'");
  // Hexadecimal and infinity are text (strtod took them as 500 and inf).
  expectLineError(
    withField(109, 14, "0x1F4"), 109, "field 15 (direct normal irradiance) is '0x1F4'");
  expectLineError(
    withField(110, 15, "inf"), 110, "field 16 (diffuse horizontal irradiance) is 'inf'");
  {
    std::vector<std::string> lines = year(false);
    lines[500] = "2023,1,21,9,60\n";
    expectLineError(join(lines), 509, "has 5 fields, but field 14");
    lines = year(false);
    lines.erase(lines.begin() + 1000);
    expectLineError(
      join(lines), 1009, "gives February 11 hour 18 where February 11 hour 17 belongs");
    // A day of the file that does not exist in its calendar: February 29 of 8760 hours.
    lines = year(false);
    lines[59 * 24] = record(2023, 2, 29, 1, 0);
    expectLineError(join(lines), 59 * 24 + 9, "February 29 hour 1 where March 1 hour 1 belongs");
    lines = year(false);
    lines[2000] = "\n";
    expectLineError(join(lines), 2009, "the line is empty");
    lines = year(false);
    lines.push_back(record(2024, 1, 1, 1, 0));
    expectLineError(join(lines), 8769, "the year ended on the line before");
  }
  // Too few hours: the last one read is named.
  {
    std::vector<std::string> lines = year(false);
    lines.resize(4000);
    expectError([&] { parseWeatherFile(join(lines), "t.epw"); },
      "has 4000 hourly lines (lines 9 to 4008), the last June 16 hour 16: give a whole year");
  }
  expectError([] { parseWeatherFile(header(), "t.epw"); }, "has 0 hourly lines");
  expectError([] { parseWeatherFile("LOCATION,a\n", "t.epw"); }, "fewer than the 8 header lines");
  expectError([] { parseWeatherFile(std::string("LOC\0ATION", 9), "t.epw"); }, "zero byte");
  expectError([] { parseWeatherFile(std::string(MaximumWeatherFileBytes + 1, 'x'), "t.epw"); },
    "more than the 32 MiB");
}

TEST(WeatherFile, OnlyRegularFilesOfBoundedSizeAreRead)
{
  expectError([] { readWeatherFile("/nonexistent/x.epw"); }, "cannot read the weather file");
  expectError([] { readWeatherFile("/dev/null"); }, "not a regular file");
  expectError([] { readWeatherFile("/tmp"); }, "not a regular file");
  char name[] = "/tmp/mlr-weather-XXXXXX";
  const int fd = mkstemp(name);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(ftruncate(fd, static_cast<off_t>(MaximumWeatherFileBytes) + 1), 0);
  close(fd);
  expectError([&] { readWeatherFile(name); }, "more than the 32 MiB");
  {
    std::ofstream out(name, std::ios::trunc);
    out << join(year(false));
  }
  EXPECT_EQ(readWeatherFile(name).hours.size(), 8760u);
  std::remove(name);
}

TEST(WeatherFile, HoursAreChosenByDateHourAndDaylight)
{
  const WeatherFile file = parseWeatherFile(join(year(false)), "t.epw");
  WeatherSelection s;
  s.firstMonth = 6;
  s.firstDay = 21;
  s.lastMonth = 6;
  s.lastDay = 22;
  s.firstHour = 3;
  s.lastHour = 5;
  s.includeNight = true;
  std::vector<WeatherFrame> frames = weatherFrames(file, s);
  ASSERT_EQ(frames.size(), 6u);
  // June 21 is day 172; its hour starting at 03:00 is the file's hour 4, index 171 * 24 + 3.
  EXPECT_DOUBLE_EQ(frames[0].seriesHour, 171 * 24 + 3);
  EXPECT_EQ(frames[0].dayOfYear, 172);
  EXPECT_EQ(frames[0].clockHour, 3);
  EXPECT_DOUBLE_EQ(frames[0].sun.clockHours, 3.5);
  EXPECT_DOUBLE_EQ(frames[0].directNormal, 504);
  EXPECT_DOUBLE_EQ(frames[0].diffuseHorizontal, 21);
  EXPECT_EQ(frames[0].line, 171u * 24 + 3 + 9);
  EXPECT_DOUBLE_EQ(frames[5].seriesHour, 172 * 24 + 5);
  // In Paris (UTC+1) the sun rises at about 04:47 in June (clock time, no summer time): the
  // hours starting at 3 and 4 are night (mid-hour at 03:30 and 04:30), 05:30 is day.
  EXPECT_LT(frames[0].sun.elevationDegrees, 0);
  EXPECT_LT(frames[1].sun.elevationDegrees, 0);
  EXPECT_GT(frames[2].sun.elevationDegrees, 0);
  s.includeNight = false;
  frames = weatherFrames(file, s);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].clockHour, 5);
  EXPECT_EQ(frames[1].dayOfYear, 173);

  // A selection over the new year: December 31 first, then January 1 after the year's hours.
  s = WeatherSelection();
  s.firstMonth = 12;
  s.firstDay = 31;
  s.lastMonth = 1;
  s.lastDay = 1;
  s.firstHour = 12;
  s.lastHour = 12;
  frames = weatherFrames(file, s);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_DOUBLE_EQ(frames[0].seriesHour, 364 * 24 + 12);
  EXPECT_EQ(frames[0].dayOfYear, 365);
  EXPECT_DOUBLE_EQ(frames[1].seriesHour, 8760 + 12);
  EXPECT_EQ(frames[1].dayOfYear, 1);

  // A whole year keeps about half its hours as day.
  frames = weatherFrames(file, WeatherSelection());
  EXPECT_GT(frames.size(), 4300u);
  EXPECT_LT(frames.size(), 4600u);
  for (const WeatherFrame& f : frames)
  {
    EXPECT_GT(f.sun.elevationDegrees, 0);
  }

  s = WeatherSelection();
  s.firstMonth = 12;
  s.firstDay = 21;
  s.lastMonth = 12;
  s.lastDay = 21;
  s.firstHour = 0;
  s.lastHour = 5;
  expectError([&] { weatherFrames(file, s); }, "only night");
  // February 29 of a file that is not of a leap year: no hour at all, said so.
  WeatherSelection leapDay;
  leapDay.firstMonth = leapDay.lastMonth = 2;
  leapDay.firstDay = leapDay.lastDay = 29;
  leapDay.firstHour = leapDay.lastHour = 12;
  expectError([&] { weatherFrames(file, leapDay); }, "which has no February 29");
  s.lastHour = 24;
  expectError([&] { weatherFrames(file, s); }, "clock hours from 0 to 23");
  s.lastHour = 5;
  s.lastDay = 32;
  expectError([&] { weatherFrames(file, s); }, "does not exist");
  s = WeatherSelection();
  s.north = { 0, 0, 1 };
  expectError([&] { weatherFrames(file, s); }, "north");

  // A missing irradiance matters only in a chosen hour.
  const WeatherFile missing = parseWeatherFile(withField(4000, 15, "99999"), "t.epw");
  s = WeatherSelection();
  s.firstMonth = s.lastMonth = 6;
  s.firstDay = s.lastDay = 16;
  expectError([&] { weatherFrames(missing, s); },
    "line 4000: the diffuse horizontal irradiance of a chosen hour is missing (9999 or more)");
  s.firstDay = s.lastDay = 17;
  EXPECT_NO_THROW(weatherFrames(missing, s));
}

TEST(WeatherFile, TheSunOfAnHourIsTheSunPathsAtItsMiddle)
{
  const WeatherFile file = parseWeatherFile(join(year(false)), "t.epw");
  WeatherSelection s;
  s.firstMonth = s.lastMonth = 3;
  s.firstDay = s.lastDay = 20;
  s.firstHour = s.lastHour = 10; // 10:00 to 11:00, file hour 11
  s.north = { 1, 0, 0 };
  s.up = { 0, 1, 0 };
  const std::vector<WeatherFrame> frames = weatherFrames(file, s);
  ASSERT_EQ(frames.size(), 1u);
  SunPathRequest r;
  r.latitude = 48.85;
  r.longitude = 2.35;
  r.year = 2023;
  r.month = 3;
  r.day = 20;
  r.startHour = 10.5;
  r.endHour = 11.5;
  r.stepMinutes = 60;
  r.timeZoneHours = 1;
  r.north = s.north;
  r.up = s.up;
  const SunPosition p = sunPath(r).front();
  EXPECT_DOUBLE_EQ(frames[0].sun.azimuthDegrees, p.azimuthDegrees);
  EXPECT_DOUBLE_EQ(frames[0].sun.elevationDegrees, p.elevationDegrees);
  EXPECT_NEAR(length(frames[0].sun.direction - p.direction), 0, 1e-15);
  // At an equinox in Paris, 10:30 UTC+1 is about 09:32 local solar time: the sun is in the
  // south-east, some 30 degrees up.
  EXPECT_NEAR(p.elevationDegrees, 31, 2);
  EXPECT_GT(p.azimuthDegrees, 120);
  EXPECT_LT(p.azimuthDegrees, 150);
}

TEST(WeatherFile, TheDayOfTheYearSetsThePerezExtraterrestrialIrradiance)
{
  // Delta = E_dh m / (1367 eccentricity): the Earth is nearest the sun in early January
  // (eccentricity 1.0342 on day 1) and farthest in early July (0.9669 on day 185), so the
  // same diffuse irradiance is a brighter sky in July by the ratio of the two.
  const Vec3 sun = normalize(Vec3{ 0.5, 0, 0.6 });
  const SkyDistribution january(SkyModel::Perez, sun, 150, 600, 1);
  const SkyDistribution july(SkyModel::Perez, sun, 150, 600, 185);
  const SkyDistribution unknown(SkyModel::Perez, sun, 150, 600);
  const SkyDistribution day150(SkyModel::Perez, sun, 150, 600, 150);
  const auto eccentricity = [](int day)
  {
    const double a = 2 * M_PI * (day - 1) / 365.0;
    return 1.00011 + 0.034221 * std::cos(a) + 0.00128 * std::sin(a) + 0.000719 * std::cos(2 * a) +
      0.000077 * std::sin(2 * a);
  };
  EXPECT_NEAR(july.brightness() / january.brightness(), eccentricity(1) / eccentricity(185), 1e-12);
  EXPECT_GT(july.brightness() / january.brightness(), 1.06);
  EXPECT_DOUBLE_EQ(unknown.brightness(), day150.brightness());
  // The sky's shape changes with it, and a Sky keeps frames of different days apart.
  const Vec3 zenith{ 0, 0, 1 };
  EXPECT_NE(january(zenith), july(zenith));
  const Sky sky(
    SkyModel::Perez, zenith, { SkyFrame{ sun, 150, 600, 1 }, SkyFrame{ sun, 150, 600, 185 } });
  EXPECT_EQ(sky.positions(), 2u);
  const Sky same(
    SkyModel::Perez, zenith, { SkyFrame{ sun, 150, 600, 9 }, SkyFrame{ sun, 150, 600, 9 } });
  EXPECT_EQ(same.positions(), 1u);
  expectError(
    [&] {
      Sky(SkyModel::Perez, zenith, { SkyFrame{ sun, 150, 600, 367 } });
    },
    "day of the year of frame 0 is 367");
  // The luminous efficacy reads it too.
  EXPECT_NE(perezEfficacy(SkyFrame{ sun, 150, 600, 1 }, zenith).diffuse,
    perezEfficacy(SkyFrame{ sun, 150, 600, 185 }, zenith).diffuse);
}

TEST(WeatherFile, IrradiancesThatDisagreeWithTheirSunAreWarnedOf)
{
  // The sun at 30 degrees with 600 W/m^2 direct and 100 diffuse closes at 400 global; the
  // same hours under a sun at 60 degrees (a time zone of the wrong sign puts the sun hours
  // off) depart by 55%.
  WeatherFile file;
  file.name = "t.epw";
  file.longitude = 2.35;
  file.timeZoneHours = -1;
  auto hours = [](double elevation, double global, std::size_t count)
  {
    WeatherFrame f;
    f.sun.elevationDegrees = elevation;
    f.directNormal = 600;
    f.diffuseHorizontal = 100;
    f.globalHorizontal = global;
    return std::vector<WeatherFrame>(count, f);
  };
  EXPECT_EQ(irradianceClosureWarning(file, hours(30, 400, 20)), "");
  const std::string warning = irradianceClosureWarning(file, hours(60, 400, 20));
  EXPECT_NE(warning.find("t.epw: over 20 chosen hours"), std::string::npos) << warning;
  EXPECT_NE(warning.find("departs by 55%"), std::string::npos) << warning;
  EXPECT_NE(warning.find("time zone (-1 h, east of Greenwich positive)"), std::string::npos)
    << warning;
  // Too few hours, a low sun, or an unknown global: nothing to judge by.
  EXPECT_EQ(irradianceClosureWarning(file, hours(60, 400, 9)), "");
  EXPECT_EQ(irradianceClosureWarning(file, hours(8, 100, 20)), "");
  EXPECT_EQ(irradianceClosureWarning(file, hours(60, std::nan(""), 20)), "");
}

TEST(WeatherFile, ADirectNormalAboveTheSunsOutsideTheAtmosphereIsWarnedOf)
{
  WeatherFile file;
  file.name = "t.epw";
  std::vector<WeatherFrame> hours(3);
  hours[0].directNormal = 900;
  hours[1].directNormal = MostDirectNormalIrradiance; // the sun at its nearest: possible
  hours[2].directNormal = 1500;
  hours[2].line = 4391;
  EXPECT_EQ(directNormalAboveTheSunWarning(file, { hours[0], hours[1] }), "");
  const std::string warning = directNormalAboveTheSunWarning(file, hours);
  EXPECT_NE(warning.find("t.epw: 1 chosen hour gives a direct normal irradiance above the sun's "
                         "outside the atmosphere (1408 W/m^2), the first 1500 W/m^2 on line 4391"),
    std::string::npos)
    << warning;
}

TEST(WeatherFile, TheShippedYearReads)
{
  const WeatherFile file = readWeatherFile(MLR_SOURCE_DIR "/Data/paris_synthetic.epw");
  EXPECT_EQ(file.hours.size(), 8760u);
  EXPECT_DOUBLE_EQ(file.timeZoneHours, 1.0);
  const std::vector<WeatherFrame> frames = weatherFrames(file, WeatherSelection());
  EXPECT_EQ(irradianceClosureWarning(file, frames), "");
  for (const WeatherFrame& f : frames)
  {
    // Its model has light whenever the sun at the middle of the hour is up (NOAA's formulas
    // and libnova agree to a few hundredths of a degree: near the horizon it may be dark).
    if (f.sun.elevationDegrees > 0.5)
    {
      EXPECT_GT(f.diffuseHorizontal, 0) << "line " << f.line;
    }
    EXPECT_NEAR(f.globalHorizontal,
      f.directNormal * std::max(0.0, f.sun.direction.z) + f.diffuseHorizontal, 6)
      << "line " << f.line;
  }
}
