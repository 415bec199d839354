// The lit sides a Solution chooses once its radiosity is complete (one per surface), and how
// it stores results.
#include "GeneratedScenes.h"
#include "Solution.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

using namespace mlr;

namespace
{
/// Two surfaces: a sheet of two coplanar patches of areas 0.5 and 1.5 facing +z (patches 0
/// and 1, one surface), and a patch standing on the first's edge y = 0 at 90 degrees (patch
/// 2, a surface of its own).
Scene twoSurfaces()
{
  PatchMesh mesh;
  mesh.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, { -3, 0, 0 }, { 0, 0, 1 } };
  mesh.triangles = { { 0, 1, 2 }, { 0, 2, 3 }, { 1, 0, 4 } };
  mesh.reflectance.assign(3, Rgb(0.5));
  return Scene::fromPatchMesh(mesh);
}

void set(StoredArray& data, std::size_t index, double value)
{
  data[index] = PackedRgb(Rgb(value, value, value));
}
}

TEST(Solution, EverySurfaceShowsTheSideItsElementsReceivedMoreOnByArea)
{
  const Scene scene = twoSurfaces();
  ASSERT_EQ(scene.regionCount(), 2u);
  ASSERT_DOUBLE_EQ(scene.patchArea(0), 0.5);
  ASSERT_DOUBLE_EQ(scene.patchArea(1), 1.5);
  // Two frames. The sheet: three elements of its small patch received 4 on the front in
  // frame 0 and its fourth 5 on the back in frame 1; the large patch's elements 2 on the back
  // in frame 1 and one of them 3 on its front in frame 0. Summed element by element the
  // front has more (15 against 13), weighted by area the back (2.625 against 3.625): the
  // whole sheet shows its back, the elements that received more on their fronts too.
  Solution solution(2, scene.elementCount(), scene.patchCount());
  for (std::size_t e = 0; e < 4; ++e)
  {
    set(solution.directData(), solution.elementIndex(0, e, Side::Front), e == 1 ? 0.0 : 4.0);
    set(solution.directData(), solution.elementIndex(1, 4 + e, Side::Back), 2.0);
  }
  set(solution.directData(), solution.elementIndex(1, 1, Side::Back), 5.0);
  set(solution.directData(), solution.elementIndex(0, 6, Side::Front), 3.0);
  // The standing patch is black: its radiosity is nothing on either side, and its sides are
  // chosen by irradiance, more on the front over the patch though one element got more on
  // its back. The patches' own (shooting) radiosity is brighter on the back of every patch:
  // patches show their surface's side, not their own.
  solution.reflectanceData().assign(scene.elementCount(), Rgb(1));
  for (std::size_t e = 8; e < 12; ++e)
  {
    solution.reflectanceData()[e] = Rgb(0);
    set(solution.directData(), solution.elementIndex(0, e, Side::Front), e == 8 ? 0.0 : 1.0);
  }
  set(solution.directData(), solution.elementIndex(1, 8, Side::Back), 2.0);
  for (std::size_t p = 0; p < 3; ++p)
  {
    set(solution.patchData(), solution.patchIndex(0, p, Side::Back), 100.0);
  }
  solution.allocateIndirect();
  solution.chooseLitSides(scene, 2);
  const Side expected[] = { Side::Back, Side::Back, Side::Front };
  for (std::size_t p = 0; p < 3; ++p)
  {
    EXPECT_EQ(solution.patchLitSide(p), expected[p]) << p;
    for (std::size_t e = 4 * p; e < 4 * p + 4; ++e)
    {
      EXPECT_EQ(solution.litSide(e), expected[p]) << e;
    }
  }
  // Alike on both sides: the front.
  Solution tie(1, scene.elementCount(), scene.patchCount());
  set(tie.directData(), tie.elementIndex(0, 0, Side::Front), 1.0);
  set(tie.directData(), tie.elementIndex(0, 1, Side::Back), 1.0);
  tie.chooseLitSides(scene, 1);
  EXPECT_EQ(tie.litSide(1), Side::Front);
}

TEST(Solution, LitSidesDoNotDependOnTheWorkers)
{
  // More patches than one worker's block, so that blocks end inside the data: 1250 loose
  // triangles (a surface each) and a grid of 1250 (one surface), random light on both sides.
  // Every element and patch shows its surface's side, litSideOf on the area-weighted sums
  // of its elements' totals, the same for 1 and 3 workers.
  constexpr std::size_t Frames = 3, Loose = 1250;
  PatchMesh mesh;
  for (std::size_t t = 0; t < Loose; ++t)
  {
    const auto first = static_cast<std::uint32_t>(mesh.points.size());
    const double x = static_cast<double>(t % 50), y = static_cast<double>(t / 50);
    mesh.points.insert(
      mesh.points.end(), { { x, y, 5 }, { x + 1 + 0.01 * double(t % 7), y, 5 }, { x, y + 1, 5 } });
    mesh.triangles.push_back({ first, first + 1, first + 2 });
    mesh.reflectance.push_back(Rgb(0.5));
  }
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 50, 0, 0 }, { 0, 30, 0 }, 25, 25, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::size_t patches = scene.patchCount(), elements = scene.elementCount();
  ASSERT_EQ(scene.regionCount(), Loose + 1);
  Solution solution(Frames, elements, patches);
  std::uint64_t state = 12345;
  auto next = [&]
  {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 40) / double(1ull << 24);
  };
  for (std::size_t f = 0; f < Frames; ++f)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      for (std::size_t e = 0; e < elements; ++e)
      {
        // A tenth of the elements black on both sides in every frame.
        const double value = e % 10 == 3 ? 0.0 : next();
        solution.directData()[solution.elementIndex(f, e, side)] =
          PackedRgb(Rgb(value, 0.5 * value, 0.25 * value));
      }
    }
  }
  solution.allocateIndirect();
  solution.chooseLitSides(scene, 1);
  const std::vector<Side> one(solution.litSideData()), onePatches(solution.patchLitSideData());
  solution.litSideData().assign(elements, Side::Back);
  solution.patchLitSideData().assign(patches, Side::Back);
  solution.chooseLitSides(scene, 3);
  EXPECT_EQ(solution.litSideData(), one);
  EXPECT_EQ(solution.patchLitSideData(), onePatches);
  std::size_t backs = 0, elementsDisagreeing = 0;
  for (std::size_t p = 0; p < Loose; ++p)
  {
    double front = 0, back = 0;
    for (std::size_t e = 4 * p; e < 4 * p + 4; ++e)
    {
      const Solution::SideTotals t = solution.elementTotals(e);
      front += scene.elementArea(e) * t.front;
      back += scene.elementArea(e) * t.back;
      elementsDisagreeing += Solution::litSideOf(t.front, t.back, t.irradianceFront,
                               t.irradianceBack) != solution.litSide(e);
      ASSERT_EQ(solution.litSide(e), solution.patchLitSide(p)) << e;
    }
    ASSERT_EQ(solution.patchLitSide(p), Solution::litSideOf(front, back, 0, 0)) << p;
    backs += solution.patchLitSide(p) == Side::Back;
  }
  // Both choices occur, so the comparison above can fail; and the surface's choice is not
  // every element's own.
  EXPECT_GT(backs, Loose / 4);
  EXPECT_LT(backs, 3 * Loose / 4);
  EXPECT_GT(elementsDisagreeing, Loose / 2);
  for (std::size_t p = Loose; p < patches; ++p)
  {
    ASSERT_EQ(solution.patchLitSide(p), solution.patchLitSide(Loose)) << p;
    for (std::size_t e = 4 * p; e < 4 * p + 4; ++e)
    {
      ASSERT_EQ(solution.litSide(e), solution.patchLitSide(Loose)) << e;
    }
  }
}

TEST(Solution, StoredResultsKeepTheirPrecisionInAnyUnit)
{
  // A room of 100 m^2 in metres, in micrometres and at the coordinate bound's scale, lit by
  // lights of 10^-20 W to 10^20 W: its irradiance ranges over 80 decades, beyond PackedRgb's
  // 37, and is stored as a multiple of the mean irradiance, lights' power over area, with
  // room for peaks of 10^15 times it and dim corners of 10^-15.
  for (const double metre : { 1.0, 1e6, 1e13 })
  {
    for (const double power : { 1e-20, 1.0, 1e20 })
    {
      const double area = 100 * metre * metre;
      const double scale = Solution::storageScaleFor(area, power);
      int exponent = 0;
      EXPECT_EQ(std::frexp(scale, &exponent), 0.5) << "a power of two";
      const double mean = power / area;
      EXPECT_GT(mean / scale, 0.7);
      EXPECT_LT(mean / scale, 1.5);
      Solution solution(1, 4, 1);
      solution.setStorageScale(scale);
      for (const double share : { 1e-15, 1.0, 1e15 })
      {
        const double irradiance = share * mean;
        const Rgb back = solution.load(solution.store(Rgb(irradiance, 0.5 * irradiance, 0)));
        EXPECT_NEAR(back.r, irradiance, PackedRgb::RelativeRounding * irradiance) << area;
        EXPECT_NEAR(back.g, 0.5 * irradiance, PackedRgb::RelativeRounding * irradiance) << area;
        EXPECT_EQ(back.b, 0.0);
      }
    }
  }
  // Lights all off: the area alone; no area: 1.
  EXPECT_EQ(Solution::storageScaleFor(4, 0), 0.25);
  EXPECT_EQ(Solution::storageScaleFor(0, 1), 1.0);
  EXPECT_EQ(Solution::storageScaleFor(std::nan(""), 1), 1.0);
}
