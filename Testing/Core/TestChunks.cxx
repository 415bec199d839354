// Animations solved in chunks: the plan and its blend weights, bits independent of the thread
// count, one chunk as the plain solve, streaming as assembling, an unbiased seam, and a memory
// limit that leaves room for 2 frames per chunk, and ranks that take whole chunks.
#include "Animation.h"
#include "Chunks.h"
#include "CoreChecks.h"
#include "ErrorEstimate.h"
#include "GeneratedScenes.h"
#include "MemoryPlan.h"
#include "ThreadRanks.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <map>
#include <thread>
#include <vector>

using namespace mlr;

namespace
{
constexpr std::size_t Frames = 12;

Scene box()
{
  return Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(0.6, 0.5, 0.4) }));
}

LightRig rig(std::size_t frames = Frames)
{
  LightRig r;
  r.areaLights.emplace_back(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.2, 0.2, 0.9 }, { 0.8, 0.8, 0.9 }, frames));
  return r;
}

SolverOptions options(std::uint64_t paths, std::uint64_t seed, int threads = 2)
{
  SolverOptions o;
  o.pathsPerFrame = paths;
  o.seed = seed;
  o.threads = threads;
  return o;
}

/// The mean of the total radiosity (lit side, sum over channels) over the elements, by area.
double frameMean(const Scene& scene, const Solution& s, std::size_t frame)
{
  double sum = 0, area = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    sum += scene.elementArea(e) * s.total(frame, e, s.litSide(e)).sum();
    area += scene.elementArea(e);
  }
  return sum / area;
}
}

TEST(Chunks, PlanCoversEveryFrameWithWeightsSummingToOne)
{
  for (const std::size_t c : { 2, 3, 4, 8, 16, 17 })
  {
    const ChunkPlan plan = planChunks(100, c);
    EXPECT_EQ(plan.overlap, std::max<std::size_t>(1, c / 8));
    EXPECT_EQ(plan.chunks.front().begin, 0u);
    EXPECT_EQ(plan.chunks.back().end, 100u);
    for (std::size_t k = 0; k < plan.chunks.size(); ++k)
    {
      const ChunkPlan::Chunk& chunk = plan.chunks[k];
      if (k > 0)
      {
        EXPECT_EQ(chunk.begin, plan.chunks[k - 1].end);
        EXPECT_EQ(plan.finishedBegin(k), plan.finishedEnd(k - 1));
      }
      EXPECT_EQ(chunk.solveBegin, k == 0 ? 0 : chunk.begin - plan.overlap);
      EXPECT_LE(chunk.solveEnd, std::min<std::size_t>(100, chunk.end + plan.overlap));
    }
    for (std::size_t f = 0; f < 100; ++f)
    {
      double sum = 0;
      int solvedBy = 0;
      for (std::size_t k = 0; k < plan.chunks.size(); ++k)
      {
        const double w = plan.weight(k, f);
        EXPECT_GE(w, 0.0);
        sum += w;
        solvedBy += w > 0;
      }
      EXPECT_NEAR(sum, 1.0, 1e-12) << "frame " << f << ", " << c << " frames per chunk";
      EXPECT_LE(solvedBy, 2);
    }
  }
  EXPECT_EQ(planChunks(30, 0).chunks.size(), 1u);
  EXPECT_EQ(planChunks(30, 30).chunks.size(), 1u);
  EXPECT_EQ(planChunks(30, 100).chunks.size(), 1u);
  EXPECT_EQ(planChunks(1, 1).chunks.size(), 1u); // a static scene: one frame, one chunk
  checks::expectError([] { planChunks(30, 1); }, "the chunk length is 1: give 0");
  SolverOptions o;
  o.framesPerChunk = 1;
  checks::expectError([&] { validateOptions(o); },
    "the option framesPerChunk is 1: give 0 (the memory limit chooses) or at least 2");
}

TEST(Chunks, SlicedRigKeepsThePosesOfItsFrames)
{
  LightRig r = rig();
  r.directionalLights.emplace_back(std::vector<Vec3>(Frames, Vec3(0, 0, 1)), Rgb(1));
  r.areaLights.emplace_back(
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.95 }, 0.1), Rgb(1), std::vector<Vec3>{ Vec3() });
  const LightRig s = sliceRig(r, 3, 5);
  EXPECT_EQ(frameCount(s, false), 5u);
  EXPECT_EQ(s.areaLights[0].pose(0).position.x, r.areaLights[0].pose(3).position.x);
  EXPECT_EQ(s.areaLights[0].pose(4).position.x, r.areaLights[0].pose(7).position.x);
  EXPECT_EQ(s.areaLights[1].frameCount(), 1u); // static lights stay static
  EXPECT_EQ(s.directionalLights[0].frameCount(), 5u);
}

TEST(Chunks, OneChunkIsThePlainSolveBitForBit)
{
  const Scene scene = box();
  SolverOptions o = options(20000, 7);
  o.errorBatches = 4;
  Solution plain = solve(scene, rig(), o);
  for (const std::size_t c : { 0, 12, 50 })
  {
    Solution chunked = solveInChunks(scene, rig(), o, c);
    EXPECT_EQ(chunked.statistics.chunks, 1u);
    EXPECT_TRUE(checks::sameBits(plain.directData(), chunked.directData()));
    EXPECT_TRUE(checks::sameBits(plain.indirectData(), chunked.indirectData()));
    EXPECT_TRUE(checks::sameBits(plain.patchData(), chunked.patchData()));
    EXPECT_TRUE(checks::sameBits(plain.stdErrorData(), chunked.stdErrorData()));
  }
}

TEST(Chunks, ThreadCountDoesNotChangeABit)
{
  const Scene scene = box();
  SolverOptions o = options(20000, 42, 1);
  o.errorBatches = 3;
  Solution one = solveInChunks(scene, rig(), o, 4);
  o.threads = 2;
  Solution two = solveInChunks(scene, rig(), o, 4);
  o.threads = 3;
  Solution three = solveInChunks(scene, rig(), o, 4);
  EXPECT_EQ(one.statistics.chunks, 3u);
  EXPECT_EQ(one.frameCount(), Frames);
  for (Solution* s : { &two, &three })
  {
    EXPECT_TRUE(checks::sameBits(one.directData(), s->directData()));
    EXPECT_TRUE(checks::sameBits(one.indirectData(), s->indirectData()));
    EXPECT_TRUE(checks::sameBits(one.patchData(), s->patchData()));
    EXPECT_TRUE(checks::sameBits(one.stdErrorData(), s->stdErrorData()));
    EXPECT_EQ(one.statistics.shadowRays, s->statistics.shadowRays);
  }
  // Chunks differ from the plain solve: each reuses paths over its own positions only.
  Solution plain = solve(scene, rig(), o);
  EXPECT_FALSE(checks::sameBits(one.directData(), plain.directData()));
}

TEST(Chunks, ATimeLimitIsTheWholeSolvesAndItsMessagesNameTheAnimationsFrames)
{
  // A target out of reach: every chunk runs until its share of the limit is spent. The
  // shares are what is left over the chunks still to solve, so they add up to the limit at
  // most; the messages name the animation's frames, and one warning covers the 3 chunks.
  const Scene scene = box();
  SolverOptions o = options(4000, 3);
  o.errorBatches = 2;
  o.targetRelativeError = 1e-4;
  o.timeLimitSeconds = 0.3;
  std::vector<std::string> log;
  o.log = [&](const std::string& line) { log.push_back(line); };
  const Solution s = solveInChunks(scene, rig(), o, 4);
  ASSERT_EQ(s.statistics.chunks, 3u);
  EXPECT_EQ(s.errorEstimate.stoppedBy, "time limit");
  std::vector<double> shares;
  std::vector<std::size_t> roundFrames;
  for (const std::string& line : log)
  {
    const std::size_t within = line.find(", within ");
    if (line.rfind("chunk ", 0) == 0 && within != std::string::npos)
    {
      shares.push_back(std::stod(line.substr(within + 9)));
    }
    const std::size_t at = line.find("(frame ");
    if (line.rfind("error estimate, round 1", 0) == 0 && at != std::string::npos)
    {
      roundFrames.push_back(std::stoul(line.substr(at + 7)));
    }
  }
  ASSERT_EQ(shares.size(), 3u);
  EXPECT_LE(shares[0], 0.1);
  EXPECT_LE(shares[0] + shares[1] + shares[2], 0.3 + 3e-3);
  ASSERT_EQ(roundFrames.size(), 3u);
  // Chunk k solves the positions from 4k - 1 (its overlap) to 4k + 4.
  for (std::size_t k = 0; k < 3; ++k)
  {
    EXPECT_GE(roundFrames[k] + 1, 4 * k) << k;
    EXPECT_LT(roundFrames[k], 4 * k + 5) << k;
  }
  std::size_t notReached = 0;
  for (const std::string& w : s.warnings)
  {
    if (w.rfind(TargetNotReached, 0) == 0)
    {
      ++notReached;
      EXPECT_NE(
        w.find("was not reached in 3 of 3 chunks: the time limit stopped them"), std::string::npos)
        << w;
    }
  }
  EXPECT_EQ(notReached, 1u);
}

TEST(Chunks, StreamedChunksWarnWhenTheAnimationLitTheOtherSide)
{
  // A thin panel under the sun from above for 4 frames, then from below for 8: streamed, every
  // frame shows the first chunk's side (the top), where the whole animation lit the bottom
  // more. The run says so; a run whose first chunk chose as the animation does is silent.
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 4, 4, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  auto sun = [](std::size_t above)
  {
    std::vector<Vec3> towards;
    for (std::size_t f = 0; f < Frames; ++f)
    {
      towards.push_back(f < above ? Vec3(0.1, 0.2, 1) : Vec3(0.1, 0.2, -1));
    }
    LightRig r;
    r.directionalLights.emplace_back(towards, Rgb(100));
    return r;
  };
  const SolverOptions o = options(4000, 5);
  auto warned = [&](const LightRig& r)
  {
    const Solution s = solveInChunks(scene, r, o, 4, {}, [](std::size_t, Solution&) {});
    EXPECT_EQ(s.statistics.chunks, 3u);
    return std::count_if(s.warnings.begin(), s.warnings.end(),
      [](const std::string& w)
      {
        return w.find("show the side the first chunk lit more") != std::string::npos ||
          w.find("shows the side the first chunk lit more") != std::string::npos;
      });
  };
  EXPECT_EQ(warned(sun(4)), 1);
  EXPECT_EQ(warned(sun(8)), 0);
  // Assembled rather than streamed, the lit sides are chosen over the whole animation.
  const Solution whole = solveInChunks(scene, sun(4), o, 4);
  EXPECT_EQ(whole.litSide(0), Side::Back);
}

TEST(Chunks, TheSidesLightCanReachAreProbedOnceForEveryChunk)
{
  // The probes cost a fixed number of rays per patch side: per chunk, they would cost as
  // much as gathering on a fine mesh, chunk after chunk.
  const Scene scene = box();
  const SolverOptions o = options(20000, 42);
  const Solution plain = solve(scene, rig(), o);
  const Solution chunked = solveInChunks(scene, rig(), o, 4);
  EXPECT_EQ(chunked.statistics.chunks, 3u);
  EXPECT_GT(plain.statistics.reachabilityRays, 0u);
  EXPECT_EQ(chunked.statistics.reachabilityRays, plain.statistics.reachabilityRays);
  EXPECT_EQ(chunked.statistics.reachableSides, plain.statistics.reachableSides);
}

TEST(Chunks, StreamedFramesAreTheAssembledOnes)
{
  const Scene scene = box();
  SolverOptions o = options(20000, 3);
  o.errorBatches = 2;
  Solution whole = solveInChunks(scene, rig(), o, 5);
  std::size_t next = 0;
  const Solution stats = solveInChunks(scene, rig(), o, 5, {},
    [&](std::size_t first, Solution& frames)
    {
      EXPECT_EQ(first, next);
      next += frames.frameCount();
      for (std::size_t f = 0; f < frames.frameCount(); ++f)
      {
        for (std::size_t e = 0; e < scene.elementCount(); ++e)
        {
          for (const Side side : { Side::Front, Side::Back })
          {
            ASSERT_EQ(
              frames.irradiance(f, e, side).sum(), whole.irradiance(first + f, e, side).sum());
            ASSERT_EQ(frames.irradianceStdError(f, e, side).sum(),
              whole.irradianceStdError(first + f, e, side).sum());
          }
        }
        EXPECT_EQ(frames.errorEstimate.relativeErrorP95.size(), frames.frameCount());
      }
    });
  EXPECT_EQ(next, Frames);
  EXPECT_EQ(stats.frameCount(), 0u);
  EXPECT_EQ(stats.statistics.frames, Frames);
  EXPECT_EQ(stats.statistics.chunks, 3u);
  EXPECT_EQ(stats.statistics.shadowRays, whole.statistics.shadowRays);
}

class ChunkOverlaps : public ::testing::TestWithParam<std::uint64_t>
{
};

TEST_P(ChunkOverlaps, MeanOverSeedsAtASeamIsClassics)
{
  // 4 frames per chunk. m = 1 (the default, C/8 at least 1): frames 3 and 4 blend chunks 0
  // and 1; m = 2: frames 2 to 5 do. Over S seeds the mean of each mode's frame mean differs
  // from the other's by noise only: 4 standard errors of the difference, from the seeds' own
  // spread.
  const Scene scene = box();
  constexpr int Seeds = 12;
  constexpr std::uint64_t Paths = 8000;
  const std::vector<std::size_t> frames{ 1, 2, 3, 4, 5, 8 };
  std::vector<double> sumC(frames.size()), sqC(frames.size()), sumR(frames.size()),
    sqR(frames.size());
  for (int seed = 0; seed < Seeds; ++seed)
  {
    SolverOptions o = options(Paths, 100 + seed);
    o.chunkOverlap = GetParam();
    const Solution chunked = solveInChunks(scene, rig(), o, 4);
    ASSERT_EQ(chunked.statistics.chunkOverlap, std::max<std::uint64_t>(1, GetParam()));
    const Solution classic =
      solve(scene, rig(), checks::modeOptions(false, Paths, 500 + static_cast<unsigned>(seed)));
    for (std::size_t i = 0; i < frames.size(); ++i)
    {
      const double c = frameMean(scene, chunked, frames[i]);
      const double r = frameMean(scene, classic, frames[i]);
      sumC[i] += c;
      sqC[i] += c * c;
      sumR[i] += r;
      sqR[i] += r * r;
    }
  }
  for (std::size_t i = 0; i < frames.size(); ++i)
  {
    const double mc = sumC[i] / Seeds, mr = sumR[i] / Seeds;
    const double vc = (sqC[i] - Seeds * mc * mc) / (Seeds - 1);
    const double vr = (sqR[i] - Seeds * mr * mr) / (Seeds - 1);
    const double tolerance = 4 * std::sqrt((vc + vr) / Seeds);
    EXPECT_NEAR(mc, mr, tolerance) << "frame " << frames[i];
    EXPECT_GT(mc, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Chunks, ChunkOverlaps, ::testing::Values(0, 2));

TEST(Chunks, AnOverlapAskedForBlendsEachSeamOverItsFrames)
{
  // m = 15 in chunks of 30: each seam ramps over 30 frames in steps of 1/30, the blends of a
  // chunk's two seams meet without overlapping, and a larger m is cut to C / 2.
  const ChunkPlan plan = planChunks(100, 30, 15);
  EXPECT_EQ(plan.overlap, 15u);
  EXPECT_EQ(plan.chunks[1].solveBegin, 15u);
  EXPECT_EQ(plan.chunks[1].solveEnd, 75u);
  for (std::size_t f = 0; f < 100; ++f)
  {
    double sum = 0;
    int solvedBy = 0;
    for (std::size_t k = 0; k < plan.chunks.size(); ++k)
    {
      sum += plan.weight(k, f);
      solvedBy += plan.weight(k, f) > 0;
    }
    EXPECT_NEAR(sum, 1.0, 1e-12) << "frame " << f;
    EXPECT_LE(solvedBy, 2);
  }
  for (std::size_t f = 15; f + 1 < 45; ++f)
  {
    EXPECT_NEAR(plan.weight(1, f + 1) - plan.weight(1, f), 1.0 / 30, 1e-12) << "frame " << f;
  }
  EXPECT_EQ(planChunks(100, 30, 20).overlap, 15u);
  EXPECT_EQ(planChunks(100, 30, 0).overlap, 3u);
  EXPECT_EQ(planChunks(100, 30, 1).overlap, 1u);

  // The memory check counts the longer overlap's positions.
  {
    const Scene scene = box();
    SolverOptions wide;
    wide.chunkOverlap = 15;
    auto estimate = [&](const SolverOptions& o)
    {
      return estimateChunkedMemory(
        scene.patchCount(), scene.elementCount(), scene.points().size(), 300, 30, o, 1, 0, true);
    };
    EXPECT_GT(estimate(wide), estimate(SolverOptions()));
  }

  SolverOptions o;
  o.framesPerChunk = 30;
  o.chunkOverlap = 15;
  validateOptions(o);
  o.framesPerChunk = 3;
  o.chunkOverlap = 1;
  validateOptions(o);
  o.chunkOverlap = 2;
  checks::expectError([&] { validateOptions(o); },
    "the option chunkOverlap is 2, more than half of framesPerChunk (3): give 0 (an eighth of a "
    "chunk) or at most 1");
  o.chunkOverlap = 16;
  checks::expectError([&] { validateOptions(o); }, "chunkOverlap is 16, more than half");

  // A chunk length chosen elsewhere (options.framesPerChunk 0, as when the memory limit
  // chooses) cuts a larger m, with a warning; the same bits for any thread count.
  const Scene scene = box();
  SolverOptions cut = options(20000, 3, 1);
  cut.chunkOverlap = 3;
  Solution one = solveInChunks(scene, rig(), cut, 4);
  EXPECT_EQ(one.statistics.chunkOverlap, 2u);
  ASSERT_EQ(one.warnings.size(), 1u);
  EXPECT_NE(one.warnings[0].find("chunk overlap of 3 frames is more than half"), std::string::npos)
    << one.warnings[0];
  cut.threads = 3;
  Solution three = solveInChunks(scene, rig(), cut, 4);
  EXPECT_TRUE(checks::sameBits(one.directData(), three.directData()));
  EXPECT_TRUE(checks::sameBits(one.indirectData(), three.indirectData()));
  // The overlap changes the blended frames: m = 2 against m = 1.
  cut.chunkOverlap = 0;
  Solution narrow = solveInChunks(scene, rig(), cut, 4);
  EXPECT_EQ(narrow.statistics.chunkOverlap, 1u);
  EXPECT_TRUE(narrow.warnings.empty());
  EXPECT_FALSE(checks::sameBits(one.directData(), narrow.directData()));
}

TEST(Chunks, MemoryLimitForTwoFramesPerChunkGivesTheRightResult)
{
  // Enough elements and frames that the frames, not the scene's fixed buffers (the shooting
  // sums' 2 MiB pages above all), decide the memory; one worker, so that one copy of the sums
  // does on any machine.
  constexpr std::size_t Long = 40;
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(16, true, { Rgb(0.6, 0.5, 0.4) }));
  SolverOptions o = options(20000, 11, 1);
  const auto estimate = [&](std::size_t c)
  {
    return estimateChunkedMemory(
      scene.patchCount(), scene.elementCount(), scene.points().size(), Long, c, o, 1, 0, true);
  };
  ASSERT_LT(estimate(2), estimate(3));
  ASSERT_LT(estimate(3), estimate(Long));
  o.memoryLimitBytes = (estimate(2) + estimate(3)) / 2;
  const std::size_t c = chooseFramesPerChunk(
    scene.patchCount(), scene.elementCount(), scene.points().size(), Long, o, 1, 0, true);
  EXPECT_EQ(c, 2u);
  // The whole solve would not fit: the memory check refuses it.
  checks::expectError([&] { solve(scene, rig(Long), o); }, "memory");

  // Streamed in chunks of 2, every frame agrees with a plain solve of 8 times the paths: each
  // frame's mean radiosity within 5 standard errors, the relative standard error of a frame
  // mean being about 1/sqrt(N) (the box's walls all see the light).
  std::vector<double> means(Long);
  solveInChunks(scene, rig(Long), o, c, {},
    [&](std::size_t first, Solution& frames)
    {
      for (std::size_t f = 0; f < frames.frameCount(); ++f)
      {
        means[first + f] = frameMean(scene, frames, f);
      }
    });
  SolverOptions reference = options(160000, 12);
  const Solution ref = solve(scene, rig(Long), reference);
  for (std::size_t f = 0; f < Long; ++f)
  {
    const double r = frameMean(scene, ref, f);
    EXPECT_NEAR(means[f], r, 5 * r / std::sqrt(20000.0)) << "frame " << f;
  }
}

TEST(Chunks, RanksThatKeepTheirFramesAreEstimatedTheirShare)
{
  // 40 frames in chunks of 10 (4 chunks, m = 1): a caller that keeps what is streamed to it
  // holds the frames of every R-th chunk over R ranks, all of them when there are fewer chunks
  // than ranks, or as many chunks as its cache takes. The estimate's difference from a streamed one
  // is those frames, less the one chunk a streamed solve holds.
  constexpr std::size_t Long = 40, C = 10;
  const Scene scene = box();
  SolverOptions o = options(20000, 11);
  const auto estimate = [&](int ranks, bool streamed, std::size_t kept)
  {
    o.ranks = ranks;
    return estimateChunkedMemory(scene.patchCount(), scene.elementCount(), scene.points().size(),
      Long, C, o, 1, 0, streamed, kept);
  };
  constexpr std::size_t all = std::numeric_limits<std::size_t>::max();
  const std::uint64_t streamed = estimate(1, true, 0);
  const std::uint64_t perFrame = (estimate(1, false, 0) - streamed) / (Long - C);
  ASSERT_GT(perFrame, 0u);
  EXPECT_EQ(estimate(1, true, all), estimate(1, false, 0));
  EXPECT_EQ(estimate(2, true, all), streamed + perFrame * (2 * C - C));
  EXPECT_EQ(estimate(3, true, all), streamed + perFrame * (2 * C - C));
  EXPECT_EQ(estimate(4, true, all), streamed + perFrame * (C - C));
  EXPECT_EQ(estimate(5, true, all), estimate(1, false, 0)); // fewer chunks than ranks
  // A cache of 3 chunks on one rank.
  EXPECT_EQ(estimate(1, true, 3), streamed + perFrame * (3 * C - C));
}

TEST(Chunks, SolveAnimationChoosesChunksAndStreams)
{
  // Through the one entry point: a set C is used, the frames stream, the statistics say so.
  PolygonSoup soup = scenes::boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) }, true);
  AnimationOptions options;
  options.solver.pathsPerFrame = 10000;
  options.solver.threads = 2;
  options.solver.framesPerChunk = 4;
  options.remeshing.targetEdgeLength = 0.25;
  std::size_t streamed = 0;
  options.chunkFrames = [&](const Animation& animation, std::size_t first, Solution& frames)
  {
    EXPECT_EQ(animation.scene.elementCount(), frames.elementCount());
    EXPECT_EQ(first, streamed);
    streamed += frames.frameCount();
  };
  const Animation a = solveAnimation(soup, rig(), options);
  EXPECT_EQ(streamed, Frames);
  EXPECT_EQ(a.solution.statistics.chunks, 3u);
  EXPECT_EQ(a.solution.statistics.framesPerChunk, 4u);
  options.sensors.points.push_back(Vec3(0.5, 0.5, 0.01));
  options.sensors.normals.push_back(Vec3(0, 0, 1));
  checks::expectError([&] { solveAnimation(soup, rig(), options); }, "sensors");
}

namespace
{
/// The bits of every streamed frame: direct, indirect and standard error of each element side,
/// then each patch side, as the stored codes.
using FrameBits = std::map<std::size_t, std::vector<std::uint16_t>>;

void recordFrames(std::size_t first, Solution& s, FrameBits& out)
{
  for (std::size_t f = 0; f < s.frameCount(); ++f)
  {
    std::vector<std::uint16_t>& bits = out[first + f];
    auto add = [&](const PackedRgb& c) { bits.insert(bits.end(), { c.r, c.g, c.b }); };
    for (std::size_t e = 0; e < s.elementCount(); ++e)
    {
      for (const Side side : { Side::Front, Side::Back })
      {
        const std::size_t i = s.elementIndex(f, e, side);
        add(s.directData()[i]);
        add(s.indirectData()[i]);
        add(s.stdErrorData()[i]);
      }
    }
    for (std::size_t p = 0; p < s.patchCount(); ++p)
    {
      for (const Side side : { Side::Front, Side::Back })
      {
        add(s.patchData()[s.patchIndex(f, p, side)]);
      }
    }
  }
}
}

TEST(Chunks, RanksTakeWholeChunksAndHandOnTheSerialBits)
{
  // 12 frames in chunks of 3 (m = 1): 4 chunks, so 3 ranks leave one idle in the second round.
  const Scene scene = box();
  SolverOptions o = options(20000, 11, 1);
  o.errorBatches = 2;
  constexpr std::size_t perChunk = 3;
  const ChunkPlan plan = planChunks(Frames, perChunk);
  ASSERT_EQ(plan.chunks.size(), 4u);
  FrameBits serial;
  std::vector<Side> serialSides;
  // A figure of the first chunk's frames (the filter's display exposure): on every rank, the
  // same, and there before the rank's first frames.
  auto figureOf = [](const Solution& frames)
  {
    double sum = 0;
    for (std::size_t e = 0; e < frames.elementCount(); ++e)
    {
      sum += frames.total(0, e, Side::Front).sum();
    }
    return sum;
  };
  double serialFigure = -1;
  const Solution serialStats = solveInChunks(scene, rig(), o, perChunk, {},
    [&](std::size_t first, Solution& frames)
    {
      recordFrames(first, frames, serial);
      serialSides = frames.litSideData();
    },
    { figureOf, [&](double v) { serialFigure = v; } });
  ASSERT_EQ(serial.size(), Frames);
  ASSERT_GT(serialFigure, 0);

  for (const int ranks : { 1, 2, 3 })
  {
    for (const int threads : { 1, 2 })
    {
      checks::ThreadRanks group(ranks);
      std::vector<FrameBits> got(static_cast<std::size_t>(ranks));
      std::vector<std::vector<std::size_t>> firsts(static_cast<std::size_t>(ranks));
      std::vector<Solution> stats(static_cast<std::size_t>(ranks));
      std::vector<std::string> errors(static_cast<std::size_t>(ranks));
      std::vector<std::vector<Side>> sides(static_cast<std::size_t>(ranks));
      std::vector<double> figures(static_cast<std::size_t>(ranks), -1);
      std::vector<int> figuresLate(static_cast<std::size_t>(ranks), 0);
      std::vector<std::thread> workers;
      for (int r = 0; r < ranks; ++r)
      {
        workers.emplace_back(
          [&, r]
          {
            const auto i = static_cast<std::size_t>(r);
            SolverOptions mine = group.optionsFor(r, o);
            mine.threads = threads;
            try
            {
              stats[i] = solveInChunks(scene, rig(), mine, perChunk, {},
                [&](std::size_t first, Solution& frames)
                {
                  figuresLate[i] += figures[i] < 0 ? 1 : 0;
                  firsts[i].push_back(first);
                  recordFrames(first, frames, got[i]);
                  sides[i] = frames.litSideData();
                },
                { figureOf, [&](double v) { figures[i] = v; } });
            }
            catch (const std::exception& e)
            {
              errors[i] = e.what();
            }
          });
      }
      for (std::thread& t : workers)
      {
        t.join();
      }
      std::size_t handedOn = 0;
      for (std::size_t r = 0; r < static_cast<std::size_t>(ranks); ++r)
      {
        SCOPED_TRACE("rank " + std::to_string(r) + " of " + std::to_string(ranks) + ", " +
          std::to_string(threads) + " threads");
        ASSERT_EQ(errors[r], "");
        // Rank r hands on the frames of chunks r, r + R, ... and no others.
        std::vector<std::size_t> expected;
        for (std::size_t k = r; k < plan.chunks.size(); k += static_cast<std::size_t>(ranks))
        {
          expected.push_back(plan.finishedBegin(k));
        }
        EXPECT_EQ(firsts[r], expected);
        for (const auto& [frame, bits] : got[r])
        {
          EXPECT_EQ(bits, serial.at(frame)) << "frame " << frame;
        }
        handedOn += got[r].size();
        EXPECT_EQ(sides[r], serialSides);
        EXPECT_EQ(figures[r], serialFigure);
        EXPECT_EQ(figuresLate[r], 0) << "frames before the first chunk's figure";
        // The figures of every chunk reach every rank.
        EXPECT_EQ(stats[r].statistics.shadowRays, serialStats.statistics.shadowRays);
        EXPECT_EQ(stats[r].statistics.pathsCast, serialStats.statistics.pathsCast);
        EXPECT_EQ(stats[r].statistics.gatheringRays, serialStats.statistics.gatheringRays);
        EXPECT_EQ(stats[r].statistics.chunks, 4u);
        EXPECT_EQ(stats[r].errorEstimate.batches, serialStats.errorEstimate.batches);
        EXPECT_EQ(stats[r].errorEstimate.stoppedBy, serialStats.errorEstimate.stoppedBy);
      }
      EXPECT_EQ(handedOn, Frames);
    }
  }
}

TEST(Chunks, AChunkSolvedAgainHasTheBitsOfTheWholeRun)
{
  // 12 frames in chunks of 3: each chunk's frames, solved again alone (on another thread
  // count), are the frames the whole run handed on, error figures included.
  const Scene scene = box();
  SolverOptions o = options(20000, 13, 2);
  o.errorBatches = 2;
  constexpr std::size_t perChunk = 3;
  FrameBits whole;
  std::vector<Side> sides, patchSides;
  std::vector<std::vector<double>> p95;
  solveInChunks(scene, rig(), o, perChunk, {},
    [&](std::size_t first, Solution& frames)
    {
      recordFrames(first, frames, whole);
      if (first == 0)
      {
        sides = frames.litSideData();
        patchSides = frames.patchLitSideData();
      }
      p95.push_back(frames.errorEstimate.relativeErrorP95);
    });
  const ChunkPlan plan = planChunks(Frames, perChunk);
  o.threads = 1;
  for (std::size_t k = 0; k < plan.chunks.size(); ++k)
  {
    Solution again = solveChunk(scene, rig(), o, perChunk, k, sides, patchSides);
    FrameBits bits;
    recordFrames(plan.finishedBegin(k), again, bits);
    ASSERT_EQ(again.frameCount(), plan.finishedEnd(k) - plan.finishedBegin(k)) << "chunk " << k;
    for (const auto& [frame, b] : bits)
    {
      EXPECT_EQ(b, whole.at(frame)) << "chunk " << k << ", frame " << frame;
    }
    EXPECT_EQ(again.errorEstimate.relativeErrorP95, p95[k]) << "chunk " << k;
  }
  checks::expectError([&] { solveChunk(scene, rig(), o, perChunk, 4, sides, patchSides); },
    "chunk 4 of an animation in 4 chunks");
}

TEST(Chunks, TheProgressWeighsTheWorkOfEveryElementAndFrame)
{
  // 21,600 elements, few paths, 60 frames in chunks of 20, 4 batches: the work per element
  // side and frame (the sums, the merges, the blends) outweighs the rays, and the setup's
  // probes take a few percent of the time (Documentation/Performance.md, "Progress"). The
  // progress weighed by rays alone was 0.93 when the first chunk started.
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(30, true, { Rgb(0.6, 0.5, 0.4) }));
  SolverOptions o = options(2000, 3, 2);
  o.errorBatches = 4;
  double last = 0, atFirstChunk = -1;
  bool monotone = true;
  o.log = [&](const std::string& message)
  {
    if (message.rfind("chunk 1 of", 0) == 0)
    {
      atFirstChunk = last;
    }
  };
  solveInChunks(scene, rig(60), o, 20,
    [&](double f)
    {
      monotone = monotone && f >= last;
      last = f;
      return true;
    });
  EXPECT_TRUE(monotone);
  EXPECT_DOUBLE_EQ(last, 1.0);
  EXPECT_GT(atFirstChunk, 0.0);
  EXPECT_LT(atFirstChunk, 0.3);

  // Without gathering (k = 0) the passes are all shooting: a solve's progress reaches its
  // end with them (on one thread, the last task's share from it), not at a jump after them
  // (at 0.86 here; 0.71 when the gathering that does not run was counted).
  o.gatheringRatio = 0;
  o.errorBatches = 1;
  o.threads = 1;
  std::vector<double> reported;
  solve(scene, rig(60), o,
    [&](double f)
    {
      reported.push_back(f);
      return true;
    });
  ASSERT_FALSE(reported.empty());
  std::sort(reported.begin(), reported.end());
  const auto belowOne = std::lower_bound(reported.begin(), reported.end(), 1.0);
  ASSERT_NE(belowOne, reported.begin());
  EXPECT_GT(*std::prev(belowOne), 0.8);
}

TEST(Chunks, AChunkSolvedAgainRepeatsTheBatchesItsFirstSolveRan)
{
  // A target's rounds differ between chunks; a chunk solved again under a time limit that
  // would now stop it after its first round still runs the batches of the first solve.
  const Scene scene = box();
  SolverOptions o = options(4000, 29, 2);
  o.errorBatches = 4;
  o.targetRelativeError = 0.3;
  constexpr std::size_t perChunk = 4;
  FrameBits whole;
  std::vector<Side> sides, patchSides;
  const Solution first = solveInChunks(scene, rig(), o, perChunk, {},
    [&](std::size_t firstFrame, Solution& frames)
    {
      recordFrames(firstFrame, frames, whole);
      if (firstFrame == 0)
      {
        sides = frames.litSideData();
        patchSides = frames.patchLitSideData();
      }
    });
  const std::vector<std::uint64_t>& batches = first.errorEstimate.chunkBatches;
  const ChunkPlan plan = planChunks(Frames, perChunk);
  ASSERT_EQ(batches.size(), plan.chunks.size());
  EXPECT_EQ(first.errorEstimate.batches, *std::min_element(batches.begin(), batches.end()));
  ASSERT_GT(*std::max_element(batches.begin(), batches.end()), o.errorBatches)
    << "the target needs more than one round, which the time limit below would cut";

  SolverOptions cut = o;
  cut.timeLimitSeconds = 1e-3;
  for (std::size_t k = 0; k < plan.chunks.size(); ++k)
  {
    Solution again = solveChunk(scene, rig(), cut, perChunk, k, sides, patchSides, batches);
    FrameBits bits;
    recordFrames(plan.finishedBegin(k), again, bits);
    for (const auto& [frame, b] : bits)
    {
      EXPECT_EQ(b, whole.at(frame)) << "chunk " << k << ", frame " << frame;
    }
    EXPECT_EQ(again.errorEstimate.batches, batches[k]) << "chunk " << k;
  }
  // Without the first solve's batches the time limit cuts the rounds: other values.
  const std::size_t longest =
    static_cast<std::size_t>(std::max_element(batches.begin(), batches.end()) - batches.begin());
  const Solution cutShort = solveChunk(scene, rig(), cut, perChunk, longest, sides, patchSides);
  EXPECT_EQ(cutShort.errorEstimate.batches, o.errorBatches);
  checks::expectError(
    [&] {
      solveChunk(scene, rig(), o, perChunk, 0, sides, patchSides, { 4, 4 });
    },
    "the batches of 2 chunks for an animation in 3 chunks");
}

TEST(Chunks, ACancelOnOneRankStopsEveryRankBetweenChunks)
{
  const Scene scene = box();
  const SolverOptions o = options(20000, 5, 1);
  constexpr int ranks = 2;
  checks::ThreadRanks group(ranks);
  std::vector<std::string> outcome(ranks);
  std::vector<std::thread> workers;
  for (int r = 0; r < ranks; ++r)
  {
    workers.emplace_back(
      [&, r]
      {
        // Rank 1 cancels in its second chunk (the third of the animation).
        bool second = false;
        try
        {
          solveInChunks(
            scene, rig(), group.optionsFor(r, o), 3,
            [&](double fraction) { return !(r == 1 && second && fraction > 0.6); },
            [&](std::size_t, Solution&) { second = true; });
          outcome[static_cast<std::size_t>(r)] = "finished";
        }
        catch (const Cancelled&)
        {
          outcome[static_cast<std::size_t>(r)] = "cancelled";
        }
        catch (const std::exception& e)
        {
          outcome[static_cast<std::size_t>(r)] = e.what();
        }
      });
  }
  for (std::thread& t : workers)
  {
    t.join();
  }
  EXPECT_EQ(outcome[0], "cancelled");
  EXPECT_EQ(outcome[1], "cancelled");
}

TEST(Chunks, TheSceneAndTheInputCountAgainstTheMemoryLimit)
{
  // A fine box over few frames: the scene, its patches and the polygons given live through
  // the solve, beside its own peak. A limit over the solve's estimate but short of the scene
  // on top of it must refuse, naming the solve; a limit that holds both solves.
  const PolygonSoup soup = scenes::boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) }, true);
  AnimationOptions options;
  options.solver.pathsPerFrame = 10000;
  options.solver.threads = 1;
  options.solver.framesPerChunk = Frames;
  options.remeshing.targetEdgeLength = 0.02;
  const Animation a = solveAnimation(soup, rig(), options);
  const Scene& scene = a.scene;
  const std::uint64_t sceneBytes =
    Scene::estimateMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), false);
  const std::uint64_t held = scene.memoryBytes() + a.patches.points.capacity() * sizeof(Vec3) +
    a.patches.triangles.capacity() * sizeof(Triangle) +
    a.patches.reflectance.capacity() * sizeof(Rgb);
  EXPECT_LE(held, sceneBytes);
  EXPECT_GE(1.25 * static_cast<double>(held), static_cast<double>(sceneBytes));
  const std::uint64_t solveOnly = estimateChunkedMemory(scene.patchCount(), scene.elementCount(),
    scene.points().size(), Frames, Frames, options.solver, 1, 0, false);
  std::printf("solve %.2f MB, scene %.2f MB\n", solveOnly / 1e6, sceneBytes / 1e6);
  options.solver.memoryLimitBytes = solveOnly + sceneBytes / 2;
  checks::expectError([&] { solveAnimation(soup, rig(), options); }, "the solve needs");
  options.solver.memoryLimitBytes = solveOnly + 2 * sceneBytes + (std::uint64_t(1) << 20);
  EXPECT_NO_THROW(solveAnimation(soup, rig(), options));
}

TEST(Chunks, TheSkysTablesCountAgainstTheMemoryLimit)
{
  // A sky that changes in each of 200 frames holds 200 tables of 7,200 cells (23 MB) through
  // the solve of a small ground: a limit of half the tables must refuse the solve, naming
  // them, though the rest fits many times over (a year's 0.47 GiB went uncounted: QA).
  PolygonSoup soup;
  soup.points = { { -1, -1, 0 }, { 1, -1, 0 }, { 1, 1, 0 }, { -1, 1, 0 } };
  soup.polygons = { { 0, 1, 2, 3 } };
  soup.materials = { Material() };
  std::vector<SkyFrame> frames;
  for (int f = 0; f < 200; ++f)
  {
    frames.push_back({ {}, 100.0 + f, 0 });
  }
  LightRig lights;
  lights.skies.emplace_back(SkyModel::CieOvercast, Vec3(0, 0, 1), frames);
  const std::uint64_t tables = lights.skies.front().allocatedBytes();
  EXPECT_GE(tables, 200u * Sky::Cells * 2 * sizeof(double));
  AnimationOptions options;
  options.solver.pathsPerFrame = 2000;
  options.solver.threads = 1;
  options.remeshing.targetEdgeLength = 1;
  options.solver.memoryLimitBytes = tables / 2;
  checks::expectError([&] { solveAnimation(soup, lights, options); }, "the sky's tables");
  options.solver.memoryLimitBytes = 4 * tables;
  EXPECT_NO_THROW(solveAnimation(soup, lights, options));
}

TEST(Chunks, TheChunksLengthFollowsTheSidesLightCanReach)
{
  // Inside a closed box the outer sides, half of them, take no sums and no results: a memory
  // limit that holds 8 frames per chunk with every side's holds more with the sides light
  // reaches, which solveAnimation probes before it chooses. The frames are streamed, so that
  // memory grows with the chunks' length.
  constexpr std::size_t Long = 60;
  const PolygonSoup soup = scenes::boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) }, true);
  AnimationOptions options;
  options.solver.pathsPerFrame = 10000;
  options.solver.threads = 1;
  options.remeshing.targetEdgeLength = 0.1;
  const Scene scene = Scene::fromPatchMesh(remesh(soup, options.remeshing).mesh);
  const std::size_t patches = scene.patchCount(), elements = scene.elementCount(),
                    points = scene.points().size();
  const std::uint64_t bound8 =
    estimateChunkedMemory(patches, elements, points, Long, 8, options.solver, 1, 0, true);
  options.solver.memoryLimitBytes = bound8;
  ASSERT_EQ(chooseFramesPerChunk(patches, elements, points, Long, options.solver, 1, 0, true), 8u);
  const SolveSetup setup(scene, rig(Long), options.solver);
  const std::size_t reached = chooseFramesPerChunk(patches, elements, points, Long, options.solver,
    1, 0, true, 0, &setup.reachable(), &setup.firstHits());
  std::size_t streamed = 0;
  options.chunkFrames = [&](const Animation&, std::size_t, Solution& frames)
  { streamed += frames.frameCount(); };
  const Animation a = solveAnimation(soup, rig(Long), options);
  std::printf("chunks of %zu frames from the reachable sides (%zu without the scene's own "
              "memory), 8 from every side\n",
    a.solution.statistics.framesPerChunk, reached);
  EXPECT_GT(a.solution.statistics.framesPerChunk, 8u);
  EXPECT_LE(a.solution.statistics.framesPerChunk, reached);
  EXPECT_EQ(streamed, Long);
}
