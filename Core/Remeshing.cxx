#include "Remeshing.h"

#include "Error.h"
#include "PolygonTriangulation.h"

#include <chrono>
#include <cmath>
#include <sstream>

namespace mlr
{

namespace
{
/// Patches past this many would exhaust memory long before the solve: refuse early.
constexpr double MaximumPatches = 1 << 26;

/// Uniform 1:m^2 split of a triangle, m = ceil(longest edge / h). Neighbours split with
/// different m meet at T-junctions, which are harmless to ray casting.
void refineTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double h, const Rgb& rho,
  PatchMesh& out)
{
  const double longest = std::max({ length(b - a), length(c - b), length(a - c) });
  const int m = std::max(1, static_cast<int>(std::ceil(longest / h - 1e-9)));
  const auto base = static_cast<std::uint32_t>(out.points.size());
  // Row i (0..m) holds m - i + 1 points: a + (b-a) j/m + (c-a) i/m.
  std::vector<std::uint32_t> rowStart(static_cast<std::size_t>(m) + 2);
  std::uint32_t next = base;
  for (int i = 0; i <= m; ++i)
  {
    rowStart[static_cast<std::size_t>(i)] = next;
    for (int j = 0; j <= m - i; ++j)
    {
      out.points.push_back(a + (b - a) * (double(j) / m) + (c - a) * (double(i) / m));
      ++next;
    }
  }
  auto at = [&](int i, int j) { return rowStart[static_cast<std::size_t>(i)] + static_cast<std::uint32_t>(j); };
  for (int i = 0; i < m; ++i)
  {
    for (int j = 0; j < m - i; ++j)
    {
      out.triangles.push_back({ at(i, j), at(i, j + 1), at(i + 1, j) });
      out.reflectance.push_back(rho);
      if (j + 1 < m - i)
      {
        out.triangles.push_back({ at(i, j + 1), at(i + 1, j + 1), at(i + 1, j) });
        out.reflectance.push_back(rho);
      }
    }
  }
}
}

double edgeLengthForPatchCount(double area, std::size_t patches)
{
  const double count = static_cast<double>(std::max<std::size_t>(1, patches));
  return std::sqrt(4.0 * area / (std::sqrt(3.0) * count));
}

RemeshResult remesh(const PolygonSoup& soup, const RemeshOptions& options, const RemeshProgress& progress)
{
  const auto start = std::chrono::steady_clock::now();
  RemeshResult result;
  RemeshStatistics& stats = result.statistics;
  stats.inputPolygons = soup.polygons.size();

  if (soup.materials.size() != soup.polygons.size())
  {
    std::ostringstream s;
    s << "the scene has " << soup.polygons.size() << " polygons but " << soup.materials.size()
      << " materials: give exactly one material per polygon";
    throw Error(s.str());
  }
  std::size_t nonFinite = 0;
  for (const Vec3& p : soup.points)
  {
    nonFinite += isFinite(p) ? 0 : 1;
  }
  if (nonFinite > 0)
  {
    throw Error("the scene has " + std::to_string(nonFinite) +
      " points with NaN or infinite coordinates: remove or fix them");
  }
  if (!(options.targetEdgeLength >= 0) || !std::isfinite(options.targetEdgeLength))
  {
    throw Error("the patch size must be 0 (automatic) or a positive length");
  }

  // Triangulate every polygon in its own plane.
  struct SoupTriangle
  {
    Vec3 a, b, c;
    std::size_t polygon;
  };
  std::vector<SoupTriangle> triangles;
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
  {
    const auto& polygon = soup.polygons[i];
    const Rgb& rho = soup.materials[i].reflectance;
    for (int c = 0; c < 3; ++c)
    {
      if (!(rho[c] >= 0.0 && rho[c] < 1.0))
      {
        std::ostringstream s;
        s << "polygon " << i << " has reflectance (" << rho.r << ", " << rho.g << ", " << rho.b
          << "): every channel must be >= 0 and < 1";
        throw Error(s.str());
      }
    }
    std::vector<Vec3> corners;
    corners.reserve(polygon.size());
    for (std::uint32_t v : polygon)
    {
      if (v >= soup.points.size())
      {
        std::ostringstream s;
        s << "polygon " << i << " uses point " << v << " but the scene has only "
          << soup.points.size() << " points";
        throw Error(s.str());
      }
      corners.push_back(soup.points[v]);
    }
    const auto ears = polygon.size() >= 3 ? triangulatePolygon(corners) : decltype(triangulatePolygon(corners)){};
    if (ears.empty())
    {
      ++stats.droppedPolygons;
      continue;
    }
    for (const auto& t : ears)
    {
      triangles.push_back({ corners[t[0]], corners[t[1]], corners[t[2]], i });
      stats.inputArea += 0.5 * length(triangleAreaVector(corners[t[0]], corners[t[1]], corners[t[2]]));
    }
  }
  stats.inputTriangles = triangles.size();
  if (triangles.empty())
  {
    throw Error("the scene has no polygon with an area (" + std::to_string(soup.polygons.size()) +
      " polygons, all degenerate): give at least one triangle or polygon that encloses area");
  }
  if (stats.droppedPolygons > 0)
  {
    result.warnings.push_back("ignored " + std::to_string(stats.droppedPolygons) +
      " polygons with fewer than 3 points, zero area or crossing edges");
  }

  const double h = options.targetEdgeLength > 0
    ? options.targetEdgeLength
    : edgeLengthForPatchCount(stats.inputArea, options.targetPatchCount);
  stats.targetEdgeLength = h;
  double expected = 0;
  for (const SoupTriangle& t : triangles)
  {
    const double longest = std::max({ length(t.b - t.a), length(t.c - t.b), length(t.a - t.c) });
    const double m = std::max(1.0, std::ceil(longest / h - 1e-9));
    expected += m * m;
  }
  if (expected > MaximumPatches)
  {
    std::ostringstream s;
    s << "the patch size " << h << " would cut the scene into about " << expected
      << " patches (the maximum is " << MaximumPatches << "): give a larger patch size";
    throw Error(s.str());
  }

  for (std::size_t i = 0; i < triangles.size(); ++i)
  {
    const SoupTriangle& t = triangles[i];
    refineTriangle(t.a, t.b, t.c, h, soup.materials[t.polygon].reflectance, result.mesh);
    if (progress && i % 4096 == 0 && !progress(double(i) / double(triangles.size())))
    {
      throw Cancelled();
    }
  }
  stats.regions = 0;
  stats.fallbackRegions = 0;
  stats.patches = result.mesh.triangles.size();
  for (const Triangle& t : result.mesh.triangles)
  {
    stats.outputArea += 0.5 *
      length(triangleAreaVector(result.mesh.points[t[0]], result.mesh.points[t[1]], result.mesh.points[t[2]]));
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (progress && !progress(1.0))
  {
    throw Cancelled();
  }
  return result;
}

} // namespace mlr
