// Where the sun is: directions towards it over a day, for a directional light.
#pragma once

#include "Vec3.h"

#include <string>
#include <vector>

namespace mlr
{

/// A day of sun positions as the command line's --sun-path asks for them.
struct SunPathRequest
{
  double latitude = 0;  ///< degrees, north positive, in [-90, 90]
  double longitude = 0; ///< degrees, east positive, in [-180, 180]
  int year = 2000, month = 1, day = 1;
  double startHour = 6, endHour = 18; ///< local clock time, hours (e.g. 6.5 is 06:30)
  double stepMinutes = 15;
  double timeZoneHours = 0; ///< local clock time minus UTC (e.g. +1 for CET)
  Vec3 north{ 0, 1, 0 };    ///< the scene's north, horizontal
  Vec3 up{ 0, 0, 1 };       ///< the scene's zenith
};

struct SunPosition
{
  double clockHours = 0;       ///< local clock time of the frame, hours
  double azimuthDegrees = 0;   ///< from north towards east
  double elevationDegrees = 0; ///< above the horizon (negative: below it), no refraction
  Vec3 direction;              ///< unit, in scene coordinates, towards the sun
};

/// The sun seen from (latitude, longitude) at a UTC time given as a Julian day, from libnova's
/// solar theory (VSOP87): azimuth from north towards east and elevation, in degrees.
void sunAzimuthElevation(double latitude, double longitude, double julianDay,
  double& azimuthDegrees, double& elevationDegrees);

/// The scene's horizontal north and east and its zenith, unit vectors.
struct Horizon
{
  Vec3 north, east, up;
};

/// The horizon of a scene's north and up: throws mlr::Error for an up that is zero or not
/// finite and a north that is not finite or not horizontal.
Horizon horizonOf(const Vec3& north, const Vec3& up);

/**
 * The sun at a local clock time (hours from the day's midnight, any value: 25 is 01:00 of the
 * next day) of a date, the clock `timeZoneHours` ahead of UTC, as sunPath computes it. Checks
 * nothing: callers check the place and the date.
 */
SunPosition sunAt(double latitude, double longitude, int year, int month, int day,
  double clockHours, double timeZoneHours, const Horizon& horizon);

/// 1 to 366: the day of the year of a date, January 1 being 1.
int dayOfYear(int year, int month, int day);

/**
 * One position every stepMinutes from startHour to endHour (both included when the step
 * lands on it) on the given day. Frames with the sun below the horizon are kept: their
 * direction points below the horizon and a caller gives them zero power. Throws mlr::Error
 * for a latitude outside +-90, a longitude outside +-180, an invalid date or time, an end
 * before the start, a step that is not positive or gives more than 100,000 frames, and a
 * north that is not horizontal.
 */
std::vector<SunPosition> sunPath(const SunPathRequest& request);

/**
 * A warning when the clock `timeZoneHours` ahead of UTC is more than 3.5 hours from the mean
 * solar time of `longitude` (longitude / 15 hours, across the date line the shorter way):
 * the times were most likely meant as local clock times with the default UTC, or with the
 * offset's sign turned. Real time zones stay within about 3 hours of their solar time
 * (western China, Alaska). Empty otherwise.
 */
std::string timeZoneWarning(double longitude, double timeZoneHours);

} // namespace mlr
