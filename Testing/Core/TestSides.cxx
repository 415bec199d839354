// Two-sided surfaces: a box built with outward normals lights up like one built inward;
// one-sided surfaces absorb on their back faces and say so.
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace mlr;

namespace
{
const std::vector<Rgb> walls = { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.6), Rgb(0.6),
  Rgb(0.5), Rgb(0.7) };

MovingLight boxLight()
{
  return MovingLight(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(4),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.6, 0.85 }, 3));
}

SolverOptions options(bool twoSided, std::uint64_t seed)
{
  SolverOptions o;
  o.pathsPerFrame = 200000;
  o.twoSided = twoSided;
  o.seed = seed;
  return o;
}

/// Total radiosity of each wall (elements grouped by face) on the element's lit side.
std::vector<double> wallTotals(const Scene& scene, const Solution& s, std::size_t frame)
{
  std::vector<double> totals(6, 0.0);
  const std::size_t perWall = scene.elementCount() / 6;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    totals[e / perWall] += s.total(frame, e, s.litSide(e)).sum() * scene.elementArea(e);
  }
  return totals;
}
}

TEST(Sides, OutwardBoxTwoSidedMatchesInwardBox)
{
  const Scene inward = Scene::fromPatchMesh(scenes::closedBox(5, true, walls));
  const Scene outward = Scene::fromPatchMesh(scenes::closedBox(5, false, walls));
  const Solution a = solve(inward, boxLight(), options(true, 1));
  const Solution b = solve(outward, boxLight(), options(true, 2));
  for (std::size_t e = 0; e < outward.elementCount(); ++e)
  {
    ASSERT_EQ(b.litSide(e), Side::Back) << "the inside of an outward box is its back side";
    ASSERT_EQ(a.litSide(e), Side::Front);
  }
  for (std::size_t f = 0; f < 3; ++f)
  {
    const auto ta = wallTotals(inward, a, f), tb = wallTotals(outward, b, f);
    for (int w = 0; w < 6; ++w)
    {
      EXPECT_NEAR(tb[w] / ta[w], 1.0, 0.02) << "frame " << f << " wall " << w;
    }
  }
  // The outside of the outward box never received power, so it never gathered.
  EXPECT_EQ(a.statistics.gatheringSides, inward.elementCount());
  EXPECT_EQ(b.statistics.gatheringSides, outward.elementCount());
}

TEST(Sides, OneSidedOutwardBoxStaysDarkAndWarns)
{
  const Scene outward = Scene::fromPatchMesh(scenes::closedBox(5, false, walls));
  const Solution s = solve(outward, boxLight(), options(false, 3));
  for (std::size_t f = 0; f < 3; ++f)
  {
    for (std::size_t e = 0; e < outward.elementCount(); ++e)
    {
      ASSERT_EQ(s.total(f, e, Side::Front), Rgb());
      ASSERT_EQ(s.total(f, e, Side::Back), Rgb());
    }
  }
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("back faces"), std::string::npos) << s.warnings[0];
}

TEST(Sides, OneSidedInwardBoxEqualsTwoSided)
{
  // Every hit inside an inward box is on a front face: one-sided changes nothing.
  const Scene inward = Scene::fromPatchMesh(scenes::closedBox(4, true, walls));
  const Solution one = solve(inward, boxLight(), options(false, 4));
  const Solution two = solve(inward, boxLight(), options(true, 4));
  EXPECT_TRUE(one.warnings.empty());
  for (std::size_t e = 0; e < inward.elementCount(); ++e)
  {
    ASSERT_EQ(one.total(1, e, Side::Front), two.total(1, e, Side::Front));
  }
}

TEST(Sides, ClosedBlockInteriorNeverGathers)
{
  // A solid block (outward normals) inside an inward room: its inside faces get no power,
  // and reachability (from geometry) never lets them gather. The block stands on one floor
  // patch cell exactly: a floor patch straddling the footprint would let the inside see a
  // lit patch, which remeshing prevents by splitting surfaces along contact lines.
  PatchMesh mesh = scenes::closedBox(4, true, { Rgb(0.5) });
  scenes::addBox(mesh, { 0.25, 0.25, 0.0 }, { 0.5, 0.5, 0.4 }, 0.1, false, { Rgb(0.5) }, true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  const Solution s = solve(scene, boxLight(), options(true, 5));
  const std::size_t roomElements = 6 * 4 * 4 * 2 * 4;
  for (std::size_t e = roomElements; e < scene.elementCount(); ++e)
  {
    for (std::size_t f = 0; f < 3; ++f)
    {
      ASSERT_EQ(s.total(f, e, Side::Back), Rgb()) << "element " << e;
    }
    ASSERT_EQ(s.litSide(e), Side::Front);
  }
  // Reachability: the room's outside, the block's inside and the floor cell under the block
  // (2 patches, 8 elements) never gather; every other element gathers on its inner side.
  EXPECT_EQ(s.statistics.gatheringSides, scene.elementCount() - 8);
}

TEST(Sides, LightFacingAwayGivesZeroAndAWarning)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  // A light above the floor that faces up.
  std::vector<std::vector<Vec3>> up = scenes::squareLightFacingDown({ 0.5, 0.5, 1 }, 0.2);
  std::reverse(up[0].begin(), up[0].end());
  const MovingLight light(up, Rgb(1), { Vec3(), Vec3(0.1, 0, 0) });
  SolverOptions o;
  o.pathsPerFrame = 1000;
  const Solution s = solve(scene, light, o);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("face away"), std::string::npos);
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    EXPECT_EQ(s.total(0, e, Side::Front), Rgb());
  }
}
