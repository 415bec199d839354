// Contact lines (issue 11, item 4): surfaces are split where others touch or cross them, so
// that no patch straddles a contact and averages lit floor with the dark under a block.
#include "GeneratedScenes.h"
#include "Remeshing.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <iostream>
#include <string>
#include <vector>

using namespace mlr;
using namespace mlr::scenes;

namespace
{
constexpr double Pi = 3.14159265358979323846;

// The block of every scene below, standing on a 2 x 2 floor.
const Vec3 BlockLo{ 0.7, 0.7, 0.0 }, BlockHi{ 1.3, 1.3, 0.6 };
const Rgb FloorRho(0.5, 0.5, 0.5), BlockRho(0.6, 0.6, 0.6);

RemeshOptions withEdgeLength(double h, bool split = true)
{
  RemeshOptions options;
  options.targetEdgeLength = h;
  options.splitAtContacts = split;
  return options;
}

std::string joined(const std::vector<std::string>& warnings)
{
  std::string all;
  for (const std::string& w : warnings)
  {
    all += "\n  " + w;
  }
  return all.empty() ? " (none)" : all;
}

double triangleArea(const Vec3& a, const Vec3& b, const Vec3& c)
{
  return 0.5 * length(triangleAreaVector(a, b, c));
}

struct Point2
{
  double x, y;
};

/// The area of the part of triangle abc (projected onto z = 0) inside the axis-aligned
/// rectangle [lo, hi]: Sutherland-Hodgman clipping against its four sides.
double areaInside(const Vec3& a, const Vec3& b, const Vec3& c, const Point2& lo, const Point2& hi)
{
  std::vector<Point2> polygon = { { a.x, a.y }, { b.x, b.y }, { c.x, c.y } };
  // Each side keeps the points with s * (coordinate - bound) >= 0.
  const std::array<std::tuple<bool, double, double>, 4> sides = { std::tuple{ true, lo.x, 1.0 },
    std::tuple{ true, hi.x, -1.0 }, std::tuple{ false, lo.y, 1.0 }, std::tuple{ false, hi.y, -1.0 } };
  for (const auto& [onX, bound, sign] : sides)
  {
    auto distance = [&, onX = onX, bound = bound, sign = sign](const Point2& p) {
      return sign * ((onX ? p.x : p.y) - bound);
    };
    std::vector<Point2> clipped;
    for (std::size_t i = 0; i < polygon.size(); ++i)
    {
      const Point2& p = polygon[i];
      const Point2& q = polygon[(i + 1) % polygon.size()];
      const double dp = distance(p), dq = distance(q);
      if (dp >= 0)
      {
        clipped.push_back(p);
      }
      if ((dp >= 0) != (dq >= 0))
      {
        const double t = dp / (dp - dq);
        clipped.push_back({ p.x + t * (q.x - p.x), p.y + t * (q.y - p.y) });
      }
    }
    polygon = clipped;
  }
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const Point2& p = polygon[i];
    const Point2& q = polygon[(i + 1) % polygon.size()];
    twice += p.x * q.y - q.x * p.y;
  }
  return std::abs(twice) / 2;
}

const Point2 FootprintLo{ BlockLo.x, BlockLo.y }, FootprintHi{ BlockHi.x, BlockHi.y };

bool onFloor(const PatchMesh& mesh, std::size_t p)
{
  const Triangle& t = mesh.triangles[p];
  return std::all_of(t.begin(), t.end(), [&](std::uint32_t v) { return std::abs(mesh.points[v].z) < 1e-12; }) &&
    mesh.reflectance[p] == FloorRho;
}

double floorArea(const PatchMesh& mesh)
{
  double sum = 0;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    const Triangle& t = mesh.triangles[p];
    sum += onFloor(mesh, p) ? triangleArea(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]) : 0.0;
  }
  return sum;
}

/// Floor patches partly inside and partly outside the block's footprint (more than a
/// millionth of their area on the smaller side).
std::size_t straddlingFloorPatches(const PatchMesh& mesh, std::size_t* inside = nullptr)
{
  std::size_t straddling = 0;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    if (!onFloor(mesh, p))
    {
      continue;
    }
    const Triangle& t = mesh.triangles[p];
    const Vec3 &a = mesh.points[t[0]], &b = mesh.points[t[1]], &c = mesh.points[t[2]];
    const double in = areaInside(a, b, c, FootprintLo, FootprintHi) / triangleArea(a, b, c);
    straddling += (in > 1e-6 && in < 1 - 1e-6) ? 1 : 0;
    if (inside && in >= 1 - 1e-6)
    {
      ++*inside;
    }
  }
  return straddling;
}

double totalArea(const PatchMesh& mesh)
{
  double sum = 0;
  for (const Triangle& t : mesh.triangles)
  {
    sum += triangleArea(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]]);
  }
  return sum;
}
}

// --- Geometry ---------------------------------------------------------------------------------

TEST(ContactLines, FloorIsCutAlongTheFootprintOfAClosedBlockAndTheCoveredPartDropped)
{
  const PolygonSoup soup = blockOnFloor(2.0, BlockLo, BlockHi, FloorRho, BlockRho);
  const RemeshResult result = remesh(soup, withEdgeLength(0.1));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_TRUE(result.warnings.empty()) << joined(result.warnings);
  std::size_t inside = 0;
  EXPECT_EQ(straddlingFloorPatches(result.mesh, &inside), 0u);
  EXPECT_EQ(inside, 0u) << "the floor under the closed block is kept";
  // The floor under the block (0.36 m^2) is dropped, the block is kept whole, bottom included.
  const double footprint = 0.6 * 0.6;
  EXPECT_GT(result.statistics.contactSplitTriangles, 0u);
  EXPECT_NEAR(result.statistics.coveredArea, footprint, 1e-9);
  EXPECT_NEAR(floorArea(result.mesh), 4.0 - footprint, 1e-9);
  const double blockArea = 6 * footprint;
  EXPECT_NEAR(totalArea(result.mesh), 4.0 + blockArea - footprint, 0.005 * (4.0 + blockArea));
  double bottom = 0;
  for (std::size_t p = 0; p < result.mesh.triangles.size(); ++p)
  {
    const Triangle& t = result.mesh.triangles[p];
    const Vec3 n = triangleAreaVector(result.mesh.points[t[0]], result.mesh.points[t[1]], result.mesh.points[t[2]]);
    if (result.mesh.reflectance[p] == BlockRho && n.z < 0)
    {
      bottom += 0.5 * length(n);
    }
  }
  EXPECT_NEAR(bottom, footprint, 1e-9) << "the block's bottom face must stay: the block stays closed";
}

TEST(ContactLines, FloorUnderAnOpenBlockIsCutAndKept)
{
  const PolygonSoup soup = blockOnFloor(2.0, BlockLo, BlockHi, FloorRho, BlockRho, true);
  const RemeshResult result = remesh(soup, withEdgeLength(0.1));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  std::size_t inside = 0;
  EXPECT_EQ(straddlingFloorPatches(result.mesh, &inside), 0u);
  EXPECT_GT(inside, 0u);
  EXPECT_EQ(result.statistics.coveredTriangles, 0u);
  EXPECT_NEAR(floorArea(result.mesh), 4.0, 0.005 * 4.0);
}

TEST(ContactLines, WithoutSplittingFloorPatchesStraddleTheFootprint)
{
  // What the tests above guard against: the remesher alone lays patches across the contact.
  const PolygonSoup soup = blockOnFloor(2.0, BlockLo, BlockHi, FloorRho, BlockRho);
  const RemeshResult result = remesh(soup, withEdgeLength(0.1, false));
  EXPECT_GT(straddlingFloorPatches(result.mesh), 10u);
}

TEST(ContactLines, WallIsCutWherePanelPassesThroughIt)
{
  const RemeshResult result = remesh(panelThroughWall(), withEdgeLength(0.07));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_TRUE(result.warnings.empty()) << joined(result.warnings);
  EXPECT_GT(result.statistics.contactSplitTriangles, 0u);
  EXPECT_EQ(result.statistics.coveredTriangles, 0u) << "an open panel encloses nothing";
  EXPECT_NEAR(totalArea(result.mesh), 1.0 + 0.36, 0.005 * 1.36);
  const double tolerance = 1e-9;
  bool segmentStart = false, segmentEnd = false;
  for (std::size_t p = 0; p < result.mesh.triangles.size(); ++p)
  {
    const Triangle& t = result.mesh.triangles[p];
    std::array<Vec3, 3> v = { result.mesh.points[t[0]], result.mesh.points[t[1]], result.mesh.points[t[2]] };
    if (std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return std::abs(q.x) < tolerance; }))
    {
      // A wall patch: where it crosses the panel's plane y = 0.5, it must stay off the
      // segment z in (0.2, 0.8) where the panel passes through.
      double zLow = 2, zHigh = -1;
      for (int k = 0; k < 3; ++k)
      {
        const Vec3& a = v[static_cast<std::size_t>(k)];
        const Vec3& b = v[static_cast<std::size_t>((k + 1) % 3)];
        const double da = a.y - 0.5, db = b.y - 0.5;
        if ((da < -tolerance && db > tolerance) || (da > tolerance && db < -tolerance))
        {
          const double z = a.z + (b.z - a.z) * da / (da - db);
          zLow = std::min(zLow, z);
          zHigh = std::max(zHigh, z);
        }
      }
      EXPECT_TRUE(zHigh < zLow || zHigh <= 0.2 + 1e-9 || zLow >= 0.8 - 1e-9)
        << "wall patch " << p << " straddles the panel between z = " << zLow << " and " << zHigh;
      for (const Vec3& q : v)
      {
        segmentStart = segmentStart || length(q - Vec3{ 0, 0.5, 0.2 }) < tolerance;
        segmentEnd = segmentEnd || length(q - Vec3{ 0, 0.5, 0.8 }) < tolerance;
      }
    }
    else
    {
      // A panel patch: wholly on one side of the wall.
      const bool behind = std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return q.x <= tolerance; });
      const bool front = std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return q.x >= -tolerance; });
      EXPECT_TRUE(behind || front) << "panel patch " << p << " straddles the wall";
    }
  }
  EXPECT_TRUE(segmentStart && segmentEnd) << "the ends of the contact segment are not patch corners";
}

TEST(ContactLines, WallInsideAThickPanelIsCutOutAndKept)
{
  // Inside a closed surface without touching it face to face: kept (it could be a room).
  const double thickness = 0.04;
  const RemeshResult result = remesh(panelThroughWall(thickness), withEdgeLength(0.07));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_EQ(result.statistics.coveredTriangles, 0u);
  EXPECT_NEAR(totalArea(result.mesh), 1.0 + 2 * (0.6 * 0.6 + 0.6 * thickness + 0.6 * thickness), 1e-3);
  double inside = 0;
  for (std::size_t p = 0; p < result.mesh.triangles.size(); ++p)
  {
    const Triangle& t = result.mesh.triangles[p];
    const std::array<Vec3, 3> v = { result.mesh.points[t[0]], result.mesh.points[t[1]], result.mesh.points[t[2]] };
    if (!std::all_of(v.begin(), v.end(), [](const Vec3& q) { return std::abs(q.x) < 1e-12; }))
    {
      continue;
    }
    // A wall patch in the panel's z range lies wholly inside or wholly outside its slab.
    const Vec3 centre = (v[0] + v[1] + v[2]) / 3.0;
    if (centre.z < 0.2 || centre.z > 0.8)
    {
      continue;
    }
    const bool in = std::abs(centre.y - 0.5) < thickness / 2;
    for (const Vec3& q : v)
    {
      EXPECT_EQ(std::abs(q.y - 0.5) <= thickness / 2 + 1e-9, in || std::abs(std::abs(q.y - 0.5) - thickness / 2) < 1e-9)
        << "wall patch " << p << " crosses a face of the panel";
    }
    inside += in ? triangleArea(v[0], v[1], v[2]) : 0.0;
  }
  EXPECT_NEAR(inside, thickness * 0.6, 1e-9);
}

TEST(ContactLines, StackedBlocksLoseBothContactFaces)
{
  // Two closed boxes touching face to face: one closed surface remains around both.
  PolygonSoup soup = boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) });
  append(soup, boxOfQuads({ 0.25, 0.25, 1 }, { 0.75, 0.75, 1.5 }, { Rgb(0.3) }));
  const RemeshResult result = remesh(soup, withEdgeLength(0.1));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_NEAR(result.statistics.coveredArea, 2 * 0.25, 1e-9);
  EXPECT_NEAR(totalArea(result.mesh), 6 + 6 * 0.25 - 2 * 0.25, 0.005 * 7);
}

TEST(ContactLines, SceneWithoutContactsIsUnchangedBySplitting)
{
  const PolygonSoup box = boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) });
  const RemeshResult split = remesh(box, withEdgeLength(0.2));
  const RemeshResult unsplit = remesh(box, withEdgeLength(0.2, false));
  EXPECT_EQ(split.statistics.contactSplitTriangles, 0u);
  EXPECT_EQ(split.statistics.coveredTriangles, 0u);
  EXPECT_EQ(split.mesh.points, unsplit.mesh.points);
  EXPECT_EQ(split.mesh.triangles, unsplit.mesh.triangles);
}
