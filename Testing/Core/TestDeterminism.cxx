// The same seed gives the same bits whatever the thread count; another seed does not.
#include "CoreChecks.h"
#include "FixedPointAccumulator.h"
#include "GeneratedScenes.h"
#include "RayTracer.h"
#include "Shooting.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace mlr;

namespace
{
constexpr std::size_t Frames = 4;

Scene box()
{
  return Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(0.6, 0.5, 0.4) }));
}

MovingLight boxLight()
{
  return MovingLight(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.7, 0.9 }, Frames));
}

/// `memoryLimit` 0 is the default limit, under which this small solve takes one accumulator
/// copy per worker.
Solution solveWith(int threads, std::uint64_t seed, bool reuseShooting, bool reuseGathering,
  std::uint64_t memoryLimit = 0)
{
  const Scene scene = box();
  SolverOptions o;
  o.pathsPerFrame = 30000;
  o.threads = threads;
  o.seed = seed;
  o.reuseShooting = reuseShooting;
  o.reuseGathering = reuseGathering;
  o.memoryLimitBytes = memoryLimit;
  return solve(scene, boxLight(), o);
}
}

class Determinism : public ::testing::TestWithParam<std::pair<bool, bool>>
{
};

TEST_P(Determinism, ThreadCountDoesNotChangeABit)
{
  const auto [shooting, gathering] = GetParam();
  Solution one = solveWith(1, 42, shooting, gathering);
  Solution two = solveWith(2, 42, shooting, gathering);
  Solution three = solveWith(3, 42, shooting, gathering);
  EXPECT_TRUE(checks::sameBits(one.directData(), two.directData()));
  EXPECT_TRUE(checks::sameBits(one.indirectData(), two.indirectData()));
  EXPECT_TRUE(checks::sameBits(one.patchData(), two.patchData()));
  EXPECT_TRUE(checks::sameBits(one.directData(), three.directData()));
  EXPECT_TRUE(checks::sameBits(one.indirectData(), three.indirectData()));
  EXPECT_EQ(one.litSideData(), three.litSideData());
  EXPECT_EQ(one.patchLitSideData(), three.patchLitSideData());
  EXPECT_EQ(one.statistics.shootingRays, two.statistics.shootingRays);
  EXPECT_EQ(one.statistics.shadowRays, two.statistics.shadowRays);
  EXPECT_EQ(one.statistics.gatheringRays, two.statistics.gatheringRays);
  EXPECT_EQ(two.statistics.threads, 2);
}

TEST_P(Determinism, SharedAccumulatorsGiveTheSameBits)
{
  // A memory limit under twice the per-worker peak makes the solver share one accumulator
  // copy between the workers (MemoryPlan); integer sums make that change no bit.
  const auto [shooting, gathering] = GetParam();
  const Scene scene = box();
  Solution one = solveWith(1, 42, shooting, gathering);
  // The plan counts accumulators for the sides light can reach (the inside of the box).
  SolverOptions o;
  o.pathsPerFrame = 30000; // solveWith's: how often the sums carry depends on it
  LightRig rig;
  rig.areaLights.push_back(boxLight());
  const checks::Reached reached = checks::reachableOf(scene, rig, o);
  const auto reachable =
    static_cast<std::size_t>(std::count(reached.sides.begin(), reached.sides.end(), 1));
  EXPECT_EQ(one.statistics.reachableSides, reachable);
  EXPECT_EQ(reachable, scene.patchCount());
  o.threads = 3;
  o.memoryLimitBytes = std::uint64_t(1) << 40;
  o.reuseShooting = shooting; // reuse gives the sums' pages back as they are read
  o.reuseGathering = gathering;
  const auto plan = [&]
  {
    return planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), Frames,
      o, 1, &reached.sides, &reached.firstHits);
  };
  const MemoryPlan roomy = plan();
  ASSERT_TRUE(roomy.accumulatorCopyPerWorker);
  o.memoryLimitBytes = 2 * roomy.peak - 1;
  const MemoryPlan tight = plan();
  ASSERT_FALSE(tight.accumulatorCopyPerWorker);
  // One copy of the low words instead of three, and the high words where carries are likely
  // at this N, each buffer in whole pages and with the index of the stored sides: on a scene
  // this small they fit in the same pages, so the shared copy saves nothing here, but it
  // never costs more.
  const auto copies = [&](int n)
  {
    const std::uint64_t elementSides = reachable * Scene::ElementsPerPatch;
    return FixedPointAccumulator<1>::allocatedStoredBytes(n, scene.elementCount(), elementSides,
             Frames, FixedPointAccumulator<1>::highWordsWritten(o.pathsPerFrame, n, elementSides)) +
      FixedPointAccumulator<3>::allocatedStoredBytes(n, scene.patchCount(), reachable, Frames,
        FixedPointAccumulator<3>::highWordsWritten(o.pathsPerFrame, n, reachable)) +
      scene.elementCount() * 2;
  };
  EXPECT_EQ(tight.accumulators, copies(1));
  EXPECT_EQ(roomy.accumulators, copies(3));
  EXPECT_LE(tight.peak, roomy.peak);

  Solution shared = solveWith(3, 42, shooting, gathering, o.memoryLimitBytes);
  EXPECT_TRUE(one.statistics.accumulatorCopyPerWorker);
  EXPECT_FALSE(shared.statistics.accumulatorCopyPerWorker);
  EXPECT_EQ(shared.statistics.memoryEstimateBytes, tight.peak);
  EXPECT_TRUE(checks::sameBits(one.directData(), shared.directData()));
  EXPECT_TRUE(checks::sameBits(one.indirectData(), shared.indirectData()));
  EXPECT_TRUE(checks::sameBits(one.patchData(), shared.patchData()));
}

TEST_P(Determinism, DifferentSeedsGiveDifferentResults)
{
  const auto [shooting, gathering] = GetParam();
  Solution a = solveWith(2, 1, shooting, gathering);
  Solution b = solveWith(2, 2, shooting, gathering);
  EXPECT_FALSE(checks::sameBits(a.directData(), b.directData()));
  EXPECT_FALSE(checks::sameBits(a.indirectData(), b.indirectData()));
}

INSTANTIATE_TEST_SUITE_P(AllReuseModes, Determinism,
  ::testing::Values(std::make_pair(false, false), std::make_pair(true, false),
    std::make_pair(false, true), std::make_pair(true, true)),
  [](const auto& info)
  {
    return std::string(info.param.first ? "ShootingReuse" : "ShootingClassic") +
      (info.param.second ? "GatheringReuse" : "GatheringClassic");
  });

TEST(Determinism, SidesWithoutSlotsLoseNoLight)
{
  // Shooting with slots for no side at all sends every score to the overflow entries: the
  // direct light and the patch solution must be the same bits as with slots for every side,
  // classic and reused, on one worker and three.
  const Scene scene = box();
  LightRig rig;
  rig.areaLights.emplace_back(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.7, 0.9 }, Frames));
  const std::vector<MovingLight> emitters;
  const std::vector<LightSource> sources = lightSources(scene, rig, emitters);
  ASSERT_EQ(sources.size(), 1u);
  const RayTracer tracer(scene);
  const std::vector<std::uint8_t> none(2 * scene.patchCount(), 0);
  for (bool reuse : { false, true })
  {
    auto shot = [&](
                  int workers, const std::vector<std::uint8_t>& reachable, std::uint64_t& overflow)
    {
      SolverOptions o;
      o.pathsPerFrame = 20000;
      o.reuseShooting = reuse;
      Solution solution(Frames, scene.elementCount(), scene.patchCount());
      double reducing = 0;
      overflow = shoot(
        scene, sources[0], o, tracer, workers, true, {}, reachable, [](double) { return true; },
        reducing, solution)
                   .overflowSides;
      return solution;
    };
    std::uint64_t overflowAll = 0, overflowNone = 0, overflowThree = 0;
    Solution all = shot(1, {}, overflowAll);
    Solution overflowed = shot(1, none, overflowNone);
    Solution three = shot(3, none, overflowThree);
    EXPECT_EQ(overflowAll, 0u);
    EXPECT_GT(overflowNone, scene.patchCount()) << "elements' and patches' sides were hit";
    EXPECT_EQ(overflowThree, overflowNone);
    EXPECT_TRUE(checks::sameBits(all.directData(), overflowed.directData())) << reuse;
    EXPECT_TRUE(checks::sameBits(all.patchData(), overflowed.patchData())) << reuse;
    EXPECT_TRUE(checks::sameBits(all.directData(), three.directData())) << reuse;
    EXPECT_TRUE(checks::sameBits(all.patchData(), three.patchData())) << reuse;
  }
}
