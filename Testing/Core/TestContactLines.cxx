// Contact lines: surfaces are split where others touch or cross them, so
// that no patch straddles a contact and averages lit floor with the dark under a block.
#include "CoreChecks.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "Remeshing.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
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
    std::tuple{ true, hi.x, -1.0 }, std::tuple{ false, lo.y, 1.0 },
    std::tuple{ false, hi.y, -1.0 } };
  for (const auto& [onX, bound, sign] : sides)
  {
    auto distance = [&, onX = onX, bound = bound, sign = sign](const Point2& p)
    { return sign * ((onX ? p.x : p.y) - bound); };
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
  return std::all_of(t.begin(), t.end(),
           [&](std::uint32_t v) { return std::abs(mesh.points[v].z) < 1e-12; }) &&
    mesh.reflectance[p] == FloorRho;
}

double floorArea(const PatchMesh& mesh)
{
  double sum = 0;
  for (std::size_t p = 0; p < mesh.triangles.size(); ++p)
  {
    const Triangle& t = mesh.triangles[p];
    sum += onFloor(mesh, p) ? triangleArea(mesh.points[t[0]], mesh.points[t[1]], mesh.points[t[2]])
                            : 0.0;
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
    const Vec3 n = triangleAreaVector(
      result.mesh.points[t[0]], result.mesh.points[t[1]], result.mesh.points[t[2]]);
    if (result.mesh.reflectance[p] == BlockRho && n.z < 0)
    {
      bottom += 0.5 * length(n);
    }
  }
  EXPECT_NEAR(bottom, footprint, 1e-9)
    << "the block's bottom face must stay: the block stays closed";
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
    std::array<Vec3, 3> v = { result.mesh.points[t[0]], result.mesh.points[t[1]],
      result.mesh.points[t[2]] };
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
      const bool behind =
        std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return q.x <= tolerance; });
      const bool front =
        std::all_of(v.begin(), v.end(), [&](const Vec3& q) { return q.x >= -tolerance; });
      EXPECT_TRUE(behind || front) << "panel patch " << p << " straddles the wall";
    }
  }
  EXPECT_TRUE(segmentStart && segmentEnd)
    << "the ends of the contact segment are not patch corners";
}

TEST(ContactLines, WallInsideAThickPanelIsCutOutAndKept)
{
  // Inside a closed surface without touching it face to face: kept (it could be a room).
  const double thickness = 0.04;
  const RemeshResult result = remesh(panelThroughWall(thickness), withEdgeLength(0.07));
  EXPECT_EQ(result.statistics.fallbackRegions, 0u) << joined(result.warnings);
  EXPECT_EQ(result.statistics.coveredTriangles, 0u);
  EXPECT_NEAR(
    totalArea(result.mesh), 1.0 + 2 * (0.6 * 0.6 + 0.6 * thickness + 0.6 * thickness), 1e-3);
  double inside = 0;
  for (std::size_t p = 0; p < result.mesh.triangles.size(); ++p)
  {
    const Triangle& t = result.mesh.triangles[p];
    const std::array<Vec3, 3> v = { result.mesh.points[t[0]], result.mesh.points[t[1]],
      result.mesh.points[t[2]] };
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
      EXPECT_EQ(std::abs(q.y - 0.5) <= thickness / 2 + 1e-9,
        in || std::abs(std::abs(q.y - 0.5) - thickness / 2) < 1e-9)
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

TEST(ContactLines, ContactsOnOppositeTrianglesOfAFanAreSplit)
{
  // A floor of 8 triangles around one point, and two small blocks on two opposite triangles:
  // those triangles and their neighbours meet at the centre only, which a mesh cannot hold
  // unless the triangles between them join in.
  PolygonSoup soup;
  soup.points.push_back({ 0, 0, 0 });
  for (int k = 0; k < 8; ++k)
  {
    soup.points.push_back({ std::cos(k * Pi / 4), std::sin(k * Pi / 4), 0 });
  }
  for (std::uint32_t k = 0; k < 8; ++k)
  {
    soup.polygons.push_back({ 0, 1 + k, 1 + (k + 1) % 8 });
    soup.materials.push_back(Material{ FloorRho });
  }
  const Vec3 centre{ 0.6 * std::cos(Pi / 8), 0.6 * std::sin(Pi / 8), 0 }, half{ 0.025, 0.025, 0 };
  append(soup, boxOfQuads(centre - half, centre + half + Vec3{ 0, 0, 0.05 }, { BlockRho }));
  append(soup,
    boxOfQuads(-1.0 * centre - half, -1.0 * centre + half + Vec3{ 0, 0, 0.05 }, { BlockRho }));
  const RemeshResult result = remesh(soup, withEdgeLength(0.05));
  EXPECT_TRUE(result.warnings.empty()) << joined(result.warnings);
  EXPECT_GE(result.statistics.contactSplitTriangles, 2u);
  EXPECT_NEAR(result.statistics.coveredArea, 2 * 0.05 * 0.05, 1e-12);
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

// --- Light at the contact ---------------------------------------------------------------------

namespace
{
// A square light above the floor beside the block: the block shadows part of the floor next to
// it, and the floor lights the block's sides.
const Vec3 LightCentre{ 0.35, 1.0, 1.2 };
constexpr double LightSide = 0.4;
const Rgb LightPower(10, 10, 10);

/// The ring of floor next to the block: [0.5, 1.5]^2 minus the footprint [0.7, 1.3]^2.
const Point2 RingLo{ 0.5, 0.5 }, RingHi{ 1.5, 1.5 };

struct LitBlock
{
  Scene scene;
  Solution solution;
  std::uint64_t paths = 0;
};

LitBlock solveBlockOnFloor(double h, bool split, std::uint64_t paths, std::uint64_t seed)
{
  const RemeshResult remeshed =
    remesh(blockOnFloor(2.0, BlockLo, BlockHi, FloorRho, BlockRho), withEdgeLength(h, split));
  EXPECT_EQ(remeshed.statistics.fallbackRegions, 0u) << joined(remeshed.warnings);
  LitBlock lit{ Scene::fromPatchMesh(remeshed.mesh), Solution(), paths };
  SolverOptions options;
  options.pathsPerFrame = paths;
  options.reuseShooting = false;
  options.reuseGathering = false;
  options.seed = seed;
  lit.solution = solve(lit.scene,
    MovingLight(squareLightFacingDown(LightCentre, LightSide), LightPower, { Vec3() }), options);
  return lit;
}

bool isFloorElement(const Scene& scene, std::size_t e)
{
  const Triangle& t = scene.elementTriangles()[e];
  return scene.elementReflectance(e) == FloorRho && scene.elementNormal(e).z > 0.999 &&
    std::abs(scene.points()[t[0]].z) < 1e-12;
}

/// Whether the segment from p to q passes through the block (slab test; the ends excluded).
bool blockHides(const Vec3& p, const Vec3& q)
{
  double enter = 1e-12, leave = 1 - 1e-12;
  for (int axis = 0; axis < 3; ++axis)
  {
    const double d = q[axis] - p[axis];
    if (std::abs(d) < 1e-300)
    {
      if (p[axis] <= BlockLo[axis] || p[axis] >= BlockHi[axis])
      {
        return false;
      }
      continue;
    }
    double t0 = (BlockLo[axis] - p[axis]) / d, t1 = (BlockHi[axis] - p[axis]) / d;
    if (t0 > t1)
    {
      std::swap(t0, t1);
    }
    enter = std::max(enter, t0);
    leave = std::min(leave, t1);
  }
  return enter < leave;
}

/// Irradiance at floor point x from the light, by midpoint quadrature over steps x steps
/// points of the light, each seen or hidden by the block exactly.
double irradiance(const Vec3& x, double power, int steps)
{
  const double radiance = power / (Pi * LightSide * LightSide);
  const double cell = LightSide / steps;
  double sum = 0;
  for (int a = 0; a < steps; ++a)
  {
    for (int b = 0; b < steps; ++b)
    {
      const Vec3 y{ LightCentre.x - LightSide / 2 + (a + 0.5) * cell,
        LightCentre.y - LightSide / 2 + (b + 0.5) * cell, LightCentre.z };
      if (!blockHides(x, y))
      {
        const Vec3 d = y - x;
        const double r2 = lengthSquared(d);
        // The cosines at the floor and at the light are both d.z / r.
        sum += radiance * (d.z * d.z / r2) / r2 * cell * cell;
      }
    }
  }
  return sum;
}

/// rho * integral over the ring of the irradiance from the light, by midpoint quadrature:
/// 1 cm cells on the floor (the ring's edges fall on cell edges), 16 x 16 points on the light.
double ringDirectPowerReference(double rho, double power)
{
  constexpr double Cell = 0.01;
  double sum = 0;
  const int cells = static_cast<int>(std::lround((RingHi.x - RingLo.x) / Cell));
  for (int i = 0; i < cells; ++i)
  {
    for (int j = 0; j < cells; ++j)
    {
      const Vec3 x{ RingLo.x + (i + 0.5) * Cell, RingLo.y + (j + 0.5) * Cell, 0 };
      if (x.x > FootprintLo.x && x.x < FootprintHi.x && x.y > FootprintLo.y && x.y < FootprintHi.y)
      {
        continue;
      }
      sum += rho * irradiance(x, power, 16) * Cell * Cell;
    }
  }
  return sum;
}

struct RingPower
{
  double value = 0;
  double sigma = 0; ///< binomial standard deviation of the path count estimate
};

/// The solver's direct power on the ring, taking each element's radiosity as uniform over it
/// (as it is drawn), channel 0; sigma from the paths whose first hit may count.
RingPower ringDirectPower(const LitBlock& lit)
{
  RingPower ring;
  double touchingPower = 0;
  const auto& p = lit.scene.points();
  for (std::size_t e = 0; e < lit.scene.elementCount(); ++e)
  {
    if (!isFloorElement(lit.scene, e))
    {
      continue;
    }
    const Triangle& t = lit.scene.elementTriangles()[e];
    const double overlap = areaInside(p[t[0]], p[t[1]], p[t[2]], RingLo, RingHi) -
      areaInside(p[t[0]], p[t[1]], p[t[2]], FootprintLo, FootprintHi);
    const double B = lit.solution.direct(0, e, Side::Front).r;
    ring.value += overlap * B;
    touchingPower += overlap > 1e-12 ? lit.scene.elementArea(e) * B : 0.0;
  }
  // Each path adds at most rho Phi / N, and only if its first hit is on an element that
  // overlaps the ring, which a fraction touchingPower / (rho Phi) of them do.
  const double unit = FloorRho.r * LightPower.r;
  ring.sigma = unit * std::sqrt(touchingPower / unit / double(lit.paths));
  return ring;
}

/// Power landing on the part of triangle abc outside the footprint: midpoints of a 4^3-triangle
/// subdivision, those under the block left out.
double landingPower(
  const Vec3& a, const Vec3& b, const Vec3& c, double rho, double power, int depth = 3)
{
  if (depth == 0)
  {
    const Vec3 x = (a + b + c) / 3.0;
    const bool under =
      x.x > FootprintLo.x && x.x < FootprintHi.x && x.y > FootprintLo.y && x.y < FootprintHi.y;
    return under ? 0.0 : rho * irradiance(x, power, 8) * triangleArea(a, b, c);
  }
  const Vec3 ab = (a + b) * 0.5, bc = (b + c) * 0.5, ca = (c + a) * 0.5;
  return landingPower(a, ab, ca, rho, power, depth - 1) +
    landingPower(ab, b, bc, rho, power, depth - 1) +
    landingPower(ca, bc, c, rho, power, depth - 1) +
    landingPower(ab, bc, ca, rho, power, depth - 1);
}

struct ZScores
{
  double meanSquare = 0;
  double minimum = 0;
  std::size_t count = 0;
};

/**
 * z = (B - B_seen) / sigma for every floor element in the ring, channel 0. B_seen is the
 * radiosity of the element's visible part: the power landing on it over its area outside the
 * footprint. An element across the footprint's edge shows its power spread over its whole
 * area, too dark by the share of it under the block. sigma is the binomial deviation of the
 * paths' first hits.
 */
ZScores ringElementScores(const LitBlock& lit)
{
  ZScores z;
  const auto& p = lit.scene.points();
  const double unit = FloorRho.r * LightPower.r;
  for (std::size_t e = 0; e < lit.scene.elementCount(); ++e)
  {
    if (!isFloorElement(lit.scene, e))
    {
      continue;
    }
    const Triangle& t = lit.scene.elementTriangles()[e];
    const double area = lit.scene.elementArea(e);
    const double under = areaInside(p[t[0]], p[t[1]], p[t[2]], FootprintLo, FootprintHi);
    if (areaInside(p[t[0]], p[t[1]], p[t[2]], RingLo, RingHi) - under < 1e-12 ||
      area - under < 1e-9 * area)
    {
      continue;
    }
    const double landing = landingPower(p[t[0]], p[t[1]], p[t[2]], FloorRho.r, LightPower.r);
    const double hitProbability = landing / unit;
    if (hitProbability * double(lit.paths) < 20)
    {
      continue; // in shadow: too few hits for a normal z-score
    }
    const double seen = landing / (area - under);
    const double sigma = unit / (double(lit.paths) * area) *
      std::sqrt(double(lit.paths) * hitProbability * (1 - hitProbability));
    const double score = (lit.solution.direct(0, e, Side::Front).r - seen) / sigma;
    z.meanSquare += score * score;
    z.minimum = std::min(z.minimum, score);
    ++z.count;
  }
  z.meanSquare /= double(std::max<std::size_t>(1, z.count));
  return z;
}

/// Indirect power leaving the block's four vertical sides (front: out of the block), channel 0.
double sidesIndirectPower(const LitBlock& lit)
{
  double sum = 0;
  for (std::size_t e = 0; e < lit.scene.elementCount(); ++e)
  {
    if (lit.scene.elementReflectance(e) == BlockRho &&
      std::abs(lit.scene.elementNormal(e).z) < 1e-9)
    {
      sum += lit.scene.elementArea(e) * lit.solution.indirect(0, e, Side::Front).r;
    }
  }
  return sum;
}
}

TEST(ContactLines, DirectPowerOnTheFloorNextToTheBlockMatchesQuadrature)
{
  const double reference = ringDirectPowerReference(FloorRho.r, LightPower.r);
  const LitBlock split = solveBlockOnFloor(0.1, true, 400000, 3);
  const RingPower ring = ringDirectPower(split);
  std::cout << "ring direct power: reference " << reference << " W, split " << ring.value << " +- "
            << ring.sigma << " W\n";
  // 4 sigma of the path count, and 0.5% for taking each element's radiosity as uniform
  // where the ring's outer edge cuts elements.
  EXPECT_NEAR(ring.value, reference, 4 * ring.sigma + 0.005 * reference);
}

TEST(ContactLines, FloorElementsNextToTheBlockShowTheLightTheyReceive)
{
  const std::uint64_t paths = 1000000;
  const ZScores split = ringElementScores(solveBlockOnFloor(0.1, true, paths, 5));
  const ZScores leaky = ringElementScores(solveBlockOnFloor(0.1, false, paths, 5));
  std::cout << "floor elements next to the block: mean z^2 " << split.meanSquare << " (min z "
            << split.minimum << ", " << split.count << " elements); unsplit " << leaky.meanSquare
            << " (min z " << leaky.minimum << ")\n";
  // Independent binomial errors: mean z^2 is 1 up to sqrt(2 / count) (~0.06 here).
  ASSERT_GT(split.count, 200u);
  EXPECT_NEAR(split.meanSquare, 1.0, 0.25);
  EXPECT_GT(split.minimum, -5.0);
  // Unsplit, the elements across the footprint's edge are too dark: the check sees it.
  EXPECT_GT(leaky.meanSquare, 1.5);
  EXPECT_LT(leaky.minimum, -6.0);
}

TEST(ContactLines, IndirectLightOnTheBlockSidesDoesNotDependOnThePatchSize)
{
  // Gathering on the block's sides reads the floor next to them. Coarse floor patches across
  // the footprint's edge average their bounced light (and their elements' direct light) with
  // the dark under the block, so the sides come out dark unless the floor is split there.
  // Means and standard errors over seeds.
  auto sides = [](double h, bool split)
  {
    std::vector<double> values;
    for (std::uint64_t seed = 1; seed <= 8; ++seed)
    {
      values.push_back(sidesIndirectPower(solveBlockOnFloor(h, split, 300000, seed)));
    }
    double mean = 0, square = 0;
    for (double v : values)
    {
      mean += v / double(values.size());
    }
    for (double v : values)
    {
      square += (v - mean) * (v - mean);
    }
    return std::make_pair(
      mean, std::sqrt(square / double(values.size() - 1) / double(values.size())));
  };
  const auto fine = sides(0.05, true);
  const auto coarse = sides(0.5, true);
  const auto leaky = sides(0.5, false);
  std::cout << "block sides, indirect power: fine " << fine.first << " +- " << fine.second
            << ", coarse " << coarse.first << " +- " << coarse.second << ", coarse unsplit "
            << leaky.first << " +- " << leaky.second << " W\n";
  const double noise = std::sqrt(fine.second * fine.second + coarse.second * coarse.second);
  // 4 standard errors, and 1.5% for what coarse patches change elsewhere (measured 0.4%).
  EXPECT_NEAR(coarse.first, fine.first, 4 * noise + 0.015 * fine.first);
  // Unsplit at the same patch size, the sides are darker beyond the noise (measured 4.6%).
  EXPECT_LT(leaky.first,
    coarse.first - 4 * std::sqrt(coarse.second * coarse.second + leaky.second * leaky.second));
}

// --- Cost and cancellation --------------------------------------------------------------------

TEST(ContactLines, TrianglesAddedBySplittingCountAgainstTheMemoryLimit)
{
  const PolygonSoup soup = blockOnFloor(2.0, BlockLo, BlockHi, FloorRho, BlockRho);
  // The smallest limit that passes the check made before any work: checkExpectedPatches runs
  // right after it, and stops the remeshing there.
  struct Passed
  {
  };
  auto passesFirstCheck = [&](std::uint64_t limit)
  {
    RemeshOptions options = withEdgeLength(0.1);
    options.memoryLimitBytes = limit;
    options.checkExpectedPatches = [](std::size_t) { throw Passed{}; };
    try
    {
      remesh(soup, options);
    }
    catch (const Passed&)
    {
      return true;
    }
    catch (const Error&)
    {
    }
    return false;
  };
  std::uint64_t refused = 1, passes = std::uint64_t(1) << 40;
  ASSERT_TRUE(passesFirstCheck(passes));
  while (passes - refused > 1)
  {
    const std::uint64_t middle = refused + (passes - refused) / 2;
    (passesFirstCheck(middle) ? passes : refused) = middle;
  }
  RemeshOptions options = withEdgeLength(0.1);
  options.memoryLimitBytes = passes;
  const std::string message = checks::errorOf([&] { remesh(soup, options); });
  EXPECT_NE(message.find("over the memory limit"), std::string::npos) << message;
  options.splitAtContacts = false;
  EXPECT_NO_THROW(remesh(soup, options));
}

TEST(ContactLines, SplittingIsCancellableAndReportsProgressInOrder)
{
  // A 32,000-triangle sphere crossing a floor: about 600 of its triangles cross it.
  PolygonSoup soup = icosphere(40);
  addPolygon(
    soup, { { -2, -2, -0.5 }, { 2, -2, -0.5 }, { 2, 2, -0.5 }, { -2, 2, -0.5 } }, Rgb(0.3));
  std::vector<double> reported;
  const RemeshResult result = remesh(soup, RemeshOptions{},
    [&](double f)
    {
      reported.push_back(f);
      return true;
    });
  EXPECT_GT(result.statistics.contactSplitTriangles, 300u);
  EXPECT_TRUE(std::is_sorted(reported.begin(), reported.end()));
  EXPECT_EQ(reported.back(), 1.0);
  std::cout << "contacts took " << result.statistics.secondsContacts << " s of "
            << result.statistics.seconds << " s\n";

  // Contacts are split once the surface is repaired, with progress held just under 5%: the
  // second report of that value comes from within the phase, and stopping there stops it.
  std::chrono::steady_clock::time_point asked;
  int held = 0;
  bool cancelled = false;
  try
  {
    remesh(soup, RemeshOptions{},
      [&](double f)
      {
        held += f >= 0.04 ? 1 : 0;
        if (held < 2 && f < 0.05)
        {
          return true;
        }
        asked = std::chrono::steady_clock::now();
        return false;
      });
  }
  catch (const Cancelled&)
  {
    cancelled = true;
    const double latency =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - asked).count();
    // 0.5 s on a quiet machine; ten times that under the gate's load (no timing verdicts).
    EXPECT_LT(latency, 5.0);
  }
  EXPECT_TRUE(cancelled);
}
