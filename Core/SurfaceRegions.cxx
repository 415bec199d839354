#include "SurfaceRegions.h"
#include "DisjointSets.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <utility>

namespace mlr
{

void forEachSharedEdge(const std::vector<std::array<std::uint32_t, 3>>& triangles,
  const std::function<void(const EdgeUse&, const EdgeUse&)>& visit)
{
  // Every edge once per triangle, keyed by its two points (lower first); sorted so that the
  // triangles of an edge are adjacent.
  struct Keyed
  {
    std::uint64_t key;
    EdgeUse use;
  };
  std::vector<Keyed> uses;
  uses.reserve(3 * triangles.size());
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    for (std::uint32_t k = 0; k < 3; ++k)
    {
      const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      uses.push_back({ (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b),
        { static_cast<std::uint32_t>(t), k } });
    }
  }
  std::sort(uses.begin(), uses.end(),
    [](const Keyed& x, const Keyed& y)
    { return x.key < y.key || (x.key == y.key && x.use.triangle < y.use.triangle); });
  for (std::size_t first = 0; first < uses.size();)
  {
    std::size_t last = first + 1;
    while (last < uses.size() && uses[last].key == uses[first].key)
    {
      ++last;
    }
    for (std::size_t i = first; i < last; ++i)
    {
      for (std::size_t j = i + 1; j < last; ++j)
      {
        visit(uses[i].use, uses[j].use);
      }
    }
    first = last;
  }
}

std::vector<std::uint32_t> surfaceRegions(
  const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<Vec3>& normals)
{
  const std::size_t n = triangles.size();
  // Every set's root is its first triangle, whatever order the edges join in.
  DisjointSets surfaces(n);

  const double cosCrease = std::cos(CreaseAngleDegrees * M_PI / 180.0);
  const auto ascending = [&triangles](const EdgeUse& u)
  { return triangles[u.triangle][u.corner] < triangles[u.triangle][(u.corner + 1) % 3]; };
  forEachSharedEdge(triangles,
    [&](const EdgeUse& u, const EdgeUse& v)
    {
      // Running the edge the same way, two triangles within the angle lie on the same side
      // of it, one folded back over the other: no surface passes smoothly from one to the
      // other.
      if (ascending(u) != ascending(v) &&
        dot(normals[u.triangle], normals[v.triangle]) >= cosCrease)
      {
        surfaces.join(u.triangle, v.triangle);
      }
    });

  std::vector<std::uint32_t> region(n);
  std::uint32_t count = 0;
  for (std::size_t t = 0; t < n; ++t)
  {
    const std::size_t root = surfaces.find(t);
    region[t] = root == t ? count++ : region[root];
  }
  return region;
}

} // namespace mlr
