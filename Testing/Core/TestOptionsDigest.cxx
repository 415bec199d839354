// The digest ranks compare before solving together: every option that changes the result is
// in it, the ones that may differ per rank are not; and the agreement that decodes it.
#include "Ranks.h"

#include <gtest/gtest.h>

#include <set>
#include <string>

using namespace mlr;

namespace
{
/// `options` with the field named `name` changed to another valid value.
SolverOptions changed(SolverOptions options, const std::string& name)
{
  if (name == "pathsPerFrame")
    options.pathsPerFrame += 1;
  else if (name == "gatheringRatio")
    options.gatheringRatio *= 2;
  else if (name == "firstBounceSurvival")
    options.firstBounceSurvival = 0.5;
  else if (name == "reuseShooting")
    options.reuseShooting = !options.reuseShooting;
  else if (name == "balanceFrames")
    options.balanceFrames = !options.balanceFrames;
  else if (name == "reuseGathering")
    options.reuseGathering = !options.reuseGathering;
  else if (name == "twoSided")
    options.twoSided = !options.twoSided;
  else if (name == "seed")
    options.seed += 1;
  else if (name == "threads")
    options.threads = 3;
  else if (name == "memoryLimitBytes")
    options.memoryLimitBytes = 1 << 30;
  else if (name == "errorBatches")
    options.errorBatches = 16;
  else if (name == "targetRelativeError")
    options.targetRelativeError = 0.02;
  else if (name == "framesPerChunk")
    options.framesPerChunk = 8;
  else if (name == "chunkOverlap")
    options.chunkOverlap = 4;
  else if (name == "timeLimitSeconds")
    options.timeLimitSeconds = 60;
  else if (name == "batchLimit")
    options.batchLimit = 12;
  else if (name == "storageScale")
    options.storageScale = 0.25;
  else if (name == "log")
    options.log = [](const std::string&) {};
  else if (name == "batchSolved")
    options.batchSolved = [](std::uint64_t, std::size_t, const Solution&) {};
  else if (name == "rank")
    options.rank = 1;
  else if (name == "firstFrame")
    options.firstFrame = 8;
  else if (name == "ranks")
    options.ranks = 2;
  else if (name == "sumAcrossRanks")
    options.sumAcrossRanks = [](std::int64_t*, std::size_t) {};
  else if (name == "sumDoublesAcrossRanks")
    options.sumDoublesAcrossRanks = [](double*, std::size_t) {};
  else
    ADD_FAILURE() << "no change for option " << name << ": add it to this test";
  return options;
}

std::vector<std::pair<std::string, OptionRole>> fields()
{
  std::vector<std::pair<std::string, OptionRole>> all;
  visitSolverOptions(SolverOptions(),
    [&](const char* name, const auto&, OptionRole role) { all.emplace_back(name, role); });
  return all;
}
}

TEST(OptionsDigest, EveryFieldIsVisitedOnce)
{
  std::set<std::string> names;
  for (const auto& [name, role] : fields())
  {
    EXPECT_TRUE(names.insert(name).second) << name << " visited twice";
  }
  EXPECT_EQ(names.size(), 24u);
}

TEST(OptionsDigest, EveryOptionThatDecidesTheResultChangesTheDigest)
{
  const SolverOptions base;
  const std::uint64_t reference = digestOf(base);
  EXPECT_EQ(reference, digestOf(SolverOptions()));
  std::set<std::uint64_t> digests{ reference };
  for (const auto& [name, role] : fields())
  {
    const std::uint64_t digest = digestOf(changed(base, name));
    if (role == OptionRole::Result)
    {
      EXPECT_NE(digest, reference) << name << " changes the solve but not the digest";
      EXPECT_TRUE(digests.insert(digest).second) << name << " collides with another option";
    }
    else
    {
      EXPECT_EQ(digest, reference) << name << " may differ per rank but changes the digest";
    }
  }
}

TEST(OptionsDigest, RankOutcomeFindsDifferentDigestsAndFailures)
{
  auto agreed = [](std::vector<std::tuple<bool, bool, std::uint64_t>> ranks)
  {
    long long maxima[RankOutcome::Size];
    for (std::size_t r = 0; r < ranks.size(); ++r)
    {
      long long mine[RankOutcome::Size];
      RankOutcome::encode(
        std::get<0>(ranks[r]), std::get<1>(ranks[r]), std::get<2>(ranks[r]), mine);
      for (std::size_t i = 0; i < RankOutcome::Size; ++i)
      {
        maxima[i] = r == 0 ? mine[i] : std::max(maxima[i], mine[i]);
      }
    }
    return RankOutcome::decode(maxima);
  };
  const std::uint64_t a = digestOf(SolverOptions());
  const std::uint64_t b = digestOf(changed(SolverOptions(), "seed"));
  RankOutcome same = agreed({ { false, false, a }, { false, false, a }, { false, false, a } });
  EXPECT_FALSE(same.failed || same.cancelled || same.digestsDiffer);
  // Differences in the low half only, the high half only, and in both are all found.
  EXPECT_TRUE(agreed({ { false, false, a }, { false, false, a ^ 1 } }).digestsDiffer);
  EXPECT_TRUE(agreed({ { false, false, a }, { false, false, a ^ (1ULL << 63) } }).digestsDiffer);
  EXPECT_TRUE(
    agreed({ { false, false, a }, { false, false, a }, { false, false, b } }).digestsDiffer);
  const RankOutcome failed = agreed({ { false, false, a }, { true, false, a } });
  EXPECT_TRUE(failed.failed);
  EXPECT_FALSE(failed.cancelled);
  EXPECT_TRUE(agreed({ { false, true, a }, { false, false, a } }).cancelled);
}
