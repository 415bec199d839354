// The memory plan's count of the result pages a solve writes (writtenResultBytes), against
// arithmetic and against the pages the kernel holds for the same writes.
#include "MemoryPlan.h"
#include "Rgb.h"
#include "Solution.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#ifdef __linux__
#include <sys/mman.h>
#include <unistd.h>
#endif

using namespace mlr;

namespace
{
constexpr std::size_t Patches = 1000;
constexpr std::size_t Frames = 100;
// One patch side's elements: 4 x 100 frames x 6 bytes.
constexpr std::uint64_t RunBytes = Scene::ElementsPerPatch * Frames * sizeof(PackedRgb);
constexpr std::uint64_t Whole = 2 * Patches * RunBytes;

std::vector<std::uint8_t> flags(bool (*reachable)(std::size_t patch, int side))
{
  std::vector<std::uint8_t> f(2 * Patches);
  for (std::size_t p = 0; p < Patches; ++p)
  {
    for (int s = 0; s < 2; ++s)
    {
      f[2 * p + static_cast<std::size_t>(s)] = reachable(p, s) ? 1 : 0;
    }
  }
  return f;
}

std::uint64_t written(const std::vector<std::uint8_t>& reachable)
{
  return writtenResultBytes(Patches, Scene::ElementsPerPatch, Frames, &reachable);
}
}

TEST(MemoryPlan, WrittenResultsAreTheHugePagesOfTheReachableRuns)
{
  ASSERT_EQ(RunBytes, 2400u);
  EXPECT_EQ(writtenResultBytes(Patches, Scene::ElementsPerPatch, Frames, nullptr), Whole);
  EXPECT_EQ(written(flags([](std::size_t, int) { return true; })), Whole);
  EXPECT_EQ(written(flags([](std::size_t, int) { return false; })), 0u);
  // The front sides are the first 2.4 MB: two huge pages.
  EXPECT_EQ(written(flags([](std::size_t, int s) { return s == 0; })), 2 * HugePageBytes);
  // The back sides run from 2.4 to 4.8 MB: pages 1 and 2.
  EXPECT_EQ(written(flags([](std::size_t, int s) { return s == 1; })), 2 * HugePageBytes);
  // One run, and one run that straddles two pages (patch 873's front side ends at 2,097,600).
  EXPECT_EQ(written(flags([](std::size_t p, int s) { return p == 10 && s == 0; })), HugePageBytes);
  EXPECT_EQ(
    written(flags([](std::size_t p, int s) { return p == 873 && s == 0; })), 2 * HugePageBytes);
  // Every other patch's front side: each page holds 873 runs, so every page but the back's
  // is touched.
  EXPECT_EQ(
    written(flags([](std::size_t p, int s) { return p % 2 == 0 && s == 0; })), 2 * HugePageBytes);
  // The patches (one record a patch): all front sides are 600,000 bytes in the first page,
  // which the array of 1.2 MB does not fill.
  const std::vector<std::uint8_t> front = flags([](std::size_t, int s) { return s == 0; });
  EXPECT_EQ(writtenResultBytes(Patches, 1, Frames, &front), 2 * Patches * Frames * 6);
}

#ifdef __linux__
TEST(MemoryPlan, TheKernelHoldsNoMoreThanTheWrittenPagesCounted)
{
  // Where the kernel grants huge pages the counts are equal; where it does not, it holds
  // 4 KiB pages, fewer: the count bounds what is resident either way.
  for (const auto reachable : { flags([](std::size_t, int s) { return s == 0; }),
         flags([](std::size_t p, int s) { return p % 7 == 0 && s == 1; }),
         flags([](std::size_t p, int) { return p > 900; }) })
  {
    Solution solution(Frames, Patches * Scene::ElementsPerPatch, Patches);
    StoredArray& direct = solution.directData();
    for (std::size_t e = 0; e < Patches * Scene::ElementsPerPatch; ++e)
    {
      for (int s = 0; s < 2; ++s)
      {
        if (reachable[2 * Scene::patchOfElement(e) + static_cast<std::size_t>(s)])
        {
          for (std::size_t f = 0; f < Frames; ++f)
          {
            direct[solution.elementIndex(f, e, static_cast<Side>(s))] = PackedRgb(Rgb(1));
          }
        }
      }
    }
    const std::size_t page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    const auto begin = reinterpret_cast<std::uintptr_t>(direct.data()) / page * page;
    const auto end = reinterpret_cast<std::uintptr_t>(direct.data() + direct.size());
    std::vector<unsigned char> in((end - begin + page - 1) / page);
    ASSERT_EQ(mincore(reinterpret_cast<void*>(begin), end - begin, in.data()), 0);
    std::uint64_t resident = 0;
    for (unsigned char c : in)
    {
      resident += (c & 1) ? page : 0;
    }
    EXPECT_GT(resident, 0u);
    EXPECT_LE(resident, written(reachable));
  }
}
#endif

TEST(MemoryPlan, GatheringTakesWhatTheLimitLeaves)
{
  // The large benchmark scene, 120 frames, one worker: gathering's phase is the peak. Under a
  // limit that leaves less than the default 192 MiB of rows and hits beside the results,
  // gathering holds fewer frames of rows at a time, so that the solve fits the limit.
  const std::size_t patches = 105420, elements = 4 * patches, points = 220000, frames = 120;
  SolverOptions options;
  options.pathsPerFrame = 4000000;
  options.threads = 1;
  options.memoryLimitBytes = std::uint64_t(1) << 40;
  const MemoryPlan roomy = planSolveMemory(patches, elements, points, frames, options);
  EXPECT_EQ(roomy.gathering.rowBytes, GatheringBudget().rowBytes);
  EXPECT_EQ(roomy.gathering.hitBytes, GatheringBudget().hitBytes);

  options.memoryLimitBytes = roomy.peak - (std::uint64_t(96) << 20);
  const MemoryPlan tight = planSolveMemory(patches, elements, points, frames, options);
  EXPECT_LE(tight.peak, options.memoryLimitBytes);
  EXPECT_LT(tight.gathering.rowBytes, roomy.gathering.rowBytes);
  EXPECT_LT(tight.gathering.hitBytes, roomy.gathering.hitBytes);
  EXPECT_GE(tight.gathering.rowBytes, 2 * elements * sizeof(PackedRgb)) << "a frame of rows";
  EXPECT_EQ(tight.results, roomy.results);

  // A limit below the results themselves is not met by shrinking: the plan says so.
  options.memoryLimitBytes = roomy.results / 2;
  EXPECT_GT(
    planSolveMemory(patches, elements, points, frames, options).peak, options.memoryLimitBytes);
}
