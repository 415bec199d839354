#include "FormFactor.h"

#include <cmath>

namespace mlr
{

double pointToPolygonFormFactor(
  const Vec3& point, const Vec3& normal, const std::vector<Vec3>& polygon)
{
  constexpr double twoPi = 6.283185307179586476925286766559;
  double sum = 0;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec3 a = normalize(polygon[i] - point);
    const Vec3 b = normalize(polygon[(i + 1) % n] - point);
    const Vec3 c = cross(a, b);
    const double s = length(c);
    if (s <= 0)
    {
      continue;
    }
    const double angle = std::atan2(s, dot(a, b));
    sum += angle * dot(normal, c) / s;
  }
  return std::abs(sum) / twoPi;
}

} // namespace mlr
