#include "SurfaceRegions.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <numeric>
#include <utility>

namespace mlr
{

std::vector<std::uint32_t> surfaceRegions(
  const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<Vec3>& normals)
{
  const std::size_t n = triangles.size();
  // Joining the larger root under the smaller makes every root its set's first triangle,
  // whatever order the edges join in.
  std::vector<std::size_t> parent(n);
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  auto find = [&parent](std::size_t t)
  {
    while (parent[t] != t)
    {
      parent[t] = parent[parent[t]];
      t = parent[t];
    }
    return t;
  };

  // Every edge once per triangle, keyed by its two points (lower first); sorted so that the
  // triangles of an edge are adjacent.
  struct EdgeUse
  {
    std::uint64_t key;
    std::uint32_t triangle;
    bool ascending; ///< the triangle runs from the lower point to the higher
  };
  std::vector<EdgeUse> uses;
  uses.reserve(3 * n);
  for (std::size_t t = 0; t < n; ++t)
  {
    for (std::size_t k = 0; k < 3; ++k)
    {
      const std::uint32_t a = triangles[t][k], b = triangles[t][(k + 1) % 3];
      uses.push_back({ (static_cast<std::uint64_t>(std::min(a, b)) << 32) | std::max(a, b),
        static_cast<std::uint32_t>(t), a < b });
    }
  }
  std::sort(uses.begin(), uses.end(),
    [](const EdgeUse& x, const EdgeUse& y)
    { return x.key < y.key || (x.key == y.key && x.triangle < y.triangle); });

  const double cosCrease = std::cos(CreaseAngleDegrees * M_PI / 180.0);
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
        const std::uint32_t a = uses[i].triangle, b = uses[j].triangle;
        // Running the edge the same way, two triangles within the angle lie on the same side
        // of it, one folded back over the other: no surface passes smoothly from one to the
        // other.
        if (uses[i].ascending != uses[j].ascending && dot(normals[a], normals[b]) >= cosCrease)
        {
          const std::size_t ra = find(a), rb = find(b);
          parent[std::max(ra, rb)] = std::min(ra, rb);
        }
      }
    }
    first = last;
  }

  std::vector<std::uint32_t> region(n);
  std::uint32_t count = 0;
  for (std::size_t t = 0; t < n; ++t)
  {
    const std::size_t root = find(t);
    region[t] = root == t ? count++ : region[root];
  }
  return region;
}

} // namespace mlr
