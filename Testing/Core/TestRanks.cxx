// A solve shared by R ranks gives every rank the serial solution bit for bit, for
// any number of ranks and threads, and a cancel or failure on one rank stops them all. The
// ranks are threads of this process here, their sums a barrier: Core knows no MPI, only
// SolverOptions' sum hooks (the filter's tests run the same under mpiexec).
#include "CoreChecks.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "Solver.h"
#include "ThreadRanks.h"

#include <gtest/gtest.h>

#include <exception>
#include <string>
#include <thread>
#include <vector>

using namespace mlr;
using mlr::checks::ThreadRanks;

namespace
{
struct RankResult
{
  Solution solution;
  std::string error;
  bool cancelled = false;
};

/// Solves on `ranks` threads as ranks; `progress(rank)` gives each rank's callback.
std::vector<RankResult> solveOnRanks(const Scene& scene, const LightRig& rig,
  const SolverOptions& options, int ranks,
  const std::function<ProgressCallback(int rank)>& progress = {})
{
  ThreadRanks group(ranks);
  std::vector<RankResult> results(static_cast<std::size_t>(ranks));
  std::vector<std::thread> threads;
  for (int r = 0; r < ranks; ++r)
  {
    threads.emplace_back(
      [&, r]
      {
        RankResult& result = results[static_cast<std::size_t>(r)];
        try
        {
          result.solution = solve(
            scene, rig, group.optionsFor(r, options), progress ? progress(r) : ProgressCallback());
        }
        catch (const Cancelled& e)
        {
          result.cancelled = true;
          result.error = e.what();
        }
        catch (const std::exception& e)
        {
          result.error = e.what();
        }
      });
  }
  for (std::thread& t : threads)
  {
    t.join();
  }
  return results;
}

Scene boxScene()
{
  return Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(0.6, 0.5, 0.4) }));
}

/// Two lights: a moving one and a static one (two sources, two random streams).
LightRig twoLights()
{
  LightRig rig;
  rig.areaLights.emplace_back(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.7, 0.9 }, 5));
  rig.areaLights.emplace_back(scenes::squareLightFacingDown({ 0.2, 0.7, 0.95 }, 0.1), Rgb(2, 2, 2),
    scenes::translationsAlong({ 0.2, 0.7, 0.95 }, { 0.2, 0.7, 0.95 }, { 0.2, 0.7, 0.95 }, 1));
  return rig;
}
}

class Ranks : public ::testing::TestWithParam<std::tuple<bool, bool, double>>
{
};

TEST_P(Ranks, EveryRankHoldsTheSerialSolutionBitForBit)
{
  const auto [shooting, gathering, k] = GetParam();
  const Scene scene = boxScene();
  const LightRig rig = twoLights();
  SolverOptions options;
  options.pathsPerFrame = 20000;
  options.seed = 7;
  options.reuseShooting = shooting;
  options.reuseGathering = gathering;
  options.gatheringRatio = k;
  options.threads = 1;
  Solution serial = solve(scene, rig, options);
  for (const auto& [ranks, threads] : { std::pair{ 2, 1 }, std::pair{ 3, 2 }, std::pair{ 5, 1 } })
  {
    options.threads = threads;
    std::vector<RankResult> results = solveOnRanks(scene, rig, options, ranks);
    for (int r = 0; r < ranks; ++r)
    {
      RankResult result = results[static_cast<std::size_t>(r)];
      SCOPED_TRACE("rank " + std::to_string(r) + " of " + std::to_string(ranks) + ", " +
        std::to_string(threads) + " threads");
      ASSERT_TRUE(result.error.empty()) << result.error;
      Solution& s = result.solution;
      EXPECT_TRUE(checks::sameBits(serial.directData(), s.directData()));
      EXPECT_TRUE(checks::sameBits(serial.indirectData(), s.indirectData()));
      EXPECT_TRUE(checks::sameBits(serial.patchData(), s.patchData()));
      EXPECT_EQ(serial.litSideData(), s.litSideData());
      EXPECT_EQ(serial.patchLitSideData(), s.patchLitSideData());
      EXPECT_EQ(serial.statistics.shootingRays, s.statistics.shootingRays);
      EXPECT_EQ(serial.statistics.shadowRays, s.statistics.shadowRays);
      EXPECT_EQ(serial.statistics.gatheringRays, s.statistics.gatheringRays);
      EXPECT_EQ(serial.statistics.missedRays, s.statistics.missedRays);
      EXPECT_EQ(serial.statistics.pathsCast, s.statistics.pathsCast);
      EXPECT_EQ(serial.warnings, s.warnings);
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Modes, Ranks,
  ::testing::Values(std::make_tuple(true, true, 1.0), std::make_tuple(false, false, 1.0),
    std::make_tuple(true, false, 0.5), std::make_tuple(true, true, 0.0)));

TEST(RanksWithErrorEstimate, BatchesAndRoundsGiveEveryRankTheSerialBits)
{
  // Every batch is summed over the ranks, and the rounds are decided from those bits: the
  // same batches, the same mean and the same standard errors on every rank.
  const Scene scene = boxScene();
  const LightRig rig = twoLights();
  SolverOptions options;
  options.pathsPerFrame = 16000;
  options.seed = 3;
  options.errorBatches = 8;
  options.targetRelativeError = 0.08;
  options.threads = 1;
  Solution serial = solve(scene, rig, options);
  ASSERT_GT(serial.errorEstimate.rounds, 1u);
  for (const auto& [ranks, threads] : { std::pair{ 2, 1 }, std::pair{ 3, 2 } })
  {
    options.threads = threads;
    std::vector<RankResult> results = solveOnRanks(scene, rig, options, ranks);
    for (int r = 0; r < ranks; ++r)
    {
      SCOPED_TRACE("rank " + std::to_string(r) + " of " + std::to_string(ranks));
      const RankResult& result = results[static_cast<std::size_t>(r)];
      ASSERT_TRUE(result.error.empty()) << result.error;
      Solution s = result.solution;
      EXPECT_EQ(serial.errorEstimate.batches, s.errorEstimate.batches);
      EXPECT_TRUE(checks::sameBits(serial.directData(), s.directData()));
      EXPECT_TRUE(checks::sameBits(serial.indirectData(), s.indirectData()));
      EXPECT_TRUE(checks::sameBits(serial.stdErrorData(), s.stdErrorData()));
      EXPECT_EQ(serial.errorEstimate.relativeErrorP95, s.errorEstimate.relativeErrorP95);
    }
  }
}

TEST(RankFailures, ACancelOnOneRankStopsEveryRank)
{
  const Scene scene = boxScene();
  SolverOptions options;
  options.pathsPerFrame = 200000;
  options.threads = 1;
  // Rank 1 cancels a quarter of the way; the others never would.
  const std::vector<RankResult> results = solveOnRanks(scene, twoLights(), options, 3,
    [](int rank) -> ProgressCallback
    { return [rank](double fraction) { return rank != 1 || fraction < 0.25; }; });
  for (const RankResult& result : results)
  {
    EXPECT_TRUE(result.cancelled) << result.error;
  }
}

TEST(RankFailures, AFailureOnOneRankIsReportedOnEveryRank)
{
  const Scene scene = boxScene();
  SolverOptions options;
  options.pathsPerFrame = 20000;
  options.threads = 1;
  ThreadRanks group(2);
  std::vector<RankResult> results(2);
  std::vector<std::thread> threads;
  for (int r = 0; r < 2; ++r)
  {
    threads.emplace_back(
      [&, r]
      {
        SolverOptions mine = group.optionsFor(r, options);
        // Rank 1 alone has a memory limit the solve does not fit in.
        mine.memoryLimitBytes = r == 1 ? 1024 : 0;
        try
        {
          results[static_cast<std::size_t>(r)].solution = solve(scene, twoLights(), mine);
        }
        catch (const FailedOnAnotherRank& e)
        {
          results[static_cast<std::size_t>(r)].error = std::string("elsewhere: ") + e.what();
        }
        catch (const Error& e)
        {
          results[static_cast<std::size_t>(r)].error = e.what();
        }
      });
  }
  for (std::thread& t : threads)
  {
    t.join();
  }
  EXPECT_NE(results[1].error.find("memory limit"), std::string::npos) << results[1].error;
  EXPECT_NE(
    results[0].error.find("elsewhere: the solve failed on 1 other rank of 2"), std::string::npos)
    << results[0].error;
}

TEST(RankFailures, MissingSumsAreAnError)
{
  SolverOptions options;
  options.ranks = 2;
  EXPECT_THROW(validateOptions(options), Error);
  options.ranks = 1;
  options.rank = 1;
  EXPECT_THROW(validateOptions(options), Error);
}
