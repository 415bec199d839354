#include "SunPath.h"

#include "Error.h"

#include <libnova/julian_day.h>
#include <libnova/solar.h>
#include <libnova/transform.h>

#include <cmath>
#include <sstream>
#include <string>

namespace mlr
{

void sunAzimuthElevation(double latitude, double longitude, double julianDay,
  double& azimuthDegrees, double& elevationDegrees)
{
  ln_equ_posn equatorial{};
  ln_get_solar_equ_coords(julianDay, &equatorial);
  ln_lnlat_posn observer{ longitude, latitude };
  ln_hrz_posn horizontal{};
  ln_get_hrz_from_equ(&equatorial, &observer, julianDay, &horizontal);
  // libnova measures azimuth from south towards west.
  azimuthDegrees = std::fmod(horizontal.az + 180.0, 360.0);
  elevationDegrees = horizontal.alt;
}

namespace
{
bool isLeap(int year)
{
  return (year % 4 == 0 && year % 100 != 0) || year % 400 == 0;
}

int daysIn(int year, int month)
{
  static const int days[] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
  return month == 2 && isLeap(year) ? 29 : days[month - 1];
}
}

std::vector<SunPosition> sunPath(const SunPathRequest& r)
{
  if (!(r.latitude >= -90 && r.latitude <= 90))
  {
    throw Error("the latitude is " + std::to_string(r.latitude) +
      ": give degrees from -90 (south pole) to 90 (north pole)");
  }
  if (!(r.longitude >= -180 && r.longitude <= 180))
  {
    throw Error("the longitude is " + std::to_string(r.longitude) +
      ": give degrees from -180 to 180, east positive");
  }
  if (r.year < -4000 || r.year > 9999 || r.month < 1 || r.month > 12 || r.day < 1 ||
    r.day > daysIn(r.year, r.month))
  {
    std::ostringstream s;
    s << "the date " << r.year << "-" << r.month << "-" << r.day
      << " does not exist: give YYYY-MM-DD";
    throw Error(s.str());
  }
  if (!(r.startHour >= 0 && r.startHour <= 24) || !(r.endHour >= 0 && r.endHour <= 24))
  {
    throw Error("the times of day must be from 00:00 to 24:00");
  }
  if (!(r.endHour > r.startHour))
  {
    throw Error("the end time is not after the start time: give the day's start first");
  }
  if (!(r.stepMinutes > 0) || !std::isfinite(r.stepMinutes) ||
    (r.endHour - r.startHour) * 60 / r.stepMinutes > 100000)
  {
    throw Error("the step is " + std::to_string(r.stepMinutes) +
      " minutes: give a positive step that makes at most 100000 frames");
  }
  if (!(std::abs(r.timeZoneHours) <= 14))
  {
    throw Error("the time zone is " + std::to_string(r.timeZoneHours) +
      " hours from UTC: give an offset from -14 to 14");
  }
  const double upLength = length(r.up);
  if (!isFinite(r.up) || !(upLength > 0))
  {
    throw Error("the up direction must be finite and not zero");
  }
  const Vec3 up = r.up / upLength;
  const Vec3 northInPlane = r.north - up * dot(r.north, up);
  if (!isFinite(r.north) || !(length(northInPlane) > 1e-6 * std::max(1.0, length(r.north))))
  {
    throw Error("the north direction must be finite and not parallel to up");
  }
  if (std::abs(dot(normalize(r.north), up)) > 1e-6)
  {
    throw Error("the north direction must be horizontal: perpendicular to the up direction");
  }
  const Vec3 north = normalize(northInPlane);
  const Vec3 east = cross(north, up);

  ln_date midnight{};
  midnight.years = r.year;
  midnight.months = r.month;
  midnight.days = r.day;
  // Local midnight, in UTC.
  const double julianMidnight = ln_get_julian_day(&midnight) - r.timeZoneHours / 24.0;

  std::vector<SunPosition> path;
  const double step = r.stepMinutes / 60.0;
  const auto frames =
    static_cast<long long>(std::floor((r.endHour - r.startHour) / step + 1e-9)) + 1;
  for (long long i = 0; i < frames; ++i)
  {
    SunPosition p;
    p.clockHours = r.startHour + static_cast<double>(i) * step;
    sunAzimuthElevation(r.latitude, r.longitude, julianMidnight + p.clockHours / 24.0,
      p.azimuthDegrees, p.elevationDegrees);
    const double az = p.azimuthDegrees * M_PI / 180, el = p.elevationDegrees * M_PI / 180;
    p.direction = (north * std::cos(az) + east * std::sin(az)) * std::cos(el) + up * std::sin(el);
    path.push_back(p);
  }
  return path;
}

} // namespace mlr
