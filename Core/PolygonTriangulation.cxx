#include "PolygonTriangulation.h"

#include <cmath>

namespace mlr
{

Vec3 newellNormal(const std::vector<Vec3>& polygon)
{
  Vec3 n;
  const std::size_t count = polygon.size();
  for (std::size_t i = 0; i < count; ++i)
  {
    const Vec3& a = polygon[i];
    const Vec3& b = polygon[(i + 1) % count];
    n.x += (a.y - b.y) * (a.z + b.z);
    n.y += (a.z - b.z) * (a.x + b.x);
    n.z += (a.x - b.x) * (a.y + b.y);
  }
  return n;
}

namespace
{
struct Point2
{
  double u, v;
};

double orient(const Point2& a, const Point2& b, const Point2& c)
{
  return (b.u - a.u) * (c.v - a.v) - (b.v - a.v) * (c.u - a.u);
}

bool insideOrOnTriangle(const Point2& p, const Point2& a, const Point2& b, const Point2& c)
{
  return orient(a, b, p) >= 0 && orient(b, c, p) >= 0 && orient(c, a, p) >= 0;
}
}

std::vector<std::array<std::uint32_t, 3>> triangulatePolygon(const std::vector<Vec3>& polygon)
{
  std::vector<std::array<std::uint32_t, 3>> triangles;
  const Vec3 normal = newellNormal(polygon);
  const double twiceArea = length(normal);
  if (polygon.size() < 3 || !(twiceArea > 0) || !std::isfinite(twiceArea))
  {
    return triangles;
  }
  // Project onto the plane so that the polygon is counter-clockwise in (u, v).
  Vec3 t, b;
  orthonormalBasis(normal / twiceArea, t, b);
  std::vector<Point2> flat(polygon.size());
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    flat[i] = { dot(polygon[i], t), dot(polygon[i], b) };
  }

  // Drop consecutive duplicates.
  std::vector<std::uint32_t> ring;
  for (std::uint32_t i = 0; i < polygon.size(); ++i)
  {
    if (ring.empty() || !(polygon[ring.back()] == polygon[i]))
    {
      ring.push_back(i);
    }
  }
  while (ring.size() > 1 && polygon[ring.front()] == polygon[ring.back()])
  {
    ring.pop_back();
  }

  const double areaScale = twiceArea * 1e-12;
  std::size_t guard = 0;
  while (ring.size() > 3 && guard < 2 * polygon.size() * polygon.size() + 16)
  {
    ++guard;
    bool clipped = false;
    const std::size_t n = ring.size();
    for (std::size_t i = 0; i < n && !clipped; ++i)
    {
      const std::uint32_t ia = ring[(i + n - 1) % n], ib = ring[i], ic = ring[(i + 1) % n];
      const double turn = orient(flat[ia], flat[ib], flat[ic]);
      if (std::abs(turn) <= areaScale)
      {
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i)); // collinear: no ear, no area
        clipped = true;
        break;
      }
      if (turn < 0)
      {
        continue; // reflex vertex
      }
      bool empty = true;
      for (std::size_t j = 0; j < n && empty; ++j)
      {
        const std::uint32_t iq = ring[j];
        if (iq == ia || iq == ib || iq == ic || polygon[iq] == polygon[ia] ||
          polygon[iq] == polygon[ib] || polygon[iq] == polygon[ic])
        {
          continue;
        }
        empty = !insideOrOnTriangle(flat[iq], flat[ia], flat[ib], flat[ic]);
      }
      if (empty)
      {
        triangles.push_back({ ia, ib, ic });
        ring.erase(ring.begin() + static_cast<std::ptrdiff_t>(i));
        clipped = true;
      }
    }
    if (!clipped)
    {
      triangles.clear(); // not simple: no ear left
      return triangles;
    }
  }
  if (ring.size() == 3 && std::abs(orient(flat[ring[0]], flat[ring[1]], flat[ring[2]])) > areaScale)
  {
    if (orient(flat[ring[0]], flat[ring[1]], flat[ring[2]]) < 0)
    {
      triangles.clear();
      return triangles;
    }
    triangles.push_back({ ring[0], ring[1], ring[2] });
  }
  // A simple polygon's ears add up to its area; a self-intersecting one's do not.
  double sum = 0;
  for (const auto& tri : triangles)
  {
    sum += orient(flat[tri[0]], flat[tri[1]], flat[tri[2]]);
  }
  if (std::abs(sum - twiceArea) > 1e-6 * twiceArea)
  {
    triangles.clear();
  }
  return triangles;
}

} // namespace mlr
