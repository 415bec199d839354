#include "Chunks.h"

#include "Error.h"
#include "ErrorEstimate.h"
#include "Parallel.h"
#include "Plural.h"
#include "Ranks.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <numeric>
#include <optional>
#include <set>
#include <string>
#include <type_traits>

namespace mlr
{

std::string chunkSettingsProblem(std::uint64_t framesPerChunk, std::uint64_t overlap,
  const std::string& framesPerChunkName, const std::string& overlapName)
{
  const std::string why = ", so that the blends at a chunk's two seams do not overlap";
  if (framesPerChunk != 0 && framesPerChunk < MinimumFramesPerChunk)
  {
    return framesPerChunkName + " is " + std::to_string(framesPerChunk) +
      ": give 0 (the memory limit chooses) or at least " + std::to_string(MinimumFramesPerChunk) +
      why;
  }
  if (framesPerChunk != 0 && overlap > framesPerChunk / 2)
  {
    return overlapName + " is " + std::to_string(overlap) + ", more than half of " +
      framesPerChunkName + " (" + std::to_string(framesPerChunk) +
      "): give 0 (an eighth of a chunk) or at most " + std::to_string(framesPerChunk / 2) + why;
  }
  return {};
}

std::size_t chunkOverlap(std::size_t framesPerChunk, std::uint64_t asked)
{
  const std::size_t m = asked == 0
    ? framesPerChunk / 8
    : static_cast<std::size_t>(std::min<std::uint64_t>(asked, framesPerChunk / 2));
  return std::max<std::size_t>(1, m);
}

ChunkPlan planChunks(std::size_t frames, std::size_t framesPerChunk, std::uint64_t overlap)
{
  // The overlap is cut to half a chunk below, as when the memory limit chooses the length.
  if (const std::string problem =
        chunkSettingsProblem(framesPerChunk, 0, "the chunk length", "the chunk overlap");
      !problem.empty() && framesPerChunk < frames)
  {
    throw Error(problem);
  }
  ChunkPlan plan;
  plan.frames = frames;
  plan.framesPerChunk = framesPerChunk == 0 || framesPerChunk >= frames ? frames : framesPerChunk;
  plan.overlap = plan.framesPerChunk >= frames ? 0 : chunkOverlap(plan.framesPerChunk, overlap);
  for (std::size_t begin = 0; begin < frames || plan.chunks.empty(); begin += plan.framesPerChunk)
  {
    ChunkPlan::Chunk chunk;
    chunk.begin = begin;
    chunk.end = std::min(frames, begin + plan.framesPerChunk);
    chunk.solveBegin = begin - std::min(begin, plan.overlap);
    chunk.solveEnd = std::min(frames, chunk.end + plan.overlap);
    plan.chunks.push_back(chunk);
    if (plan.framesPerChunk == 0)
    {
      break;
    }
  }
  // A last chunk shorter than the overlap would leave frames of its seam's blend to a chunk
  // that does not solve them: it joins the chunk before.
  if (plan.chunks.size() > 1 && plan.chunks.back().end - plan.chunks.back().begin < plan.overlap)
  {
    plan.chunks.pop_back();
    plan.chunks.back().end = frames;
    plan.chunks.back().solveEnd = frames;
  }
  return plan;
}

double ChunkPlan::weight(std::size_t chunk, std::size_t frame) const
{
  const Chunk& c = this->chunks[chunk];
  if (frame < c.solveBegin || frame >= c.solveEnd)
  {
    return 0;
  }
  const double m = static_cast<double>(this->overlap);
  // The ramp across a seam s: the later chunk's weight rises from 1/(4m) to 1 - 1/(4m) over
  // [s - m, s + m), frame centres at f + 1/2.
  auto rising = [m](std::size_t seam, std::size_t f)
  { return (static_cast<double>(f) + 0.5 - (static_cast<double>(seam) - m)) / (2 * m); };
  if (chunk > 0 && frame < c.begin + this->overlap)
  {
    return rising(c.begin, frame);
  }
  if (chunk + 1 < this->chunks.size() && frame + this->overlap >= c.end)
  {
    return 1 - rising(c.end, frame);
  }
  return 1;
}

std::size_t ChunkPlan::finishedBegin(std::size_t chunk) const
{
  return chunk == 0 ? 0 : this->chunks[chunk].begin - this->overlap;
}

std::size_t ChunkPlan::finishedEnd(std::size_t chunk) const
{
  return chunk + 1 == this->chunks.size() ? this->frames : this->chunks[chunk].end - this->overlap;
}

LightRig sliceRig(const LightRig& rig, std::size_t first, std::size_t count)
{
  auto poses = [&](const std::vector<LightPose>& all)
  { return std::vector<LightPose>(all.begin() + first, all.begin() + first + count); };
  LightRig slice = rig;
  slice.firstFrame = rig.firstFrame + first;
  for (MovingLight& light : slice.areaLights)
  {
    if (light.frameCount() > 1)
    {
      light.setPoses(poses(light.poses()));
    }
  }
  for (PointLight& light : slice.pointLights)
  {
    if (light.frameCount() > 1)
    {
      light.setPoses(poses(light.poses()));
    }
  }
  for (DirectionalLight& light : slice.directionalLights)
  {
    if (light.frameCount() > 1)
    {
      std::vector<Vec3> directions;
      std::vector<Rgb> factors;
      for (std::size_t f = first; f < first + count; ++f)
      {
        directions.push_back(light.direction(f));
        factors.push_back(light.powerFactor(f));
      }
      light = DirectionalLight(directions, light.irradiance(), factors);
    }
  }
  for (Sky& sky : slice.skies)
  {
    if (sky.frameCount() > 1)
    {
      sky = sky.slice(first, count);
    }
  }
  return slice;
}

namespace
{
/// A chunk's estimate: `solution` holds the frames from `first` on.
struct Estimate
{
  Solution* solution = nullptr;
  std::size_t first = 0;
};

/// Copies frames [begin, end) of `src` into `dest` (frame f at f - dest.first), bit for bit.
void copyFrames(const Estimate& src, std::size_t begin, std::size_t end, const Estimate& dest)
{
  Solution& s = *src.solution;
  Solution& d = *dest.solution;
  const std::size_t n = end - begin;
  auto copy = [n](StoredArray& from, std::size_t i, StoredArray& to, std::size_t j)
  {
    if (!from.empty())
    {
      std::copy(from.begin() + i, from.begin() + i + n, to.begin() + j);
    }
  };
  for (std::size_t e = 0; e < s.elementCount(); ++e)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      const std::size_t i = s.elementIndex(begin - src.first, e, side);
      const std::size_t j = d.elementIndex(begin - dest.first, e, side);
      copy(s.directData(), i, d.directData(), j);
      copy(s.indirectData(), i, d.indirectData(), j);
      copy(s.stdErrorData(), i, d.stdErrorData(), j);
    }
  }
  for (std::size_t p = 0; p < s.patchCount(); ++p)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      copy(s.patchData(), s.patchIndex(begin - src.first, p, side), d.patchData(),
        d.patchIndex(begin - dest.first, p, side));
    }
  }
}

/// The blend of two estimates, wa a + wb b, rounded once.
PackedRgb blend(const PackedRgb& a, double wa, const PackedRgb& b, double wb)
{
  return PackedRgb(Rgb(a) * wa + Rgb(b) * wb);
}

/// The standard error of that blend for estimates of correlation rho:
/// s^2 = wa^2 sa^2 + wb^2 sb^2 + 2 wa wb rho sa sb.
PackedRgb blendError(const PackedRgb& a, double wa, const PackedRgb& b, double wb, double rho)
{
  const Rgb sa(a), sb(b);
  auto q = [&](double x, double y)
  { return std::sqrt(wa * wa * x * x + wb * wb * y * y + 2 * wa * wb * rho * x * y); };
  return PackedRgb(Rgb(q(sa.r, sb.r), q(sa.g, sb.g), q(sa.b, sb.b)));
}

/**
 * The correlation of two chunks' estimates of a frame, pooled over its elements: they share
 * the paths of the positions both solve, and the gathering rays, so the variance of their
 * difference d = a - b, sa^2 + sb^2 - 2 rho sa sb, is smaller than the sum. From the
 * differences themselves: rho = (sum (sa^2 + sb^2) - sum d^2) / (2 sum sa sb), in [0, 1].
 */
double correlationOf(const Solution& a, std::size_t fa, const Solution& b, std::size_t fb)
{
  double variances = 0, squares = 0, products = 0;
  for (std::size_t e = 0; e < a.elementCount(); ++e)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      const Rgb d = a.irradiance(fa, e, side) - b.irradiance(fb, e, side);
      const Rgb sa = a.irradianceStdError(fa, e, side), sb = b.irradianceStdError(fb, e, side);
      variances +=
        sa.r * sa.r + sa.g * sa.g + sa.b * sa.b + sb.r * sb.r + sb.g * sb.g + sb.b * sb.b;
      squares += d.r * d.r + d.g * d.g + d.b * d.b;
      products += sa.r * sb.r + sa.g * sb.g + sa.b * sb.b;
    }
  }
  return products > 0 ? std::clamp((variances - squares) / (2 * products), 0.0, 1.0) : 0.0;
}

/**
 * Writes frames [begin, end) into `dest` from chunk `chunk`'s estimate `current` and, across
 * its first seam, the estimate `before` of the chunk before, blended with plan.weight. The
 * frames of weight 1 are copied, bit for bit.
 */
void finishFrames(const ChunkPlan& plan, std::size_t chunk, const Estimate& before,
  const Estimate& current, std::size_t begin, std::size_t end, const Estimate& dest)
{
  std::size_t blendEnd = begin;
  while (blendEnd < end && plan.weight(chunk, blendEnd) < 1)
  {
    ++blendEnd;
  }
  copyFrames(current, blendEnd, end, dest);
  if (blendEnd == begin)
  {
    return;
  }
  if (!before.solution)
  {
    throw Error("internal error: a chunk's seam has no chunk before it");
  }
  Solution& c = *current.solution;
  Solution& b = *before.solution;
  Solution& d = *dest.solution;
  const bool errors = c.hasErrorEstimate();
  const bool indirect = !c.indirectData().empty();
  // Each side's frames are contiguous (side-major storage): the frames run innermost.
  const std::size_t n = blendEnd - begin;
  std::vector<double> wc(n), rho(n, 0.0);
  for (std::size_t i = 0; i < n; ++i)
  {
    wc[i] = plan.weight(chunk, begin + i);
    if (errors)
    {
      rho[i] = correlationOf(c, begin + i - current.first, b, begin + i - before.first);
    }
  }
  const std::size_t fc = begin - current.first, fb = begin - before.first, fd = begin - dest.first;
  for (std::size_t e = 0; e < c.elementCount(); ++e)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      const std::size_t ic = c.elementIndex(fc, e, side), ib = b.elementIndex(fb, e, side);
      const std::size_t id = d.elementIndex(fd, e, side);
      for (std::size_t i = 0; i < n; ++i)
      {
        d.directData()[id + i] =
          blend(c.directData()[ic + i], wc[i], b.directData()[ib + i], 1 - wc[i]);
        if (indirect)
        {
          d.indirectData()[id + i] =
            blend(c.indirectData()[ic + i], wc[i], b.indirectData()[ib + i], 1 - wc[i]);
        }
        if (errors)
        {
          d.stdErrorData()[id + i] = blendError(
            c.stdErrorData()[ic + i], wc[i], b.stdErrorData()[ib + i], 1 - wc[i], rho[i]);
        }
      }
    }
  }
  for (std::size_t p = 0; p < c.patchCount(); ++p)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      const std::size_t ic = c.patchIndex(fc, p, side), ib = b.patchIndex(fb, p, side);
      const std::size_t id = d.patchIndex(fd, p, side);
      for (std::size_t i = 0; i < n; ++i)
      {
        d.patchData()[id + i] =
          blend(c.patchData()[ic + i], wc[i], b.patchData()[ib + i], 1 - wc[i]);
      }
    }
  }
}

/// An empty Solution of `frames` frames shaped as `like`: its storage scale, reflectance,
/// emission and arrays (the indirect light and standard errors when `like` has them).
Solution shapedLike(Solution& like, std::size_t frames)
{
  Solution s(frames, like.elementCount(), like.patchCount());
  s.setStorageScale(like.storageScale());
  s.reflectanceData() = like.reflectanceData();
  s.emissionData() = like.emissionData();
  s.allocateIndirect();
  if (like.hasErrorEstimate())
  {
    s.stdErrorData() = StoredArray(s.directData().size());
  }
  return s;
}

/// The per-frame relative error statistics of `s` (its lit sides chosen), recomputed.
void summariseErrors(Solution& s, const ErrorEstimateSummary& like)
{
  if (!s.hasErrorEstimate())
  {
    return;
  }
  ErrorEstimateSummary& summary = s.errorEstimate;
  summary.batches = like.batches;
  summary.rounds = like.rounds;
  summary.pathsPerFrame = like.pathsPerFrame;
  summary.target = like.target;
  summary.stoppedBy = like.stoppedBy;
  summary.relativeErrorMedian.clear();
  summary.relativeErrorP95.clear();
  summary.litElements.clear();
  for (std::size_t f = 0; f < s.frameCount(); ++f)
  {
    const FrameError e = frameError(
      s, f, [&](std::size_t element, Side side) { return s.irradianceStdError(f, element, side); });
    summary.relativeErrorMedian.push_back(e.median);
    summary.relativeErrorP95.push_back(e.p95);
    summary.litElements.push_back(e.litElements);
  }
}

/**
 * The frames chunk `chunk` finishes, as they are handed on: blended across its first seam
 * with `before`, the estimate of the chunk before (none for the first chunk), with the lit
 * sides given, the error figures of each frame and the chunk's statistics.
 */
Solution handedOn(const ChunkPlan& plan, std::size_t chunk, const Estimate& before,
  Solution& current, const std::vector<Side>& litSides, const std::vector<Side>& patchLitSides)
{
  const std::size_t begin = plan.finishedBegin(chunk), end = plan.finishedEnd(chunk);
  Solution finished = shapedLike(current, end - begin);
  finishFrames(plan, chunk, before, { &current, plan.chunks[chunk].solveBegin }, begin, end,
    { &finished, begin });
  finished.litSideData() = litSides;
  finished.patchLitSideData() = patchLitSides;
  summariseErrors(finished, current.errorEstimate);
  finished.statistics = current.statistics;
  finished.statistics.chunk = static_cast<std::int64_t>(chunk) + 1;
  finished.statistics.chunks = plan.chunks.size();
  finished.statistics.framesPerChunk = plan.framesPerChunk;
  finished.statistics.chunkOverlap = plan.overlap;
  return finished;
}

/// Adds a chunk's statistics to the animation's.
void accumulate(const SolverStatistics& c, bool first, SolverStatistics& s)
{
  if (first)
  {
    const std::uint64_t frames = s.frames;
    s = c;
    s.frames = frames;
    return;
  }
  s.effectivePathsPerFrame = std::min(s.effectivePathsPerFrame, c.effectivePathsPerFrame);
  s.pathsCast += c.pathsCast;
  s.shootingRays += c.shootingRays;
  s.shadowRays += c.shadowRays;
  s.shadowRaysBlocked += c.shadowRaysBlocked;
  s.firstHits += c.firstHits;
  s.gatheringRays += c.gatheringRays;
  s.missedRays += c.missedRays;
  s.gatheringSides = std::max(s.gatheringSides, c.gatheringSides);
  s.reachabilityRays += c.reachabilityRays;
  s.reachableSides = std::max(s.reachableSides, c.reachableSides);
  s.staticPathsCast += c.staticPathsCast;
  s.pilotRays += c.pilotRays;
  s.smallestPositionShare = std::min(s.smallestPositionShare, c.smallestPositionShare);
  s.largestPositionShare = std::max(s.largestPositionShare, c.largestPositionShare);
  s.secondsSetup += c.secondsSetup;
  s.secondsShooting += c.secondsShooting;
  s.secondsGathering += c.secondsGathering;
  s.secondsReducing += c.secondsReducing;
  s.memoryEstimateBytes = std::max(s.memoryEstimateBytes, c.memoryEstimateBytes);
  s.memoryResultBytes = std::max(s.memoryResultBytes, c.memoryResultBytes);
  s.memoryAccumulatorBytes = std::max(s.memoryAccumulatorBytes, c.memoryAccumulatorBytes);
  s.accumulatorCopyPerWorker = s.accumulatorCopyPerWorker && c.accumulatorCopyPerWorker;
}

void accumulate(const ErrorEstimateSummary& c, bool first, ErrorEstimateSummary& s)
{
  if (first)
  {
    s = c;
    return;
  }
  // The batches, rounds and N of the animation are those of its least solved chunk (the
  // first of equal ones), together, as each frame's result and error bar come from its own
  // chunk's; a limit that stopped one says so.
  if (c.pathsPerFrame < s.pathsPerFrame)
  {
    s.batches = c.batches;
    s.rounds = c.rounds;
    s.pathsPerFrame = c.pathsPerFrame;
  }
  if (c.stoppedBy == "time limit" || c.stoppedBy == "path limit")
  {
    s.stoppedBy = c.stoppedBy;
  }
}
}

namespace
{
/// What ended a chunk's batches, as a number that a sum over ranks carries.
constexpr std::array<const char*, 6> StopReasons = { "", "batches", "target", "time limit",
  "path limit", "batch limit" };

/// Every field of a chunk's statistics and error summary, in one order, for the ranks that
/// share chunks out (visit(field) with a reference to each).
template <typename Visit>
void visitChunkFigures(
  SolverStatistics& s, ErrorEstimateSummary& e, std::uint64_t& stop, Visit visit)
{
  visit(s.frames), visit(s.chunks), visit(s.framesPerChunk), visit(s.patches), visit(s.elements);
  visit(s.effectivePathsPerFrame), visit(s.pathsCast), visit(s.shootingRays);
  visit(s.shadowRays), visit(s.shadowRaysBlocked), visit(s.firstHits), visit(s.gatheringRays);
  visit(s.missedRays), visit(s.gatheringSides), visit(s.reachabilityRays);
  visit(s.reachableSides), visit(s.overflowSides), visit(s.sources), visit(s.staticPathsCast);
  visit(s.pilotRays), visit(s.smallestPositionShare), visit(s.largestPositionShare);
  visit(s.meanPathLength), visit(s.secondsRemeshing), visit(s.patchEdgeLength);
  visit(s.secondsSetup), visit(s.secondsShooting), visit(s.secondsGathering);
  visit(s.secondsReducing), visit(s.secondsTotal), visit(s.memoryEstimateBytes);
  visit(s.memoryResultBytes), visit(s.memoryAccumulatorBytes);
  visit(s.accumulatorCopyPerWorker), visit(s.threads), visit(s.reuseShooting);
  visit(s.reuseGathering), visit(s.twoSided);
  visit(e.batches), visit(e.rounds), visit(e.pathsPerFrame), visit(e.target), visit(stop);
}

/**
 * Gives every rank the figures of the chunk that one rank (`mine`) solved: a sum over ranks
 * of doubles where the others give zeros, exact for the counts (below 2^53) and the rest.
 * The error summary's per-frame figures stay behind: each frame's come with it.
 */
void exchangeFigures(const SolverOptions& options, bool mine, SolverStatistics& statistics,
  ErrorEstimateSummary& errors, double& seconds)
{
  std::uint64_t stop = 0;
  for (std::size_t i = 0; i < StopReasons.size(); ++i)
  {
    stop = errors.stoppedBy == StopReasons[i] ? i : stop;
  }
  std::vector<double> values;
  visitChunkFigures(statistics, errors, stop,
    [&](auto& field) { values.push_back(mine ? static_cast<double>(field) : 0.0); });
  const auto begin = std::chrono::steady_clock::now();
  options.sumDoublesAcrossRanks(values.data(), values.size());
  seconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - begin).count();
  std::size_t next = 0;
  visitChunkFigures(statistics, errors, stop,
    [&](auto& field)
    {
      using T = std::decay_t<decltype(field)>;
      if constexpr (std::is_same<T, bool>::value)
      {
        field = values[next++] != 0;
      }
      else
      {
        field = static_cast<T>(values[next++]);
      }
    });
  errors.stoppedBy = StopReasons[std::min<std::size_t>(stop, StopReasons.size() - 1)];
  errors.relativeErrorMedian.clear();
  errors.relativeErrorP95.clear();
  errors.litElements.clear();
}

/// Gives every rank the sides one rank (`mine`) chose; the others give Front (0).
void exchangeSides(
  const SolverOptions& options, bool mine, std::vector<Side>& sides, double& seconds)
{
  std::vector<std::int64_t> values(sides.size(), 0);
  if (mine)
  {
    std::transform(sides.begin(), sides.end(), values.begin(),
      [](Side side) { return static_cast<std::int64_t>(side); });
  }
  sumAcrossRanks(options, values.data(), values.size(), seconds);
  std::transform(values.begin(), values.end(), sides.begin(),
    [](std::int64_t v) { return v == 0 ? Side::Front : Side::Back; });
}

/// Gives every rank the frames of `frames` that one rank filled (the others give zeros).
void exchangeFrames(const SolverOptions& options, Solution& frames, double& seconds)
{
  for (StoredArray* data :
    { &frames.directData(), &frames.indirectData(), &frames.stdErrorData(), &frames.patchData() })
  {
    sumStoredAcrossRanks(options, data->data(), data->size(), seconds);
  }
}

/// Per element side and position of a chunk, in solveCost's units, past its solve: its
/// estimates blended at the seams, its sides' totals and each frame's error figures (measured
/// with solveCost's figures, Documentation/Performance.md, "Progress").
constexpr double ChunkSideFrameCost = 0.2;

/// The expected cost of chunk `chunk`'s solve and of finishing its frames.
double chunkCost(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ChunkPlan& plan, std::size_t chunk)
{
  const std::size_t positions = plan.chunks[chunk].solveEnd - plan.chunks[chunk].solveBegin;
  return solveCost(scene, rig, options, positions) +
    ChunkSideFrameCost * elementSides(scene, options) * static_cast<double>(positions);
}
}

double chunksCost(
  const Scene& scene, const LightRig& rig, const SolverOptions& options, std::size_t framesPerChunk)
{
  const ChunkPlan plan =
    planChunks(frameCount(rig, scene.hasEmission()), framesPerChunk, options.chunkOverlap);
  if (plan.chunks.size() == 1)
  {
    return solveCost(scene, rig, options);
  }
  double cost = 0;
  for (std::size_t k = 0; k < plan.chunks.size(); ++k)
  {
    cost += chunkCost(scene, rig, options, plan, k);
  }
  return cost;
}

Solution solveInChunks(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  std::size_t framesPerChunk, const ProgressCallback& progress, const ChunkFramesCallback& onFrames,
  const FirstChunkFigure& figure, const SolveSetup* givenSetup)
{
  const std::size_t frames = frameCount(rig, scene.hasEmission());
  const ChunkPlan plan = planChunks(frames, framesPerChunk, options.chunkOverlap);
  if (plan.chunks.size() == 1)
  {
    // A setup of the whole rig probes what the solve would: the same sides, the same bits.
    Solution solution = givenSetup ? solve(scene, rig, options, progress, *givenSetup)
                                   : solve(scene, rig, options, progress);
    if (givenSetup)
    {
      solution.statistics.reachabilityRays += givenSetup->reachabilityRays();
      solution.statistics.secondsSetup += givenSetup->seconds();
    }
    solution.statistics.framesPerChunk = frames;
    if (onFrames)
    {
      Solution statistics;
      statistics.statistics = solution.statistics;
      statistics.errorEstimate = solution.errorEstimate;
      statistics.warnings = solution.warnings;
      onFrames(0, solution);
      return statistics;
    }
    return solution;
  }

  // Streamed over several ranks, with a chunk for each at least, the ranks take whole chunks:
  // rank r solves chunks r, r + R, ... alone, and hands on their frames only.
  const std::size_t chunkCount = plan.chunks.size();
  const bool overRanks = static_cast<bool>(onFrames) && options.ranks > 1 &&
    chunkCount >= static_cast<std::size_t>(options.ranks);
  const std::size_t ranks = overRanks ? static_cast<std::size_t>(options.ranks) : 1;
  const std::size_t rank = overRanks ? static_cast<std::size_t>(options.rank) : 0;
  SolverOptions chunkOptions = options;
  // The chunks' results are blended and handed on as stored: in the whole rig's unit.
  chunkOptions.storageScale = storageScaleFor(scene, rig);
  if (overRanks)
  {
    chunkOptions.ranks = 1;
    chunkOptions.rank = 0;
  }

  // Progress: the setup (unless given), then each chunk, by their expected cost.
  const double setupCost = givenSetup ? 0.0 : SolveSetup::cost(scene, options);
  double solvesCost = 0;
  for (std::size_t k = rank; k < chunkCount; k += ranks)
  {
    solvesCost += chunkCost(scene, rig, options, plan, k);
  }
  const double totalCost = setupCost + solvesCost;
  std::optional<SolveSetup> ownSetup;
  if (!givenSetup)
  {
    agreeAcrossRanks(options,
      [&]
      {
        ownSetup.emplace(scene, rig, options,
          [&](double f) { return !progress || progress(f * setupCost / totalCost); });
      });
  }
  const SolveSetup* setup = givenSetup ? givenSetup : &*ownSetup;
  Solution whole; // every frame, without onFrames
  Solution result;
  SolverStatistics& stats = result.statistics;
  stats.frames = frames;
  ErrorEstimateSummary errors;
  std::vector<Side> litSides, patchLitSides;
  std::vector<std::string> warnings;
  // Streamed, every frame shows the side the first chunk chose; the sums of every chunk say
  // whether the whole animation would have chosen another (a warning).
  std::vector<Solution::SideTotals> animationTotals;
  // The chunks that missed a target, from every chunk's figures (over ranks, exchanged).
  std::size_t missed = 0;
  std::set<std::string> missedBy;
  std::vector<std::uint64_t> chunkBatches;
  if (options.chunkOverlap > plan.overlap)
  {
    warnings.push_back("the chunk overlap of " + std::to_string(options.chunkOverlap) +
      " frames is more than half of the " + std::to_string(plan.framesPerChunk) +
      " frames per chunk chosen: each seam blends over " + std::to_string(plan.overlap) +
      " frames on each side (give longer chunks, or more memory, for more)");
  }
  // The estimate of the frames around the seam before this rank's next chunk, which that
  // chunk blends with, and (over ranks) a solved chunk's shape for the seams received.
  std::optional<Solution> tail;
  std::size_t tailFirst = 0;
  Solution shape;
  double progressBase = setupCost / totalCost;
  double secondsExchanging = 0;
  double firstFigure = 0;
  const auto start = std::chrono::steady_clock::now();
  for (std::size_t round = 0; round * ranks < chunkCount; ++round)
  {
    const std::size_t k = round * ranks + rank;
    const bool solving = k < chunkCount;
    Solution current;
    if (solving)
    {
      const ChunkPlan::Chunk& c = plan.chunks[k];
      const std::size_t positions = c.solveEnd - c.solveBegin;
      const double share = chunkCost(scene, rig, options, plan, k) / totalCost;
      ProgressCallback chunkProgress;
      if (progress)
      {
        chunkProgress = [&, base = progressBase, share](double f)
        { return progress(base + share * f); };
      }
      progressBase += share;
      if (options.timeLimitSeconds > 0)
      {
        // The limit is the whole solve's, shared among this rank's chunks still to solve: a
        // chunk given the whole limit would let 100 chunks take 100 times it.
        const double left = options.timeLimitSeconds -
          std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        const std::size_t chunksLeft = (chunkCount - 1 - k) / ranks + 1;
        chunkOptions.timeLimitSeconds = std::max(1e-3, left / static_cast<double>(chunksLeft));
      }
      if (options.log)
      {
        options.log("chunk " + std::to_string(k + 1) + " of " + std::to_string(chunkCount) +
          ": frames " + std::to_string(c.begin) + " to " + std::to_string(c.end - 1) +
          ", solving positions " + std::to_string(c.solveBegin) + " to " +
          std::to_string(c.solveEnd - 1) +
          (options.timeLimitSeconds > 0 ? ", within " +
                formatNumber(std::round(chunkOptions.timeLimitSeconds * 1000) / 1000) + " s"
                                        : std::string()));
      }
      // Over ranks a chunk is solved alone; a failure or cancel on any rank stops every rank
      // here, before the exchange.
      chunkOptions.firstFrame = c.solveBegin;
      auto solveChunk = [&]
      {
        current =
          solve(scene, sliceRig(rig, c.solveBegin, positions), chunkOptions, chunkProgress, *setup);
      };
      if (overRanks)
      {
        agreeAcrossRanks(options, solveChunk, &secondsExchanging);
      }
      else
      {
        solveChunk();
      }
      for (const std::string& w : current.warnings)
      {
        if (w.rfind(TargetNotReached, 0) == 0)
        {
          continue; // one warning for the chunks that missed the target, after them all
        }
        if (std::find(warnings.begin(), warnings.end(), w) == warnings.end())
        {
          warnings.push_back(w);
        }
      }
      if (overRanks && shape.elementCount() == 0)
      {
        shape = shapedLike(current, 1);
      }
      if (onFrames)
      {
        const std::vector<Solution::SideTotals> totals =
          current.surfaceTotals(scene, resolveThreadCount(options.threads));
        animationTotals.resize(totals.size());
        for (std::size_t r = 0; r < totals.size(); ++r)
        {
          animationTotals[r] += totals[r];
        }
      }
    }
    else
    {
      agreeAcrossRanks(
        options, [] {}, &secondsExchanging);
    }

    // This rank's chunk is finished as soon as the seam before it is here (rank 0's from the
    // round before, rank r's from slot r - 1), so that no more than the two estimates of a
    // seam and the finished frames are held at once.
    std::optional<Solution> before = std::move(tail);
    std::size_t beforeFirst = tailFirst;
    tail.reset();
    auto finishMine = [&]
    {
      const Estimate seam{ before ? &*before : nullptr, beforeFirst };
      if (onFrames)
      {
        Solution finished = handedOn(plan, k, seam, current, litSides, patchLitSides);
        before.reset();
        if (k == 0 && figure.compute)
        {
          firstFigure = figure.compute(finished);
          if (figure.receive)
          {
            figure.receive(firstFigure);
          }
        }
        onFrames(plan.finishedBegin(k), finished);
      }
      else
      {
        finishFrames(plan, k, seam, { &current, plan.chunks[k].solveBegin }, plan.finishedBegin(k),
          plan.finishedEnd(k), { &whole, 0 });
        before.reset();
      }
    };
    if (solving && k == 0)
    {
      litSides = current.litSideData();
      patchLitSides = current.patchLitSideData();
      if (!onFrames)
      {
        whole = shapedLike(current, frames);
      }
    }
    if (solving && rank == 0)
    {
      finishMine();
    }

    // The figures and the seams of this round's chunks, in chunk order on every rank: each
    // from the rank that solved it (over ranks, a sum where the others give zeros).
    for (std::size_t slot = 0; slot < ranks && round * ranks + slot < chunkCount; ++slot)
    {
      const std::size_t j = round * ranks + slot;
      const bool mine = slot == rank;
      const ChunkPlan::Chunk& cj = plan.chunks[j];
      SolverStatistics chunkStatistics = mine ? current.statistics : SolverStatistics();
      ErrorEstimateSummary chunkErrors = mine ? current.errorEstimate : ErrorEstimateSummary();
      if (overRanks)
      {
        exchangeFigures(options, mine, chunkStatistics, chunkErrors, secondsExchanging);
      }
      accumulate(chunkStatistics, j == 0, stats);
      if (chunkErrors.batches > 0 && options.targetRelativeError > 0 &&
        chunkErrors.stoppedBy != "target")
      {
        ++missed;
        missedBy.insert(chunkErrors.stoppedBy);
      }
      if (chunkErrors.batches > 0)
      {
        accumulate(chunkErrors, j == 0, errors);
      }
      chunkBatches.push_back(chunkErrors.batches);
      if (j == 0 && overRanks)
      {
        litSides.resize(scene.elementCount(), Side::Front);
        patchLitSides.resize(scene.patchCount(), Side::Front);
        exchangeSides(options, mine, litSides, secondsExchanging);
        exchangeSides(options, mine, patchLitSides, secondsExchanging);
        if (onFrames && figure.compute)
        {
          // From the first chunk's rank, which computed it before the slots (a sum where the
          // others give zero, exact), before the other ranks finish their first chunks.
          double value = mine ? firstFigure : 0.0;
          options.sumDoublesAcrossRanks(&value, 1);
          if (!mine && figure.receive)
          {
            figure.receive(value);
          }
        }
      }
      // The estimate of the seam after chunk j, for the rank of the chunk after it.
      const bool forMe = (j + 1) % ranks == rank;
      if (j + 1 < chunkCount && (mine || forMe || overRanks))
      {
        const std::size_t seamFirst = plan.finishedEnd(j);
        Solution seam = shapedLike(mine ? current : shape, cj.solveEnd - seamFirst);
        if (mine)
        {
          copyFrames({ &current, cj.solveBegin }, seamFirst, cj.solveEnd, { &seam, seamFirst });
        }
        if (overRanks)
        {
          exchangeFrames(options, seam, secondsExchanging);
        }
        if (forMe && j + 1 == k)
        {
          before = std::move(seam);
          beforeFirst = seamFirst;
          finishMine();
        }
        else if (forMe)
        {
          tail = std::move(seam);
          tailFirst = seamFirst;
        }
      }
      if (mine)
      {
        current = Solution();
      }
    }
  }
  stats.secondsReducing += secondsExchanging;
  stats.reachabilityRays += setup->reachabilityRays();
  stats.secondsSetup += setup->seconds();
  // A chunk where every light is off (a night) warns that no light arrived; the animation
  // only when none arrived anywhere.
  if (stats.firstHits > 0)
  {
    warnings.erase(std::remove_if(warnings.begin(), warnings.end(),
                     [](const std::string& w) { return w.rfind("no light reached", 0) == 0; }),
      warnings.end());
  }
  if (onFrames && chunkCount > 1)
  {
    if (overRanks)
    {
      std::vector<double> sums(4 * scene.regionCount(), 0.0);
      for (std::size_t r = 0; r < animationTotals.size(); ++r)
      {
        const Solution::SideTotals& t = animationTotals[r];
        std::copy_n(
          std::array<double, 4>{ t.front, t.back, t.irradianceFront, t.irradianceBack }.begin(), 4,
          sums.begin() + static_cast<std::ptrdiff_t>(4 * r));
      }
      options.sumDoublesAcrossRanks(sums.data(), sums.size());
      animationTotals.assign(scene.regionCount(), Solution::SideTotals());
      for (std::size_t r = 0; r < animationTotals.size(); ++r)
      {
        animationTotals[r] = { sums[4 * r], sums[4 * r + 1], sums[4 * r + 2], sums[4 * r + 3] };
      }
    }
    std::vector<bool> flipped(animationTotals.size(), false);
    double flippedArea = 0, area = 0;
    for (std::size_t p = 0; p < scene.patchCount() && !animationTotals.empty(); ++p)
    {
      const Solution::SideTotals& t = animationTotals[scene.patchRegion(p)];
      area += scene.patchArea(p);
      if (Solution::litSideOf(t.front, t.back, t.irradianceFront, t.irradianceBack) !=
        patchLitSides[p])
      {
        flipped[scene.patchRegion(p)] = true;
        flippedArea += scene.patchArea(p);
      }
    }
    const auto surfaces =
      static_cast<std::size_t>(std::count(flipped.begin(), flipped.end(), true));
    if (surfaces > 0)
    {
      warnings.push_back(countOf(surfaces, "surface") + " (" +
        percent(area > 0 ? flippedArea / area : 0) + " of the scene's area) " +
        (surfaces == 1 ? "shows" : "show") +
        " the side the first chunk lit more, while over the whole animation the other side "
        "received more light: Radiosity, Color, Irradiance and their standard errors are of "
        "that first chunk's side in every frame" +
        (options.twoSided ? " (RadiosityFront, RadiosityBack, IrradianceFront and "
                            "IrradianceBack hold both sides)"
                          : "") +
        ". Solved in one chunk (more memory, or fewer frames), the animation's side is shown");
    }
  }
  if (missed > 0)
  {
    std::string by;
    for (const std::string& reason : missedBy)
    {
      by += (by.empty() ? "the " : " and the ") + reason;
    }
    warnings.push_back(std::string(TargetNotReached) + " " + percent(options.targetRelativeError) +
      " was not reached in " + std::to_string(missed) + " of " + countOf(chunkCount, "chunk") +
      ": " + by + " stopped " + (missed == 1 ? "it" : "them") +
      "; each frame's p95 relative error is in the field data RelativeErrorP95 (--stats)");
  }
  Solution& out = onFrames ? result : whole;
  if (!onFrames)
  {
    whole.chooseLitSides(scene, resolveThreadCount(options.threads));
    summariseErrors(whole, errors);
  }
  else
  {
    out.errorEstimate = errors;
  }
  if (out.errorEstimate.batches > 0)
  {
    out.errorEstimate.chunkBatches = std::move(chunkBatches);
  }
  out.statistics = stats;
  out.statistics.frames = frames;
  out.statistics.chunks = plan.chunks.size();
  out.statistics.framesPerChunk = plan.framesPerChunk;
  out.statistics.chunkOverlap = plan.overlap;
  out.statistics.meanPathLength = stats.pathsCast > 0 ? 1.0 +
      (static_cast<double>(stats.shootingRays) / static_cast<double>(stats.pathsCast) - 1.0) /
        options.firstBounceSurvival
                                                      : 0.0;
  out.statistics.secondsTotal =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  out.warnings = std::move(warnings);
  return std::move(out);
}

Solution solveChunk(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  std::size_t framesPerChunk, std::size_t chunk, const std::vector<Side>& litSides,
  const std::vector<Side>& patchLitSides, const std::vector<std::uint64_t>& chunkBatches,
  const ProgressCallback& progress)
{
  const std::size_t frames = frameCount(rig, scene.hasEmission());
  const ChunkPlan plan = planChunks(frames, framesPerChunk, options.chunkOverlap);
  if (chunk >= plan.chunks.size())
  {
    throw Error("chunk " + std::to_string(chunk) + " of an animation in " +
      std::to_string(plan.chunks.size()) + " chunks");
  }
  if (!chunkBatches.empty() && chunkBatches.size() != plan.chunks.size())
  {
    throw Error("the batches of " + countOf(chunkBatches.size(), "chunk") +
      " for an animation in " + countOf(plan.chunks.size(), "chunk"));
  }
  // The chunk before, for its estimate of the seam between them; then this chunk, in the unit
  // of the first solve (solveInChunks).
  SolverOptions chunkOptions = options;
  chunkOptions.storageScale = storageScaleFor(scene, rig);
  const std::size_t first = chunk > 0 ? chunk - 1 : chunk;
  // The setup of the whole animation, as solveInChunks has it, then the chunks, by their
  // expected cost.
  std::vector<double> costs{ SolveSetup::cost(scene, options) };
  for (std::size_t k = first; k <= chunk; ++k)
  {
    costs.push_back(chunkCost(scene, rig, options, plan, k));
  }
  const double total = std::accumulate(costs.begin(), costs.end(), 0.0);
  double base = 0;
  auto part = [&](double cost) -> ProgressCallback
  {
    const double from = base, share = cost / total;
    base += share;
    if (!progress)
    {
      return {};
    }
    return [&progress, from, share](double f) { return progress(from + share * f); };
  };
  const SolveSetup setup(scene, rig, options, part(costs[0]));
  std::optional<Solution> seam;
  for (std::size_t k = first; k <= chunk; ++k)
  {
    const ChunkPlan::Chunk& c = plan.chunks[k];
    chunkOptions.firstFrame = c.solveBegin;
    if (!chunkBatches.empty())
    {
      // The first solve's rounds, whatever the time they take now.
      chunkOptions.timeLimitSeconds = 0;
      chunkOptions.batchLimit = chunkBatches[k];
    }
    Solution current = solve(scene, sliceRig(rig, c.solveBegin, c.solveEnd - c.solveBegin),
      chunkOptions, part(costs[1 + k - first]), setup);
    if (k < chunk)
    {
      const std::size_t seamFirst = plan.finishedEnd(k);
      seam.emplace(shapedLike(current, c.solveEnd - seamFirst));
      copyFrames({ &current, c.solveBegin }, seamFirst, c.solveEnd, { &*seam, seamFirst });
      continue;
    }
    return handedOn(plan, chunk, { seam ? &*seam : nullptr, plan.finishedEnd(first) }, current,
      litSides, patchLitSides);
  }
  return Solution();
}

} // namespace mlr
