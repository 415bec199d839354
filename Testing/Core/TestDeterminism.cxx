// The same seed gives the same bits whatever the thread count; another seed does not.
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <cstring>

using namespace mlr;

namespace
{
Solution solveWith(int threads, std::uint64_t seed, bool reuseShooting, bool reuseGathering)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(0.6, 0.5, 0.4) }));
  const MovingLight light(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.7, 0.9 }, 4));
  SolverOptions o;
  o.pathsPerFrame = 30000;
  o.threads = threads;
  o.seed = seed;
  o.reuseShooting = reuseShooting;
  o.reuseGathering = reuseGathering;
  return solve(scene, light, o);
}

bool sameBits(const std::vector<Rgb>& a, const std::vector<Rgb>& b)
{
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(Rgb)) == 0;
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
  EXPECT_TRUE(sameBits(one.directData(), two.directData()));
  EXPECT_TRUE(sameBits(one.indirectData(), two.indirectData()));
  EXPECT_TRUE(sameBits(one.patchData(), two.patchData()));
  EXPECT_TRUE(sameBits(one.directData(), three.directData()));
  EXPECT_TRUE(sameBits(one.indirectData(), three.indirectData()));
  EXPECT_EQ(one.statistics.shootingRays, two.statistics.shootingRays);
  EXPECT_EQ(one.statistics.shadowRays, two.statistics.shadowRays);
  EXPECT_EQ(one.statistics.gatheringRays, two.statistics.gatheringRays);
  EXPECT_EQ(two.statistics.threads, 2);
}

TEST_P(Determinism, DifferentSeedsGiveDifferentResults)
{
  const auto [shooting, gathering] = GetParam();
  Solution a = solveWith(2, 1, shooting, gathering);
  Solution b = solveWith(2, 2, shooting, gathering);
  EXPECT_FALSE(sameBits(a.directData(), b.directData()));
  EXPECT_FALSE(sameBits(a.indirectData(), b.indirectData()));
}

INSTANTIATE_TEST_SUITE_P(AllReuseModes, Determinism,
  ::testing::Values(std::make_pair(false, false), std::make_pair(true, false),
    std::make_pair(false, true), std::make_pair(true, true)),
  [](const auto& info) {
    return std::string(info.param.first ? "ShootingReuse" : "ShootingClassic") +
      (info.param.second ? "GatheringReuse" : "GatheringClassic");
  });
