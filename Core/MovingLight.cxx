#include "MovingLight.h"

#include "Error.h"
#include "PolygonTriangulation.h"
#include "Random.h"
#include "Scene.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlr
{

MovingLight::MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
  const std::vector<Vec3>& translations)
  : MovingLight(polygons, power, std::vector<LightPose>{ LightPose() })
{
  if (translations.empty())
  {
    throw Error("the light has zero frames: give at least one light position");
  }
  std::vector<LightPose> poses(translations.size());
  for (std::size_t k = 0; k < translations.size(); ++k)
  {
    poses[k].position = this->Centroid + translations[k];
    if (!isFinite(translations[k]))
    {
      throw Error("light position " + std::to_string(k) +
        " has NaN or infinite coordinates: give every point of the Trajectory (or the path's "
        "ends) finite coordinates");
    }
  }
  this->setPoses(poses);
}

void checkLightPower(const Rgb& power)
{
  if (!power.isFinite() || power.minComponent() < 0 ||
    std::max({ power.r, power.g, power.b }) > MaximumLightPower)
  {
    std::ostringstream s;
    s << "the light power (" << power.r << ", " << power.g << ", " << power.b
      << ") W must be finite and not negative, at most " << MaximumLightPower << " W per channel";
    throw Error(s.str());
  }
}

void checkPoses(const std::vector<LightPose>& poses, const Rgb& power)
{
  if (poses.empty())
  {
    throw Error("the light has zero frames: give at least one light position");
  }
  for (std::size_t k = 0; k < poses.size(); ++k)
  {
    const LightPose& pose = poses[k];
    if (!isFinite(pose.position))
    {
      throw Error("light position " + std::to_string(k) +
        " has NaN or infinite coordinates: give every point of the Trajectory (or the path's "
        "ends) finite coordinates");
    }
    if (!isWithinCoordinateRange(pose.position))
    {
      std::ostringstream s;
      s << "light position " << k << " is at (" << pose.position.x << ", " << pose.position.y
        << ", " << pose.position.z << "): coordinates must stay within +-" << MaximumCoordinate
        << " (rays are traced in single precision)";
      throw Error(s.str());
    }
    if (!pose.power.isFinite() || pose.power.minComponent() < 0)
    {
      std::ostringstream s;
      s << "the power factor of light position " << k << " is (" << pose.power.r << ", "
        << pose.power.g << ", " << pose.power.b << "): it must be finite and >= 0 (0 turns the "
        << "light off)";
      throw Error(s.str());
    }
    // The outputs are single precision: a pose's power over the bound would write infinities.
    const Rgb emitted = power * pose.power;
    if (!(emitted.maxComponent() <= MaximumLightPower))
    {
      std::ostringstream s;
      s << "the power factor of light position " << k << " takes the light to (" << emitted.r
        << ", " << emitted.g << ", " << emitted.b << ") W, over " << MaximumLightPower
        << " W per channel: give factors around 1 (a dimmer, 0 is off)";
      throw Error(s.str());
    }
    const Rotation& r = pose.rotation;
    const double orthogonality =
      std::max({ std::abs(dot(r.row0, r.row0) - 1), std::abs(dot(r.row1, r.row1) - 1),
        std::abs(dot(r.row2, r.row2) - 1), std::abs(dot(r.row0, r.row1)),
        std::abs(dot(r.row0, r.row2)), std::abs(dot(r.row1, r.row2)) });
    if (!r.isFinite() || !(orthogonality < 1e-6) || !(dot(cross(r.row0, r.row1), r.row2) > 0))
    {
      throw Error("the orientation of light position " + std::to_string(k) +
        " is not a rotation (NaN, scaled, sheared or mirrored)");
    }
  }
}

void MovingLight::setPoses(const std::vector<LightPose>& poses)
{
  checkPoses(poses, this->Power);
  this->Rotates = false;
  for (const LightPose& pose : poses)
  {
    this->Rotates = this->Rotates || !pose.rotation.isIdentity();
  }
  this->Poses = poses;
}

MovingLight::MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
  const std::vector<LightPose>& poses)
  : Power(power)
  , Polygons(polygons)
{
  if (polygons.empty())
  {
    throw Error("the light has no polygon: give at least one polygon with 3 or more points");
  }
  checkLightPower(power);
  for (std::size_t i = 0; i < polygons.size(); ++i)
  {
    const std::vector<Vec3>& polygon = polygons[i];
    const std::string which = "light polygon " + std::to_string(i);
    if (polygon.size() < 3)
    {
      throw Error(which + " has " + std::to_string(polygon.size()) +
        " points: a light polygon needs at least 3");
    }
    for (const Vec3& p : polygon)
    {
      if (!isFinite(p))
      {
        throw Error(which + " has NaN or infinite coordinates");
      }
      if (!isWithinCoordinateRange(p))
      {
        std::ostringstream s;
        s << which << " has a point at (" << p.x << ", " << p.y << ", " << p.z
          << "): coordinates must stay within +-" << MaximumCoordinate
          << " (rays are traced in single precision)";
        throw Error(s.str());
      }
    }
    const Vec3 newell = newellNormal(polygon);
    const double twiceArea = length(newell);
    double diameter = 0;
    for (const Vec3& p : polygon)
    {
      diameter = std::max(diameter, length(p - polygon[0]));
    }
    if (!(twiceArea > 1e-12 * diameter * diameter) || !std::isfinite(twiceArea))
    {
      throw Error(which + " is degenerate (zero area): its points are collinear or coincide");
    }
    const Vec3 normal = newell / twiceArea;
    for (const Vec3& p : polygon)
    {
      if (std::abs(dot(p - polygon[0], normal)) > 1e-3 * diameter)
      {
        throw Error(which +
          " is not planar: its points lie off its plane by more than 0.1% of "
          "its size");
      }
    }
    const auto triangles = triangulatePolygon(polygon);
    if (triangles.empty())
    {
      throw Error(which + " is not a simple polygon (its edges cross): split it into simple ones");
    }
    for (const auto& t : triangles)
    {
      LightTriangle lt{ polygon[t[0]], polygon[t[1]], polygon[t[2]], normal, 0 };
      lt.area = 0.5 * length(triangleAreaVector(lt.a, lt.b, lt.c));
      if (lt.area <= 0)
      {
        continue;
      }
      this->Area += lt.area;
      this->Centroid += (lt.a + lt.b + lt.c) * (lt.area / 3.0);
      this->Triangles.push_back(lt);
      this->CumulativeArea.push_back(this->Area);
    }
  }
  if (this->Triangles.empty() || !(this->Area > 0))
  {
    throw Error("the light has zero area: give a polygon that encloses some area");
  }
  this->Centroid = this->Centroid / this->Area;
  // C = 0 along the first edge of non-zero length: an edge lies in the polygon's plane.
  const std::vector<Vec3>& first = polygons[0];
  std::size_t i = 1;
  while (i + 1 < first.size() && !(length(first[i] - first[i - 1]) > 0))
  {
    ++i;
  }
  this->OwnFrame = PhotometricFrame::fromNadir(newellNormal(first), first[i] - first[i - 1]);
  this->setPoses(poses);
}

std::size_t MovingLight::triangleAt(double area) const
{
  auto it = std::upper_bound(this->CumulativeArea.begin(), this->CumulativeArea.end(), area);
  return std::min<std::size_t>(
    static_cast<std::size_t>(it - this->CumulativeArea.begin()), this->Triangles.size() - 1);
}

void MovingLight::samplePoint(double u0, double u1, double u2, Vec3& point, Vec3& normal) const
{
  const LightTriangle& t = this->Triangles[this->triangleAt(u0 * this->Area)];
  point = sampleTriangle(t.a, t.b, t.c, u1, u2);
  normal = t.normal;
}

void MovingLight::samplePoint(double u, double v, Vec3& point, Vec3& normal) const
{
  const double target = u * this->Area;
  const std::size_t i = this->triangleAt(target);
  const double before = i > 0 ? this->CumulativeArea[i - 1] : 0.0;
  const double area = this->CumulativeArea[i] - before;
  const double rest = area > 0 ? std::clamp((target - before) / area, 0.0, 1.0) : 0.0;
  const LightTriangle& t = this->Triangles[i];
  point = sampleTriangle(t.a, t.b, t.c, rest, v);
  normal = t.normal;
}

Vec3 meanNormal(const std::vector<std::vector<Vec3>>& polygons)
{
  Vec3 sum;
  for (const std::vector<Vec3>& polygon : polygons)
  {
    sum += newellNormal(polygon); // twice the area times the unit normal
  }
  const double norm = length(sum);
  if (!(norm > 0) || !std::isfinite(norm))
  {
    throw Error("the light's polygons face opposite ways (their mean normal is zero), so a "
                "Normal cannot turn it: give an Orientation (quaternion) per frame instead");
  }
  return sum / norm;
}

std::vector<LightPose> posesFromInputs(const std::vector<std::vector<Vec3>>& polygons,
  const std::vector<PoseInput>& inputs, std::vector<std::string>& warnings)
{
  std::vector<LightPose> poses(inputs.size());
  Vec3 own;
  bool haveOwn = false;
  std::size_t normalised = 0;
  for (std::size_t k = 0; k < inputs.size(); ++k)
  {
    const PoseInput& in = inputs[k];
    LightPose& pose = poses[k];
    pose.position = in.position;
    pose.power = in.power;
    if (in.hasOrientation)
    {
      const auto& q = in.orientation;
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (!(norm > 1e-12) || !std::isfinite(norm))
      {
        std::ostringstream s;
        s << "the Orientation of light position " << k << " is (" << q[0] << ", " << q[1] << ", "
          << q[2] << ", " << q[3] << "): a quaternion (w, x, y, z) must be finite and "
          << "not zero ((1, 0, 0, 0) leaves the light as given)";
        throw Error(s.str());
      }
      if (std::abs(norm - 1) > 1e-6)
      {
        ++normalised;
      }
      pose.rotation = Rotation::fromQuaternion(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm);
    }
    else if (in.hasNormal)
    {
      const double norm = length(in.normal);
      if (!(norm > 1e-12) || !std::isfinite(norm))
      {
        std::ostringstream s;
        s << "the Normal of light position " << k << " is (" << in.normal.x << ", " << in.normal.y
          << ", " << in.normal.z << "): give a finite direction of non-zero "
          << "length, the way the light emits in that frame";
        throw Error(s.str());
      }
      if (!haveOwn)
      {
        own = meanNormal(polygons);
        haveOwn = true;
      }
      pose.rotation = Rotation::between(own, in.normal / norm);
    }
  }
  if (normalised > 0)
  {
    warnings.push_back(std::to_string(normalised) +
      " Orientation quaternions were not of unit length and were normalised");
  }
  return poses;
}

std::optional<std::size_t> aimAt(std::vector<PoseInput>& inputs, const Vec3& target)
{
  for (std::size_t k = 0; k < inputs.size(); ++k)
  {
    PoseInput& in = inputs[k];
    in.hasNormal = true;
    in.normal = target - in.position;
    if (!in.hasOrientation && !(length(in.normal) > 1e-12))
    {
      return k;
    }
  }
  return std::nullopt;
}

} // namespace mlr
