#include "Remeshing.h"

#include "CancellationPoll.h"
#include "CgalRemeshing.h"
#include "Error.h"
#include "MemoryBudget.h"
#include "Plural.h"
#include "PolygonTriangulation.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstring>
#include <iomanip>
#include <numeric>
#include <sstream>

namespace mlr
{

namespace
{
/// Patches past this many would exhaust memory long before the solve: refuse early.
constexpr double MaximumPatches = 1 << 26;
/// Share of the progress taken by CGAL; refining what it refused takes the rest.
constexpr double CgalShare = 0.95;
/// Memory estimates, generous: CGAL's repaired soup, surface meshes, AABB trees and maps per
/// input triangle, and per patch the remeshed surface, the output mesh and the Scene built
/// from it (points, element triangles, normals, areas, midpoint map). Measured peaks (VmHWM)
/// are below these on spheres, boxes and the paper room.
constexpr double BytesPerInputTriangle = 1500;
constexpr double BytesPerPatch = 1000;

/// Uniform 1:m^2 split of a triangle, m = ceil(longest edge / h). Neighbours split with
/// different m meet at T-junctions, which are harmless to ray casting.
void refineTriangle(
  const Vec3& a, const Vec3& b, const Vec3& c, double h, const Material& material, PatchMesh& out)
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
  auto at = [&](int i, int j)
  { return rowStart[static_cast<std::size_t>(i)] + static_cast<std::uint32_t>(j); };
  for (int i = 0; i < m; ++i)
  {
    for (int j = 0; j < m - i; ++j)
    {
      out.triangles.push_back({ at(i, j), at(i, j + 1), at(i + 1, j) });
      out.reflectance.push_back(material.reflectance);
      out.emission.push_back(material.emission);
      if (j + 1 < m - i)
      {
        out.triangles.push_back({ at(i, j + 1), at(i + 1, j + 1), at(i + 1, j) });
        out.reflectance.push_back(material.reflectance);
        out.emission.push_back(material.emission);
      }
    }
  }
}

double triangleArea(const std::vector<Vec3>& points, const Triangle& t)
{
  return 0.5 * length(triangleAreaVector(points[t[0]], points[t[1]], points[t[2]]));
}

void checkProgress(const RemeshProgress& progress, double fraction)
{
  if (progress && !progress(fraction))
  {
    throw Cancelled();
  }
}

void validateOptions(const RemeshOptions& options)
{
  if (!(options.targetEdgeLength >= 0) || !std::isfinite(options.targetEdgeLength))
  {
    throw Error("the patch size must be 0 (automatic) or a positive length");
  }
  if (options.targetEdgeLength == 0 && options.targetPatchCount == 0)
  {
    throw Error("the target patch count must be positive when the patch size is 0 (automatic)");
  }
  if (!(options.sharpEdgeAngle >= 0 && options.sharpEdgeAngle <= 180))
  {
    throw Error("the sharp edge angle must be between 0 and 180 degrees");
  }
}

void validateSoup(const PolygonSoup& soup)
{
  if (soup.materials.size() != soup.polygons.size())
  {
    std::ostringstream s;
    s << "the scene has " << soup.polygons.size() << " polygons but " << soup.materials.size()
      << " materials: give exactly one material per polygon";
    throw Error(s.str());
  }
  checkScenePoints(soup.points);
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
  {
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
    const Rgb& emission = soup.materials[i].emission;
    if (!emission.isFinite() || emission.minComponent() < 0)
    {
      std::ostringstream s;
      s << "polygon " << i << " has emission (" << emission.r << ", " << emission.g << ", "
        << emission.b << ") W/m^2: every channel must be finite and >= 0";
      throw Error(s.str());
    }
    for (std::uint32_t v : soup.polygons[i])
    {
      if (v >= soup.points.size())
      {
        std::ostringstream s;
        s << "polygon " << i << " uses point " << v << " but the scene has only "
          << soup.points.size() << " points";
        throw Error(s.str());
      }
    }
  }
}

/// The distinct materials, and each polygon's index among them: regions are made of faces of
/// one material, so equal materials must get equal indices.
std::vector<Material> distinctMaterials(const PolygonSoup& soup, std::vector<std::uint32_t>& index)
{
  std::vector<Material> distinct;
  index.resize(soup.polygons.size());
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
  {
    // Scenes have few materials, and the last one found is the likely match.
    std::size_t found = distinct.size();
    for (std::size_t k = distinct.size(); k-- > 0;)
    {
      if (distinct[k] == soup.materials[i])
      {
        found = k;
        break;
      }
    }
    if (found == distinct.size())
    {
      distinct.push_back(soup.materials[i]);
    }
    index[i] = static_cast<std::uint32_t>(found);
  }
  return distinct;
}

/// The polygons as triangles (indices into the input points), with the count of what was
/// dropped and why.
struct Triangulation
{
  detail::TriangleSoup soup;
  std::size_t linesAndPoints = 0;
  std::size_t duplicates = 0;
  std::size_t zeroArea = 0;
  std::size_t selfCrossing = 0;
  double area = 0;
};

/// Polygons on the same points as an earlier one, whatever their order: exporters write
/// two-sided walls twice, and two coincident surfaces cannot both be remeshed. Keys (sorted
/// distinct corners) are compared only within runs of equal hashes, so that millions of
/// polygons cost no allocation each.
std::vector<bool> duplicatePolygons(const PolygonSoup& soup, detail::CancellationPoll& poll)
{
  using Corner = std::array<double, 3>;
  auto keyOf = [&soup](std::size_t i, std::vector<Corner>& key)
  {
    key.clear();
    for (std::uint32_t v : soup.polygons[i])
    {
      const Vec3& p = soup.points[v];
      key.push_back({ p.x + 0.0, p.y + 0.0, p.z + 0.0 }); // -0 and 0 are the same point
    }
    std::sort(key.begin(), key.end());
    key.erase(std::unique(key.begin(), key.end()), key.end());
  };
  std::vector<std::pair<std::uint64_t, std::size_t>> hashes;
  hashes.reserve(soup.polygons.size());
  std::vector<Corner> key;
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
  {
    poll.tick();
    if (soup.polygons[i].size() < 3)
    {
      continue;
    }
    keyOf(i, key);
    std::uint64_t hash = 1469598103934665603ULL; // FNV-1a over the key's bytes
    for (const Corner& c : key)
    {
      unsigned char bytes[sizeof(Corner)];
      std::memcpy(bytes, c.data(), sizeof(Corner));
      for (unsigned char b : bytes)
      {
        hash = (hash ^ b) * 1099511628211ULL;
      }
    }
    hashes.emplace_back(hash, i);
  }
  std::sort(hashes.begin(), hashes.end(),
    [&poll](const auto& a, const auto& b)
    {
      poll.tick();
      return a < b;
    });

  std::vector<bool> duplicate(soup.polygons.size(), false);
  std::vector<std::vector<Corner>> distinct; // the different keys of one run of equal hashes
  for (std::size_t begin = 0; begin < hashes.size();)
  {
    std::size_t end = begin + 1;
    while (end < hashes.size() && hashes[end].first == hashes[begin].first)
    {
      ++end;
    }
    if (end - begin > 1)
    {
      // In index order: the first polygon of each key is kept, the later ones are duplicates.
      distinct.clear();
      for (std::size_t k = begin; k < end; ++k)
      {
        poll.tick();
        keyOf(hashes[k].second, key);
        const bool seen = std::find(distinct.begin(), distinct.end(), key) != distinct.end();
        duplicate[hashes[k].second] = seen;
        if (!seen)
        {
          distinct.push_back(key);
        }
      }
    }
    begin = end;
  }
  return duplicate;
}

/// True when all corners lie on one line (ear clipping cannot tell a polygon without area
/// from a self-crossing one).
bool isCollinear(const std::vector<Vec3>& corners)
{
  Vec3 far = corners[0];
  for (const Vec3& p : corners)
  {
    far = lengthSquared(p - corners[0]) > lengthSquared(far - corners[0]) ? p : far;
  }
  const Vec3 axis = far - corners[0];
  for (const Vec3& p : corners)
  {
    if (length(cross(p - corners[0], axis)) > 1e-10 * lengthSquared(axis))
    {
      return false;
    }
  }
  return true;
}

Triangulation triangulate(const PolygonSoup& soup,
  const std::vector<std::uint32_t>& materialOfPolygon, detail::CancellationPoll& poll)
{
  Triangulation out;
  const std::vector<bool> duplicate = duplicatePolygons(soup, poll);
  std::vector<Vec3> corners;
  for (std::size_t i = 0; i < soup.polygons.size(); ++i)
  {
    poll.tick();
    const auto& polygon = soup.polygons[i];
    if (polygon.size() < 3 || duplicate[i])
    {
      ++(duplicate[i] ? out.duplicates : out.linesAndPoints);
      continue;
    }
    corners.clear();
    for (std::uint32_t v : polygon)
    {
      corners.push_back(soup.points[v]);
    }
    const auto ears = triangulatePolygon(corners);
    if (ears.empty())
    {
      ++(isCollinear(corners) ? out.zeroArea : out.selfCrossing);
      continue;
    }
    for (const auto& t : ears)
    {
      const Triangle triangle{ polygon[t[0]], polygon[t[1]], polygon[t[2]] };
      out.soup.triangles.push_back(triangle);
      out.soup.material.push_back(materialOfPolygon[i]);
      out.soup.polygon.push_back(static_cast<std::uint32_t>(i));
      out.area += triangleArea(soup.points, triangle);
    }
  }
  return out;
}

void addTriangulationWarnings(const Triangulation& t, std::vector<std::string>& warnings)
{
  if (t.linesAndPoints > 0)
  {
    warnings.push_back("ignored " +
      countOf(t.linesAndPoints, "line or vertex", "lines or vertices") +
      " (polygons with fewer than 3 points): only surfaces are remeshed");
  }
  if (t.duplicates > 0)
  {
    warnings.push_back("ignored " + countOf(t.duplicates, "duplicate polygon") +
      " (on the same points as an earlier polygon, whose material was kept)");
  }
  if (t.zeroArea > 0)
  {
    warnings.push_back(
      "ignored " + countOf(t.zeroArea, "polygon") + " with zero area (all points on one line)");
  }
  if (t.selfCrossing > 0)
  {
    warnings.push_back("ignored " + countOf(t.selfCrossing, "self-crossing polygon") +
      ": split such polygons into simple ones to keep them");
  }
}

/// Patches that refining the given triangles (all when `which` is null) at h makes.
double refinedPatchCount(const std::vector<Vec3>& points, const detail::TriangleSoup& soup,
  const std::vector<std::size_t>* which, double h)
{
  double count = 0;
  const std::size_t n = which ? which->size() : soup.triangles.size();
  for (std::size_t i = 0; i < n; ++i)
  {
    const Triangle& t = soup.triangles[which ? (*which)[i] : i];
    const Vec3 &a = points[t[0]], &b = points[t[1]], &c = points[t[2]];
    const double longest = std::max({ length(b - a), length(c - b), length(a - c) });
    const double m = std::max(1.0, std::ceil(longest / h - 1e-9));
    count += m * m;
  }
  return count;
}

/// Patches isotropic remeshing makes of `area` at edge length h.
double remeshedPatchCount(double area, double h)
{
  constexpr double RemeshedPerEquilateral = 1.18; // see edgeLengthForPatchCount
  return area * RemeshedPerEquilateral / (std::sqrt(3.0) / 4.0 * h * h);
}

/// Refuses an h that would cut the scene into more patches than memory allows.
void checkPatchBudget(double expected, double h)
{
  if (expected > MaximumPatches)
  {
    std::ostringstream s;
    s << "the patch size " << h << " would cut the scene into about " << expected
      << " patches (the maximum is " << MaximumPatches << "): give a larger patch size";
    throw Error(s.str());
  }
}

/// Refuses, before allocating, remeshing `inputTriangles` into about `patches` patches when
/// the estimate exceeds the memory limit.
void checkRemeshMemory(
  double inputTriangles, double patches, double h, const RemeshOptions& options)
{
  const double estimate = inputTriangles * BytesPerInputTriangle + patches * BytesPerPatch;
  // Rounded up to whole bytes, so that it is over the limit exactly when the estimate is.
  const std::uint64_t bytes =
    estimate < 0x1p64 ? static_cast<std::uint64_t>(std::ceil(estimate)) : UINT64_MAX;
  std::ostringstream what, detail;
  what.precision(3);
  detail.precision(3);
  what << "remeshing at patch size " << h;
  detail << inputTriangles << " input triangles into about " << patches << " patches";
  MemoryBudget(options.memoryLimitBytes)
    .check(bytes, what.str(), detail.str(),
      "give a larger patch size or a smaller scene, or raise the limit");
}

/// Splits the given input triangles only; progress runs from `from` to 1.
void refineOnly(const std::vector<Vec3>& points, const detail::TriangleSoup& soup,
  const std::vector<std::size_t>& which, const std::vector<Material>& materials, double h,
  const RemeshProgress& progress, double from, PatchMesh& out)
{
  for (std::size_t i = 0; i < which.size(); ++i)
  {
    const Triangle& t = soup.triangles[which[i]];
    refineTriangle(
      points[t[0]], points[t[1]], points[t[2]], h, materials[soup.material[which[i]]], out);
    if (i % 4096 == 0)
    {
      checkProgress(progress, from + (1 - from) * double(i) / double(which.size()));
    }
  }
}

void appendCgalPatches(
  const detail::CgalRemeshOutput& cgal, const std::vector<Material>& materials, PatchMesh& out)
{
  const auto base = static_cast<std::uint32_t>(out.points.size());
  out.points.insert(out.points.end(), cgal.points.begin(), cgal.points.end());
  for (std::size_t i = 0; i < cgal.triangles.size(); ++i)
  {
    const Triangle& t = cgal.triangles[i];
    out.triangles.push_back({ base + t[0], base + t[1], base + t[2] });
    out.reflectance.push_back(materials[cgal.material[i]].reflectance);
    out.emission.push_back(materials[cgal.material[i]].emission);
  }
}
/// `points` snapped to multiples of a power of two near 2^-40 of the scene's extent. Far
/// below float precision for any real scene, it makes coordinates that differ only by
/// subnormal amounts equal, so that CGAL sees exactly degenerate triangles, which its repair
/// drops, rather than triangles of width 1e-38 in a scene of 1e11, which its constrained
/// triangulation walks off (a null face: found by fuzzing).
std::vector<Vec3> snappedPoints(const std::vector<Vec3>& points)
{
  double extent = 0;
  for (const Vec3& p : points)
  {
    extent = std::max({ extent, std::abs(p.x), std::abs(p.y), std::abs(p.z) });
  }
  if (!(extent > 0))
  {
    return points;
  }
  const double quantum = std::ldexp(1.0, std::ilogb(extent) - 40);
  std::vector<Vec3> snapped(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    const Vec3& p = points[i];
    snapped[i] = Vec3(std::nearbyint(p.x / quantum) * quantum,
      std::nearbyint(p.y / quantum) * quantum, std::nearbyint(p.z / quantum) * quantum);
  }
  return snapped;
}

/// Remeshes with CGAL (unless told not to) and refines what it refused, or everything.
void buildPatches(const PolygonSoup& soup, const detail::TriangleSoup& triangles,
  const std::vector<Material>& materials, double h, double expectedPatches,
  const RemeshOptions& options, const RemeshProgress& progress, RemeshResult& result)
{
  if (options.useCgal)
  {
    detail::CgalRemeshSettings settings;
    settings.targetEdgeLength = h;
    settings.sharpEdgeAngle = options.sharpEdgeAngle;
    settings.splitAtContacts = options.splitAtContacts;
    // Splitting at contacts adds triangles: the estimate checked before is checked again.
    settings.checkTriangleCount = [&](std::size_t split)
    { checkRemeshMemory(static_cast<double>(split), expectedPatches, h, options); };
    const detail::CgalRemeshOutput cgal =
      detail::remeshWithCgal(snappedPoints(soup.points), triangles, materials, settings,
        [&](double f) { return !progress || progress(CgalShare * f); });
    appendCgalPatches(cgal, materials, result.mesh);
    std::vector<std::size_t> refined(cgal.refineOnly.triangles.size());
    std::iota(refined.begin(), refined.end(), std::size_t(0));
    if (!refined.empty())
    {
      // What CGAL refused is refined: check its size before allocating it.
      const double count = refinedPatchCount(cgal.refinePoints, cgal.refineOnly, nullptr, h);
      checkPatchBudget(count + static_cast<double>(result.mesh.triangles.size()), h);
      checkRemeshMemory(0, count + static_cast<double>(result.mesh.triangles.size()), h, options);
    }
    result.statistics.regions = cgal.regions;
    result.statistics.fallbackRegions = cgal.fallbackRegions;
    result.statistics.removedTriangles =
      cgal.degenerateTriangles + cgal.duplicateTriangles + cgal.foldedTriangles;
    result.statistics.contactSplitTriangles = cgal.contactSplitTriangles;
    result.statistics.coveredTriangles = cgal.coveredTriangles;
    result.statistics.coveredArea = cgal.coveredArea;
    result.statistics.secondsContacts = cgal.contactSeconds;
    result.warnings.insert(result.warnings.end(), cgal.warnings.begin(), cgal.warnings.end());
    refineOnly(
      cgal.refinePoints, cgal.refineOnly, refined, materials, h, progress, CgalShare, result.mesh);
  }
  else
  {
    std::vector<std::size_t> all(triangles.triangles.size());
    std::iota(all.begin(), all.end(), std::size_t(0));
    refineOnly(soup.points, triangles, all, materials, h, progress, 0.0, result.mesh);
  }
}

double totalArea(const PatchMesh& mesh)
{
  double sum = 0;
  for (const Triangle& t : mesh.triangles)
  {
    sum += triangleArea(mesh.points, t);
  }
  return sum;
}
}

double edgeLengthForPatchCount(double area, std::size_t patches)
{
  // Isotropic remeshing keeps edges between 4/5 h and 4/3 h, and its triangles come out
  // smaller than equilateral ones of side h: measured on spheres, cubes and the paper-scale
  // room, ~18% more of them.
  constexpr double RemeshedPerEquilateral = 1.18;
  const double count = static_cast<double>(std::max<std::size_t>(1, patches));
  return std::sqrt(4.0 * area * RemeshedPerEquilateral / (std::sqrt(3.0) * count));
}

RemeshResult remesh(
  const PolygonSoup& soup, const RemeshOptions& options, const RemeshProgress& progress)
{
  const auto start = std::chrono::steady_clock::now();
  validateOptions(options);
  validateSoup(soup);
  RemeshResult result;
  RemeshStatistics& stats = result.statistics;
  stats.inputPolygons = soup.polygons.size();

  std::vector<std::uint32_t> materialOfPolygon;
  const std::vector<Material> materials = distinctMaterials(soup, materialOfPolygon);
  detail::CancellationPoll poll([&progress] { return !progress || progress(0.0); });
  const Triangulation triangulation = triangulate(soup, materialOfPolygon, poll);
  const detail::TriangleSoup& triangles = triangulation.soup;
  stats.inputTriangles = triangles.triangles.size();
  stats.inputArea = triangulation.area;
  stats.droppedPolygons = triangulation.linesAndPoints + triangulation.duplicates +
    triangulation.zeroArea + triangulation.selfCrossing;
  if (triangles.triangles.empty())
  {
    // Say why, as the warnings of a scene with some area do: a self-crossing polygon wants
    // splitting, not the "degenerate" a user would look for in vain.
    const Triangulation& t = triangulation;
    std::string why;
    const std::pair<std::size_t, std::string> reasons[] = {
      { t.selfCrossing, countOf(t.selfCrossing, "self-crossing polygon") },
      { t.zeroArea, countOf(t.zeroArea, "polygon") + " with zero area (all points on one line)" },
      { t.linesAndPoints, countOf(t.linesAndPoints, "line or vertex", "lines or vertices") },
      { t.duplicates, countOf(t.duplicates, "duplicate polygon") },
    };
    for (const auto& [count, text] : reasons)
    {
      why += count > 0 ? (why.empty() ? "" : ", ") + text : "";
    }
    throw Error("the scene has no polygon with an area (" + why +
      "): give at least one triangle or polygon that encloses area" +
      (t.selfCrossing > 0 ? ", and split self-crossing polygons into simple ones" : ""));
  }
  addTriangulationWarnings(triangulation, result.warnings);

  const double h = options.targetEdgeLength > 0
    ? options.targetEdgeLength
    : edgeLengthForPatchCount(stats.inputArea, options.targetPatchCount);
  stats.targetEdgeLength = h;
  // Refining makes exactly this many patches; remeshing about the area-based count, unless
  // CGAL refuses regions, which are then refined (and checked again, see buildPatches).
  const double refinedCount = refinedPatchCount(soup.points, triangles, nullptr, h);
  checkPatchBudget(refinedCount, h);
  const double expected =
    options.useCgal ? std::min(refinedCount, remeshedPatchCount(stats.inputArea, h)) : refinedCount;
  checkRemeshMemory(
    options.useCgal ? static_cast<double>(triangles.triangles.size()) : 0, expected, h, options);
  if (options.checkExpectedPatches)
  {
    options.checkExpectedPatches(static_cast<std::size_t>(std::min(expected, MaximumPatches)));
  }

  buildPatches(soup, triangles, materials, h, expected, options, progress, result);
  if (result.mesh.triangles.empty())
  {
    throw Error("the scene has no surface left after merging duplicate points (" +
      std::to_string(stats.removedTriangles) +
      " triangles became degenerate or duplicates): "
      "give at least one triangle with an area");
  }
  stats.patches = result.mesh.triangles.size();
  stats.outputArea = totalArea(result.mesh);
  // Patches far finer than asked for share the paths: most elements get no hit and the
  // result is speckle, with no error of the input's to see why.
  const double aimed = std::max(1.0, remeshedPatchCount(stats.inputArea, h));
  if (static_cast<double>(stats.patches) > ManyMorePatchesThanAimed * aimed)
  {
    std::ostringstream s;
    s << "the scene keeps " << stats.patches << " patches, " << std::setprecision(2)
      << static_cast<double>(stats.patches) / aimed << " times the about " << std::setprecision(6)
      << static_cast<std::size_t>(aimed) << " its patch size " << h
      << " aims at: its triangles are finer than that and are kept where they cannot be "
         "merged (regions only refined, small separate pieces). The paths are shared by that "
         "many more patches, so most elements get none (speckle, large errors): give about as "
         "many times the paths, or simplify the mesh first (ParaView's Decimate or Quadric "
         "Clustering)";
    result.warnings.push_back(s.str());
  }
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  checkProgress(progress, 1.0);
  return result;
}

} // namespace mlr
