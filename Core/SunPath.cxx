#include "SunPath.h"

#include "Error.h"

#include <libnova/julian_day.h>
#include <libnova/precession.h>
#include <libnova/solar.h>
#include <libnova/transform.h>

#include <cmath>
#include <iomanip>
#include <sstream>
#include <string>

namespace mlr
{

void sunAzimuthElevation(double latitude, double longitude, double julianDay,
  double& azimuthDegrees, double& elevationDegrees)
{
  // libnova's solar coordinates are referred to the equinox of J2000 (its VSOP87 series),
  // while the horizontal transform uses the sidereal time of the day: precessed to the day,
  // or the sun drifts by 50 arcseconds of right ascension a year from 2000 (0.3 degrees, more
  // than a minute of time, by 2021).
  constexpr double J2000 = 2451545.0;
  ln_equ_posn mean{}, equatorial{};
  ln_get_solar_equ_coords(julianDay, &mean);
  ln_get_equ_prec2(&mean, J2000, julianDay, &equatorial);
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

Horizon horizonOf(const Vec3& north, const Vec3& up)
{
  const double upLength = length(up);
  if (!isFinite(up) || !(upLength > 0))
  {
    throw Error("the up direction must be finite and not zero");
  }
  Horizon h;
  h.up = up / upLength;
  const Vec3 northInPlane = north - h.up * dot(north, h.up);
  if (!isFinite(north) || !(length(northInPlane) > 1e-6 * std::max(1.0, length(north))))
  {
    throw Error("the north direction must be finite and not parallel to up");
  }
  if (std::abs(dot(normalize(north), h.up)) > 1e-6)
  {
    throw Error("the north direction must be horizontal: perpendicular to the up direction");
  }
  h.north = normalize(northInPlane);
  h.east = cross(h.north, h.up);
  return h;
}

SunPosition sunAt(double latitude, double longitude, int year, int month, int day,
  double clockHours, double timeZoneHours, const Horizon& horizon)
{
  ln_date midnight{};
  midnight.years = year;
  midnight.months = month;
  midnight.days = day;
  // Local midnight, in UTC.
  const double julianMidnight = ln_get_julian_day(&midnight) - timeZoneHours / 24.0;
  SunPosition p;
  p.clockHours = clockHours;
  sunAzimuthElevation(
    latitude, longitude, julianMidnight + clockHours / 24.0, p.azimuthDegrees, p.elevationDegrees);
  const double az = p.azimuthDegrees * M_PI / 180, el = p.elevationDegrees * M_PI / 180;
  p.direction = (horizon.north * std::cos(az) + horizon.east * std::sin(az)) * std::cos(el) +
    horizon.up * std::sin(el);
  return p;
}

int dayOfYear(int year, int month, int day)
{
  int days = day;
  for (int m = 1; m < month; ++m)
  {
    days += daysIn(year, m);
  }
  return days;
}

std::vector<SunPosition> sunPath(const SunPathRequest& r)
{
  if (!(r.latitude >= -90 && r.latitude <= 90))
  {
    throw Error("the latitude is " + formatNumber(r.latitude) +
      ": give degrees from -90 (south pole) to 90 (north pole)");
  }
  if (!(r.longitude >= -180 && r.longitude <= 180))
  {
    throw Error("the longitude is " + formatNumber(r.longitude) +
      ": give degrees from -180 to 180, east positive");
  }
  if (r.year < -4000 || r.year > 9999 || r.month < 1 || r.month > 12 || r.day < 1 ||
    r.day > daysIn(r.year, r.month))
  {
    std::ostringstream s;
    s << "the date " << r.year << "-" << std::setfill('0') << std::setw(2) << r.month << "-"
      << std::setw(2) << r.day << " does not exist: give YYYY-MM-DD";
    throw Error(s.str());
  }
  if (!(r.startHour >= 0 && r.startHour <= 24) || !(r.endHour >= 0 && r.endHour <= 24))
  {
    throw Error("the times of day must be from 00:00 to 24:00");
  }
  if (!(r.endHour >= r.startHour))
  {
    throw Error("the end time is before the start time: give the day's start first (or the "
                "same time twice for one instant)");
  }
  if (!(r.stepMinutes > 0) || !std::isfinite(r.stepMinutes) ||
    (r.endHour - r.startHour) * 60 / r.stepMinutes > 100000)
  {
    std::ostringstream s;
    s << "the step is " << r.stepMinutes
      << " minutes: give a positive step that makes at most 100000 frames";
    throw Error(s.str());
  }
  if (!(std::abs(r.timeZoneHours) <= 14))
  {
    throw Error("the time zone is " + formatNumber(r.timeZoneHours) +
      " hours from UTC: give an offset from -14 to 14");
  }
  const Horizon horizon = horizonOf(r.north, r.up);

  std::vector<SunPosition> path;
  const double step = r.stepMinutes / 60.0;
  const auto frames =
    static_cast<long long>(std::floor((r.endHour - r.startHour) / step + 1e-9)) + 1;
  for (long long i = 0; i < frames; ++i)
  {
    path.push_back(sunAt(r.latitude, r.longitude, r.year, r.month, r.day,
      r.startHour + static_cast<double>(i) * step, r.timeZoneHours, horizon));
  }
  return path;
}

std::string timeZoneWarning(double longitude, double timeZoneHours)
{
  const double solar = longitude / 15;
  const double apart = std::remainder(timeZoneHours - solar, 24.0);
  if (!(std::abs(apart) > 3.5))
  {
    return {};
  }
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << "the clock times are taken at UTC"
    << (timeZoneHours < 0 ? "" : "+") << formatNumber(timeZoneHours) << ", " << std::abs(apart)
    << " hours " << (apart > 0 ? "ahead of" : "behind") << " the sun's time at longitude "
    << formatNumber(longitude) << " (UTC" << (solar < 0 ? "" : "+") << solar
    << "): if they are the site's clock times, give its offset from UTC, east positive "
    << "(--time-zone, or the Sun Path's TimeZone; e.g. " << std::lround(solar) << ")";
  return s.str();
}

} // namespace mlr
