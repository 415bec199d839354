#include "LuminaireTilt.h"

#include "Error.h"
#include "PhotometricParsing.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlr
{

namespace
{
constexpr double Degree = 3.14159265358979323846 / 180;
}

LuminaireTilt luminaireTilt(
  TiltTable::Geometry geometry, const PhotometricFrame& posed, const Vec3& up)
{
  const double norm = length(up);
  if (!isFinite(up) || !(norm > 0) || !std::isfinite(norm))
  {
    std::ostringstream s;
    s << "the scene's up direction (" << up.x << ", " << up.y << ", " << up.z
      << ") must be finite and not zero: it says which way a tilted luminaire's lamp burns";
    throw Error(s.str());
  }
  const Vec3 down = -up / norm;
  const double dx = std::clamp(dot(down, posed.x), -1.0, 1.0);
  const double dy = std::clamp(dot(down, posed.y), -1.0, 1.0);
  const double dz = std::clamp(dot(down, posed.z), -1.0, 1.0);
  LuminaireTilt tilt;
  switch (geometry)
  {
    case TiltTable::Geometry::Vertical:
      tilt.angle = std::acos(dz) / Degree;
      break;
    case TiltTable::Geometry::HorizontalAlongC90:
      tilt.angle = -std::asin(dy) / Degree;
      break;
    case TiltTable::Geometry::HorizontalAlongC0:
      tilt.angle = std::atan2(-dy, dz) / Degree;
      tilt.untabulated = std::asin(std::abs(dx)) / Degree;
      break;
  }
  return tilt;
}

std::vector<LightPose> tiltPoses(const TiltTable& tilt, const PhotometricFrame& own,
  std::vector<LightPose> poses, const Vec3& up, const std::string& file,
  std::vector<std::string>& warnings)
{
  if (tilt.empty())
  {
    return poses;
  }
  const bool oneSided = tilt.angles.front() >= 0;
  const double lowest = tilt.angles.front(), highest = tilt.angles.back();
  std::size_t outside = 0, leaning = 0, firstOutside = 0, firstLeaning = 0;
  double outsideAngle = 0, leaningAngle = 0;
  for (std::size_t k = 0; k < poses.size(); ++k)
  {
    LightPose& pose = poses[k];
    const PhotometricFrame posed{ pose.rotation.apply(own.x), pose.rotation.apply(own.y),
      pose.rotation.apply(own.z) };
    const LuminaireTilt t = luminaireTilt(tilt.geometry, posed, up);
    const double angle =
      oneSided && tilt.geometry != TiltTable::Geometry::Vertical ? std::abs(t.angle) : t.angle;
    // Rounding must not warn of a luminaire aimed exactly at the table's end.
    if (angle < lowest - 1e-6 || angle > highest + 1e-6)
    {
      if (outside++ == 0)
      {
        firstOutside = k;
        outsideAngle = angle;
      }
    }
    if (t.untabulated > 1)
    {
      if (leaning++ == 0)
      {
        firstLeaning = k;
        leaningAngle = t.untabulated;
      }
    }
    pose.power = pose.power * tilt.factor(angle);
  }
  auto rounded = [](double degrees) { return formatNumber(std::round(degrees * 10) / 10); };
  if (outside > 0)
  {
    warnings.push_back(file + ": light position " + std::to_string(firstOutside) +
      " tilts the luminaire by " + rounded(outsideAngle) + " degrees, outside the TILT table's " +
      formatNumber(lowest) + " to " + formatNumber(highest) + " (" + std::to_string(outside) +
      " of " + std::to_string(poses.size()) +
      " positions are): those take the factor at the table's nearer end");
  }
  if (leaning > 0)
  {
    warnings.push_back(file + ": light position " + std::to_string(firstLeaning) +
      " leans the lamp axis (C0-C180, lamp-to-luminaire geometry 2) " + rounded(leaningAngle) +
      " degrees out of the horizontal (" + std::to_string(leaning) + " of " +
      std::to_string(poses.size()) +
      " positions do), a tilt the TILT table does not give: those take the factor of their "
      "roll about the lamp axis alone");
  }
  return poses;
}

} // namespace mlr
