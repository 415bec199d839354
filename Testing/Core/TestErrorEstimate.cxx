// The error estimate from batches: its standard errors agree with the spread over seeds and
// cover a high-N reference as a standard error should, the batched mean stays unbiased, a
// target is reached, the same bits come out for any thread count, and bad options are refused.
#include "CoreChecks.h"
#include "ErrorEstimate.h"
#include "GeneratedScenes.h"
#include "MemoryPlan.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace mlr;
using mlr::checks::balanceOfFrame;
using mlr::checks::expectError;
using mlr::checks::sameBits;

namespace
{
constexpr std::size_t Frames = 3;

Scene box()
{
  return Scene::fromPatchMesh(scenes::closedBox(
    4, true, { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.5), Rgb(0.5), Rgb(0.6), Rgb(0.4) }));
}

MovingLight light()
{
  return MovingLight(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1, 2, 3),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.6, 0.85 }, Frames));
}

SolverOptions batched(std::uint64_t paths, std::uint64_t batches, std::uint64_t seed)
{
  SolverOptions o;
  o.pathsPerFrame = paths;
  o.errorBatches = batches;
  o.seed = seed;
  return o;
}

/// Every (frame, element, channel) of the lit side whose radiosity is lit (ErrorEstimate.h),
/// as storage of one value each: the elements the error statistics are about.
struct Lit
{
  std::size_t frame, element;
  Side side;
};

std::vector<Lit> litValues(const Solution& s)
{
  std::vector<Lit> lit;
  for (std::size_t f = 0; f < s.frameCount(); ++f)
  {
    double mean = 0;
    for (std::size_t e = 0; e < s.elementCount(); ++e)
    {
      mean += s.total(f, e, s.litSide(e)).sum() / static_cast<double>(s.elementCount());
    }
    for (std::size_t e = 0; e < s.elementCount(); ++e)
    {
      if (s.total(f, e, s.litSide(e)).sum() > LitFractionOfMean * mean)
      {
        lit.push_back({ f, e, s.litSide(e) });
      }
    }
  }
  return lit;
}
}

TEST(ErrorEstimate, StandardErrorMatchesTheSpreadOverSeeds)
{
  // S seeds of the same batched solve: the variance of their results about their mean, per
  // element, frame and channel, is what the reported standard error estimates.
  constexpr int Seeds = 24;
  const Scene scene = box();
  std::vector<Solution> runs;
  for (int s = 0; s < Seeds; ++s)
  {
    runs.push_back(solve(scene, light(), batched(32000, 16, 100 + s)));
    ASSERT_TRUE(runs.back().hasErrorEstimate());
  }
  const std::vector<Lit> lit = litValues(runs.front());
  ASSERT_GT(lit.size(), scene.elementCount());
  double ratioSum = 0;
  std::size_t count = 0;
  for (const Lit& v : lit)
  {
    for (int c = 0; c < 3; ++c)
    {
      double mean = 0, meanSquaredError = 0;
      for (const Solution& run : runs)
      {
        mean += run.total(v.frame, v.element, v.side)[c] / Seeds;
        const double se = run.radiosityStdError(v.frame, v.element, v.side)[c];
        meanSquaredError += se * se / Seeds;
      }
      double spread = 0;
      for (const Solution& run : runs)
      {
        const double d = run.total(v.frame, v.element, v.side)[c] - mean;
        spread += d * d / (Seeds - 1);
      }
      if (meanSquaredError > 0)
      {
        ratioSum += spread / meanSquaredError;
        ++count;
      }
    }
  }
  const double ratio = ratioSum / static_cast<double>(count);
  // One value's variance over S seeds has a relative standard deviation of sqrt(2 / (S - 1));
  // the values of a frame are counted as E / 16 independent ones (neighbouring elements share
  // patches, frames and channels share paths); four of those standard deviations.
  const double elements = static_cast<double>(scene.elementCount());
  const double tolerance = 4 * std::sqrt(2.0 / (Seeds - 1)) / std::sqrt(elements / 16);
  EXPECT_NEAR(ratio, 1.0, tolerance) << "mean of spread^2 / SE^2 over " << count << " values";
}

TEST(ErrorEstimate, OneSigmaIntervalsCoverAHighPathReference)
{
  // With 16 batches, |x - reference| <= SE holds with the probability of Student's t with 15
  // degrees of freedom within 1, 0.67, slightly less for the reference's own noise (32 times
  // more paths): between 55% and 80% of the lit values.
  const Scene scene = box();
  SolverOptions reference;
  reference.pathsPerFrame = 32 * 32000;
  reference.seed = 7;
  const Solution ref = solve(scene, light(), reference);
  const Solution run = solve(scene, light(), batched(32000, 16, 8));
  std::size_t covered = 0, total = 0;
  for (const Lit& v : litValues(run))
  {
    for (int c = 0; c < 3; ++c)
    {
      const double d =
        run.total(v.frame, v.element, v.side)[c] - ref.total(v.frame, v.element, v.side)[c];
      covered += std::abs(d) <= run.radiosityStdError(v.frame, v.element, v.side)[c] ? 1 : 0;
      ++total;
    }
  }
  const double coverage = static_cast<double>(covered) / static_cast<double>(total);
  EXPECT_GT(coverage, 0.55) << covered << " of " << total;
  EXPECT_LT(coverage, 0.80) << covered << " of " << total;
}

TEST(ErrorEstimate, BatchedSolveStillAbsorbsAllPower)
{
  // The energy balance of a closed box (TestEnergyBalance), with the mean over seeds of
  // batched solves: every batch is unbiased, so their mean is.
  const Scene scene = box();
  const MovingLight l = light();
  constexpr int Seeds = 4;
  for (std::size_t f = 0; f < Frames; ++f)
  {
    Rgb absorbed;
    for (int s = 0; s < Seeds; ++s)
    {
      const Solution solution = solve(scene, l, batched(100000, 16, 30 + s));
      absorbed += balanceOfFrame(scene, solution, f).absorbed / Seeds;
    }
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(absorbed[c] / l.power()[c], 1.0, 0.01) << "frame " << f << " channel " << c;
    }
  }
}

TEST(ErrorEstimate, UniformReflectanceStillGivesTheGeometricSeries)
{
  const double rho = 0.5;
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(rho) }));
  const MovingLight l(
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(2), std::vector<Vec3>{ Vec3() });
  const Solution solution = solve(scene, l, batched(300000, 16, 3));
  EXPECT_NEAR(balanceOfFrame(scene, solution, 0).radiantPower.r / (2 * rho / (1 - rho)), 1.0, 0.01);
}

TEST(ErrorEstimate, OneBatchIsTheSolveWithoutAnEstimate)
{
  const Scene scene = box();
  SolverOptions plain;
  plain.pathsPerFrame = 20000;
  plain.seed = 5;
  Solution a = solve(scene, light(), plain);
  Solution b = solve(scene, light(), batched(20000, 1, 5));
  EXPECT_FALSE(b.hasErrorEstimate());
  EXPECT_TRUE(sameBits(a.directData(), b.directData()));
  EXPECT_TRUE(sameBits(a.indirectData(), b.indirectData()));
  EXPECT_EQ(b.errorEstimate.batches, 0u);
}

TEST(ErrorEstimate, ThreadCountDoesNotChangeABit)
{
  const Scene scene = box();
  SolverOptions one = batched(32000, 8, 11), three = one;
  one.threads = 1;
  three.threads = 3;
  Solution a = solve(scene, light(), one);
  Solution b = solve(scene, light(), three);
  EXPECT_TRUE(sameBits(a.directData(), b.directData()));
  EXPECT_TRUE(sameBits(a.indirectData(), b.indirectData()));
  EXPECT_TRUE(sameBits(a.patchData(), b.patchData()));
  EXPECT_TRUE(sameBits(a.stdErrorData(), b.stdErrorData()));
  EXPECT_EQ(a.errorEstimate.relativeErrorP95, b.errorEstimate.relativeErrorP95);
  EXPECT_EQ(a.errorEstimate.batches, 8u);
  EXPECT_EQ(a.errorEstimate.stoppedBy, "batches");
  EXPECT_EQ(a.statistics.effectivePathsPerFrame, 32000u);
  // Each frame's statistics are over lit elements, the median at most the p95.
  ASSERT_EQ(a.errorEstimate.relativeErrorP95.size(), Frames);
  for (std::size_t f = 0; f < Frames; ++f)
  {
    EXPECT_GT(a.errorEstimate.litElements[f], 0u);
    EXPECT_GT(a.errorEstimate.relativeErrorMedian[f], 0);
    EXPECT_LE(a.errorEstimate.relativeErrorMedian[f], a.errorEstimate.relativeErrorP95[f]);
  }
}

TEST(ErrorEstimate, ASideFirstLitInALaterBatchGetsTheWholeMeanAndSpread)
{
  // Made-up batches of 1 patch (4 elements) over 3 frames. Element 0's front is lit in every
  // batch; element 1's back only from batch 3 on (a side the reachability probes missed,
  // which a later batch's path finds); element 2's back never. The merge skips a side that
  // no batch has lit so far: the side lit late must still get the mean and spread of all
  // its batches, zeros included, and the dark one zeros.
  constexpr std::size_t frames = 3, batches = 5;
  Solution result(frames, 4, 1);
  Solution batch(frames, 4, 1);
  const double values[batches] = { 1.0, 3.0, 2.0, 6.0, 4.0 };
  auto x = [&](std::size_t b, std::size_t f) { return values[b] * static_cast<double>(f + 1); };
  SolverOptions options = batched(batches * 10, batches, 1);
  options.threads = 3;
  std::size_t done = 0;
  double secondsReducing = 0;
  PatchMesh onePatch;
  onePatch.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
  onePatch.triangles = { { 0, 1, 2 } };
  onePatch.reflectance = { Rgb(0.5) };
  solveInBatches(
    Scene::fromPatchMesh(onePatch), options,
    [&](const SolverOptions&, const std::function<bool(double)>&) -> Solution&
    {
      batch.clearRadiosity();
      batch.allocateIndirect();
      for (std::size_t f = 0; f < frames; ++f)
      {
        batch.directData()[batch.elementIndex(f, 0, Side::Front)] = PackedRgb(Rgb(x(done, f)));
        batch.indirectData()[batch.elementIndex(f, 0, Side::Front)] = PackedRgb(Rgb(0.5));
        if (done >= 2)
        {
          batch.directData()[batch.elementIndex(f, 1, Side::Back)] = PackedRgb(Rgb(x(done, f)));
          batch.patchData()[batch.patchIndex(f, 0, Side::Back)] = PackedRgb(Rgb(x(done, f)));
        }
      }
      ++done;
      return batch;
    },
    {}, 0, secondsReducing, result);
  ASSERT_EQ(done, batches);
  for (std::size_t f = 0; f < frames; ++f)
  {
    // Over all 5 batches, and over the 3 that lit element 1 padded with 2 zeros.
    double all = 0, late = 0;
    for (std::size_t b = 0; b < batches; ++b)
    {
      all += x(b, f);
      late += b >= 2 ? x(b, f) : 0;
    }
    all /= batches;
    late /= batches;
    double allSquares = 0, lateSquares = 0;
    for (std::size_t b = 0; b < batches; ++b)
    {
      allSquares += (x(b, f) - all) * (x(b, f) - all);
      const double v = b >= 2 ? x(b, f) : 0;
      lateSquares += (v - late) * (v - late);
    }
    const double scale = 1.0 / ((batches - 1) * batches);
    const double rounding = 2 * PackedRgb::RelativeRounding;
    EXPECT_NEAR(result.directIrradiance(f, 0, Side::Front).g, all, rounding * all);
    EXPECT_NEAR(result.indirectIrradiance(f, 0, Side::Front).g, 0.5, rounding * 0.5);
    EXPECT_NEAR(result.irradianceStdError(f, 0, Side::Front).g, std::sqrt(allSquares * scale),
      rounding * std::sqrt(allSquares * scale));
    EXPECT_NEAR(result.directIrradiance(f, 1, Side::Back).g, late, rounding * late);
    EXPECT_NEAR(result.patchBounced(f, 0, Side::Back).g, late, rounding * late);
    EXPECT_NEAR(result.irradianceStdError(f, 1, Side::Back).g, std::sqrt(lateSquares * scale),
      rounding * std::sqrt(lateSquares * scale));
    EXPECT_EQ(result.irradiance(f, 2, Side::Back).sum(), 0.0);
    EXPECT_EQ(result.irradianceStdError(f, 2, Side::Back).sum(), 0.0);
    EXPECT_EQ(result.patchBounced(f, 0, Side::Front).sum(), 0.0);
  }
}

TEST(ErrorEstimate, TargetIsReachedAndTheSameForAnyThreadCount)
{
  const Scene scene = box();
  SolverOptions one = batched(16000, 16, 21);
  one.targetRelativeError = 0.05;
  one.threads = 1;
  SolverOptions three = one;
  three.threads = 3;
  std::vector<std::string> messages;
  one.log = [&](const std::string& m) { messages.push_back(m); };
  Solution a = solve(scene, light(), one);
  Solution b = solve(scene, light(), three);
  EXPECT_EQ(a.errorEstimate.stoppedBy, "target");
  EXPECT_GT(a.errorEstimate.rounds, 1u) << "the first round already met the target";
  EXPECT_GT(a.errorEstimate.batches, 16u);
  for (std::size_t f = 0; f < Frames; ++f)
  {
    EXPECT_LE(a.errorEstimate.relativeErrorP95[f], 0.05) << "frame " << f;
  }
  EXPECT_EQ(a.errorEstimate.batches, b.errorEstimate.batches);
  EXPECT_TRUE(sameBits(a.directData(), b.directData()));
  EXPECT_TRUE(sameBits(a.indirectData(), b.indirectData()));
  EXPECT_TRUE(sameBits(a.stdErrorData(), b.stdErrorData()));
  EXPECT_TRUE(a.warnings.empty());
  // The log tells the memory and time estimates and each round's error.
  ASSERT_GE(messages.size(), 3u);
  EXPECT_NE(messages[0].find("memory estimate"), std::string::npos) << messages[0];
  EXPECT_NE(messages[1].find("take about"), std::string::npos) << messages[1];
  EXPECT_NE(messages.back().find("reached"), std::string::npos) << messages.back();
}

TEST(ErrorEstimate, TimeLimitStopsAfterTheFirstRoundWithAWarning)
{
  // A limit no solve meets: the first round completes (it gives the estimate), then it stops.
  SolverOptions o = batched(16000, 16, 21);
  o.targetRelativeError = 0.001;
  o.timeLimitSeconds = 1e-9;
  const Solution s = solve(box(), light(), o);
  EXPECT_EQ(s.errorEstimate.stoppedBy, "time limit");
  EXPECT_EQ(s.errorEstimate.batches, 16u);
  ASSERT_EQ(s.warnings.size(), 1u);
  EXPECT_NE(s.warnings[0].find("was not reached: the time limit"), std::string::npos)
    << s.warnings[0];
}

TEST(ErrorEstimate, RoundsGrowByTheSquaredRatioClamped)
{
  EXPECT_EQ(nextBatchCount(16, 0.04, 0.02), 64u);   // 4.4 clamped to 4
  EXPECT_EQ(nextBatchCount(16, 0.03, 0.02), 40u);   // 1.1 x 2.25 = 2.475
  EXPECT_EQ(nextBatchCount(16, 0.0201, 0.02), 20u); // at least 1.25
  EXPECT_EQ(pathsOfBatch(10, 4, 0) + pathsOfBatch(10, 4, 1) + pathsOfBatch(10, 4, 2) +
      pathsOfBatch(10, 4, 3),
    10u);
  EXPECT_EQ(batchSeed(9, 0), 9u);
  EXPECT_NE(batchSeed(9, 1), batchSeed(10, 1));
  EXPECT_NE(batchSeed(9, 1), 10u);
}

TEST(ErrorEstimate, FrameErrorIsOverLitElementsByNearestRank)
{
  // 20 elements of radiosity 1 with relative errors 0.01, 0.02, ..., 0.20, and 4 dark ones
  // (below 1% of the mean) whose huge relative error must not count.
  Solution s(1, 24, 6);
  for (std::size_t e = 0; e < 24; ++e)
  {
    s.directData()[s.elementIndex(0, e, Side::Front)] = PackedRgb(Rgb(e < 20 ? 1.0 / 3 : 1e-5));
  }
  const FrameError fe = frameError(s, 0,
    [](std::size_t e, Side) { return Rgb(e < 20 ? 0.01 * static_cast<double>(e + 1) / 3 : 1.0); });
  EXPECT_EQ(fe.litElements, 20u);
  // The ratio of two stored values, each rounded to within PackedRgb::RelativeRounding.
  EXPECT_NEAR(fe.median, 0.10, 0.10 * 2 * PackedRgb::RelativeRounding);
  EXPECT_NEAR(fe.p95, 0.19, 0.19 * 2 * PackedRgb::RelativeRounding);
}

TEST(ErrorEstimate, FrameErrorLeavesTheEmissionOut)
{
  // 10 emitters that reflect little light with a 100% error, and 10 elements that reflect
  // radiosity 1 with a 2% error. Counted with their exact emission the emitters would be the
  // lit and accurate majority; without it they are dark, and the frame's error is the others'.
  Solution s(1, 20, 5);
  s.emissionData().assign(20, Rgb());
  for (std::size_t e = 0; e < 20; ++e)
  {
    const bool emitter = e < 10;
    if (emitter)
    {
      s.emissionData()[e] = Rgb(1000.0);
    }
    s.directData()[s.elementIndex(0, e, Side::Front)] = PackedRgb(Rgb(emitter ? 1e-6 : 1.0 / 3));
  }
  const FrameError fe =
    frameError(s, 0, [](std::size_t e, Side) { return e < 10 ? Rgb(1e-6 / 3) : Rgb(0.02 / 3); });
  EXPECT_EQ(fe.litElements, 10u);
  EXPECT_NEAR(fe.median, 0.02, 0.02 * 2 * PackedRgb::RelativeRounding);
  EXPECT_NEAR(fe.p95, 0.02, 0.02 * 2 * PackedRgb::RelativeRounding);
}

TEST(ErrorEstimate, BlackElementsAreJudgedByTheLightArrivingOnThem)
{
  // A black floor reflects nothing, but its illuminance is read as any other's: 10 black
  // elements with a 10% error on their irradiance and 10 grey ones with 1%. Judged by the
  // radiosity they reflect, the black ones would be dark and the frame's p95 1%.
  Solution s(1, 20, 5);
  for (std::size_t e = 0; e < 20; ++e)
  {
    s.reflectanceData()[e] = e < 10 ? Rgb(0.0) : Rgb(0.5);
    s.directData()[s.elementIndex(0, e, Side::Front)] = PackedRgb(Rgb(1.0 / 3));
  }
  const FrameError fe =
    frameError(s, 0, [](std::size_t e, Side) { return e < 10 ? Rgb(0.1 / 3) : Rgb(0.01 / 3); });
  EXPECT_EQ(fe.litElements, 20u);
  EXPECT_NEAR(fe.p95, 0.1, 0.1 * 2 * PackedRgb::RelativeRounding);
}

TEST(ErrorEstimate, MemoryEstimateCountsTheBatches)
{
  const Scene scene = box();
  SolverOptions plain, many = batched(600000, 16, 0);
  const MemoryPlan a =
    planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), Frames, plain);
  const MemoryPlan b =
    planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), Frames, many);
  EXPECT_EQ(a.errorEstimate, 0u);
  EXPECT_EQ(
    b.errorEstimate, errorEstimateBytes(scene.patchCount(), scene.elementCount(), Frames, many));
  // The standard errors (6 bytes per element side and frame) come after the last batch's
  // shooting: in the peak of the gathering phase only.
  const std::uint64_t standardErrors = Frames * 2 * scene.elementCount() * 6;
  EXPECT_LE(b.peak, a.peak + b.errorEstimate);
  EXPECT_GE(b.peak, a.peak + b.errorEstimate - standardErrors);
  // Per element side and frame: the mean's direct and indirect stored (2 x 6) and in single
  // precision (2 x 12), the squared deviations (12) and the standard error (6); per patch
  // side and frame the mean, stored and in single precision (6 + 12); per element and patch
  // side a flag, whether a batch lit it. Without reachable sides, every side counts.
  EXPECT_EQ(b.errorEstimate,
    Frames * 2 * (scene.elementCount() * 54 + scene.patchCount() * 18) +
      2 * (scene.elementCount() + scene.patchCount()));
  // Rounds need no more memory.
  many.targetRelativeError = 0.02;
  EXPECT_EQ(
    planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), Frames, many)
      .peak,
    b.peak);
}

TEST(ErrorEstimate, BadOptionsAreRefusedWithTheOptionNamed)
{
  const Scene scene = box();
  auto run = [&](SolverOptions o) { return [&scene, o] { solve(scene, light(), o); }; };
  SolverOptions o = batched(16000, 0, 0);
  expectError(run(o), "error batch count (ErrorBatches, --error-batches) is 0");
  o.errorBatches = MaximumErrorBatches + 1;
  expectError(run(o), "up to 4096");
  o = batched(10, 16, 0);
  expectError(run(o), "cannot make 16 error batches");
  o = batched(16000, 16, 0);
  o.targetRelativeError = -0.02;
  expectError(run(o), "target relative error (TargetRelativeError, --target-error) is -0.02");
  o.targetRelativeError = std::numeric_limits<double>::quiet_NaN();
  expectError(run(o), "TargetRelativeError");
  o.targetRelativeError = 1e-6;
  expectError(run(o), "below 0.0001");
  // No spread of non-negative batches exceeds their mean: a target of 1 or more is met at once.
  o.targetRelativeError = 1.5;
  expectError(run(o), "is 1.5: the batches' relative error is at most 1 (100%)");
  o.targetRelativeError = 1;
  expectError(run(o), "is 1: the batches' relative error is at most 1 (100%)");
  o = batched(16000, 1, 0);
  o.targetRelativeError = 0.02;
  expectError(run(o), "needs an error estimate");
  o = batched(16000, 16, 0);
  o.timeLimitSeconds = -1;
  expectError(run(o), "time limit (TimeLimit, --time-limit)");
  o.timeLimitSeconds = std::numeric_limits<double>::infinity();
  expectError(run(o), "time limit");
  // Reuse needs a path per position in every batch: 32 paths in 16 batches is 2 per batch,
  // fewer than the 3 positions.
  o = batched(32, 16, 0);
  expectError(run(o), "each of the 16 error batches has 2 paths per frame");
}
