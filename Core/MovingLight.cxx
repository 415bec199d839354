#include "MovingLight.h"

#include "Error.h"
#include "PolygonTriangulation.h"
#include "Random.h"
#include "Scene.h"

#include <algorithm>
#include <sstream>

namespace mlr
{

MovingLight::MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
  const std::vector<Vec3>& translations)
  : Power(power)
  , Translations(translations)
{
  if (polygons.empty())
  {
    throw Error("the light has no polygon: give at least one polygon with 3 or more points");
  }
  if (!power.isFinite() || power.minComponent() < 0)
  {
    std::ostringstream s;
    s << "the light power (" << power.r << ", " << power.g << ", " << power.b
      << ") must be finite and not negative";
    throw Error(s.str());
  }
  if (translations.empty())
  {
    throw Error("the light has zero frames: give at least one light position");
  }
  for (std::size_t k = 0; k < translations.size(); ++k)
  {
    if (!isFinite(translations[k]))
    {
      throw Error("light position " + std::to_string(k) + " has NaN or infinite coordinates");
    }
    if (!isWithinCoordinateRange(translations[k]))
    {
      std::ostringstream s;
      s << "light position " << k << " moves the light by (" << translations[k].x << ", "
        << translations[k].y << ", " << translations[k].z << "): coordinates must stay within +-"
        << MaximumCoordinate << " (rays are traced in single precision)";
      throw Error(s.str());
    }
  }

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
        throw Error(which + " is not planar: its points lie off its plane by more than 0.1% of "
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
}

void MovingLight::samplePoint(double u0, double u1, double u2, Vec3& point, Vec3& normal) const
{
  const double target = u0 * this->Area;
  auto it = std::upper_bound(this->CumulativeArea.begin(), this->CumulativeArea.end(), target);
  const std::size_t i = std::min<std::size_t>(
    static_cast<std::size_t>(it - this->CumulativeArea.begin()), this->Triangles.size() - 1);
  const LightTriangle& t = this->Triangles[i];
  point = sampleTriangle(t.a, t.b, t.c, u1, u2);
  normal = t.normal;
}

} // namespace mlr
