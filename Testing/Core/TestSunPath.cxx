// Solar positions against published references, and the sun path's directions and errors.
#include "CoreChecks.h"
#include "SunPath.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

using namespace mlr;
using mlr::checks::expectError;

namespace
{
/// The Julian day of a UTC calendar time (the proleptic Gregorian calendar, after 1582).
double julianDay(int year, int month, int day, double hours)
{
  const int a = (14 - month) / 12;
  const int y = year + 4800 - a;
  const int m = month + 12 * a - 3;
  const long jdn = day + (153 * m + 2) / 5 + 365L * y + y / 4 - y / 100 + y / 400 - 32045;
  return static_cast<double>(jdn) - 0.5 + hours / 24.0;
}
}

TEST(SunPath, MatchesTheSolarPositionAlgorithmExample)
{
  // Reda & Andreas, "Solar Position Algorithm for Solar Radiation Applications" (NREL, 2004),
  // table A4.1: Golden, Colorado, 2003-10-17 12:30:30 local time (UTC-7): topocentric zenith
  // 50.11162 degrees (with refraction, about 0.02 degrees at this height), azimuth 194.34024.
  double azimuth = 0, elevation = 0;
  sunAzimuthElevation(
    39.742476, -105.1786, julianDay(2003, 10, 17, 19.5 + 30.0 / 3600), azimuth, elevation);
  EXPECT_NEAR(elevation, 90 - 50.11162, 0.1);
  EXPECT_NEAR(azimuth, 194.34024, 0.1);
}

TEST(SunPath, MatchesTheAlmanacAtJ2000)
{
  // At J2000.0 (2000-01-01 12:00 UTC) the Sun's apparent declination is -23.03 degrees and
  // the equation of time -3.3 minutes (Astronomical Almanac): at the Greenwich observatory
  // (51.4769 N) the Sun is 0.8 degrees of hour angle before transit, at an elevation of
  // 90 - 51.4769 - 23.0325 = 15.49 degrees, nearly due south.
  double azimuth = 0, elevation = 0;
  sunAzimuthElevation(51.4769, -0.0005, julianDay(2000, 1, 1, 12), azimuth, elevation);
  EXPECT_NEAR(elevation, 15.49, 0.1);
  EXPECT_NEAR(azimuth, 179.1, 0.3);
}

TEST(SunPath, TheJuneSolsticeSunIsOnTheMeridianOfRightAscension90InAnyYear)
{
  // At a June solstice the Sun's apparent right ascension is 90 degrees and its declination
  // the obliquity of the day. So at that instant, on the meridian whose local sidereal time is
  // 90 degrees (the Greenwich mean sidereal time of IAU 1982; the equation of the equinoxes,
  // under 0.005 degrees, left out), the Sun transits: due south of 50 N, at 40 degrees plus
  // the obliquity. Solstices (UTC): 2000-06-21 01:48, 2021-06-21 03:32, 2024-06-20 20:51.
  // Coordinates referred to J2000 instead would miss by 0.014 degrees of right ascension a
  // year, twice that of azimuth here: 0.6 degrees in 2021.
  struct Solstice
  {
    int year, day;
    double hours;
  };
  for (const Solstice s : { Solstice{ 2000, 21, 1.8 }, Solstice{ 2021, 21, 3 + 32.0 / 60 },
         Solstice{ 2024, 20, 20 + 51.0 / 60 } })
  {
    SCOPED_TRACE(s.year);
    const double jd = julianDay(s.year, 6, s.day, s.hours);
    const double d = jd - 2451545.0, t = d / 36525;
    const double gmst =
      280.46061837 + 360.98564736629 * d + 0.000387933 * t * t - t * t * t / 38710000;
    const double longitude = std::remainder(90 - gmst, 360.0);
    const double obliquity = 23.439291 - 0.0130042 * t;
    double azimuth = 0, elevation = 0;
    sunAzimuthElevation(50, longitude, jd, azimuth, elevation);
    EXPECT_NEAR(azimuth, 180, 0.03);
    EXPECT_NEAR(elevation, 40 + obliquity, 0.01);
  }
}

TEST(SunPath, DirectionsFollowNorthAndUp)
{
  // Equator at an equinox, local noon at longitude 0: the sun is nearly overhead. With north
  // +y and up +z, the morning sun is in the east (+x), the evening sun in the west (-x).
  SunPathRequest r;
  r.latitude = 0;
  r.longitude = 0;
  r.year = 2024;
  r.month = 3;
  r.day = 20;
  r.startHour = 6.5;
  r.endHour = 17.5;
  r.stepMinutes = 60;
  const std::vector<SunPosition> path = sunPath(r);
  ASSERT_EQ(path.size(), 12u);
  EXPECT_DOUBLE_EQ(path.front().clockHours, 6.5);
  EXPECT_DOUBLE_EQ(path.back().clockHours, 17.5);
  for (const SunPosition& p : path)
  {
    EXPECT_NEAR(length(p.direction), 1.0, 1e-12);
    EXPECT_NEAR(std::asin(p.direction.z) * 180 / M_PI, p.elevationDegrees, 1e-9);
  }
  EXPECT_GT(path.front().direction.x, 0.9);
  EXPECT_LT(path.back().direction.x, -0.9);
  EXPECT_GT(path[5].elevationDegrees, 80); // 11:30
  EXPECT_GT(path[6].elevationDegrees, 80); // 12:30

  // A scene whose north is +x and up +y: the morning sun is in the east, -z (x cross y = z
  // points west... east = north x up).
  r.north = { 1, 0, 0 };
  r.up = { 0, 1, 0 };
  const std::vector<SunPosition> turned = sunPath(r);
  const Vec3 east = cross(r.north, r.up);
  EXPECT_GT(dot(turned.front().direction, east), 0.9);
}

TEST(SunPath, NightFramesAreKeptBelowTheHorizon)
{
  SunPathRequest r;
  r.latitude = 48.85;
  r.longitude = 2.35;
  r.year = 2021;
  r.month = 12;
  r.day = 21;
  r.timeZoneHours = 1;
  r.startHour = 0;
  r.endHour = 24;
  r.stepMinutes = 30;
  const std::vector<SunPosition> path = sunPath(r);
  ASSERT_EQ(path.size(), 49u);
  EXPECT_LT(path.front().elevationDegrees, -50); // midnight in Paris in winter
  EXPECT_LT(path.front().direction.z, 0);
  double highest = -90;
  for (const SunPosition& p : path)
  {
    highest = std::max(highest, p.elevationDegrees);
  }
  // Winter solstice noon: 90 - 48.85 - 23.44 = 17.7 degrees.
  EXPECT_NEAR(highest, 17.7, 0.3);
}

TEST(SunPath, BadRequestsSayWhatToFix)
{
  SunPathRequest r;
  r.latitude = 91;
  expectError([&] { sunPath(r); }, "latitude");
  r = SunPathRequest();
  r.month = 2;
  r.day = 30;
  expectError([&] { sunPath(r); }, "does not exist");
  r = SunPathRequest();
  r.startHour = 18;
  r.endHour = 6;
  expectError([&] { sunPath(r); }, "end time is before the start");
  // One instant: the same time twice is one frame.
  r.endHour = 18;
  EXPECT_EQ(sunPath(r).size(), 1u);
  r = SunPathRequest();
  r.year = 2023;
  r.month = 2;
  r.day = 29;
  expectError([&] { sunPath(r); }, "the date 2023-02-29 does not exist");
  r = SunPathRequest();
  r.stepMinutes = 0;
  expectError([&] { sunPath(r); }, "step");
  // A positive step too small for the frame limit is shown as given, not as 0.000000.
  r.stepMinutes = 1e-9;
  expectError([&] { sunPath(r); }, "the step is 1e-09 minutes");
  r = SunPathRequest();
  r.north = { 0, 0, 1 };
  expectError([&] { sunPath(r); }, "north");
}

TEST(SunPath, AClockFarFromTheSunsTimeIsNamed)
{
  // Paris at UTC or CEST, Kashgar on Beijing time (2.9 hours ahead), Nome on Alaska's summer
  // time (3 hours) and Kiribati's Line Islands at UTC+14 across the date line (0.5 hours)
  // are real clocks: no warning.
  for (const auto& [longitude, zone] : std::vector<std::pair<double, double>>{
         { 2.35, 0 }, { 2.35, 2 }, { 76.0, 8 }, { -165.4, -8 }, { -157.4, 14 } })
  {
    EXPECT_EQ(timeZoneWarning(longitude, zone), "") << longitude << " at " << zone;
  }
  // New York at the default UTC, and at +5 for -5.
  EXPECT_EQ(timeZoneWarning(-74.0, 0),
    "the clock times are taken at UTC+0, 4.9 hours ahead of the sun's time at longitude -74 "
    "(UTC-4.9): if they are the site's clock times, give its offset from UTC, east positive "
    "(--time-zone, or the Sun Path's TimeZone; e.g. -5)");
  EXPECT_NE(timeZoneWarning(-74.0, 5).find("9.9 hours ahead"), std::string::npos);
  // Tokyo at -9 for +9: 18.3 hours apart one way, 5.7 the other across the date line.
  EXPECT_NE(timeZoneWarning(139.7, -9).find("5.7 hours ahead"), std::string::npos)
    << timeZoneWarning(139.7, -9);
}
