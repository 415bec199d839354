#include "ErrorEstimate.h"

#include "Error.h"
#include "MemoryBudget.h"
#include "MemoryPlan.h"
#include "Parallel.h"
#include "Ranks.h"
#include "Shooting.h"
#include "ZeroedMemory.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>
#include <string>

namespace mlr
{

namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

std::uint64_t splitMix(std::uint64_t z)
{
  z += 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// Element or patch sides per task of the merge: the merge is element-wise, so any split
/// gives the same bits.
constexpr std::size_t MergeSidesPerTask = 4096;

/// Whether every value of a batch's row is zero: a side no path reached in that batch.
bool zeroRow(const PackedRgb* values, std::size_t count)
{
  std::uint32_t any = 0;
  for (std::size_t i = 0; i < count; ++i)
  {
    any |= static_cast<std::uint32_t>(values[i].r | values[i].g | values[i].b);
  }
  return any == 0;
}

/**
 * The mean of the batches so far and the sum of squared deviations of their total
 * irradiance (Welford's update, in batch order), per element side and frame, and the mean of
 * the patches' bounced light. The running mean is kept in single precision, where an update
 * of one batch in thousands still counts, and the result's stored arrays get it rounded once,
 * when the solve reads it (publish()): after a round, not after every batch. The sums of
 * squared deviations are in single precision too: each is a sum of non-negative terms, in
 * batch order, and a standard error needs two significant digits, where single precision
 * keeps six over thousands of batches.
 *
 * A side's frames are a row. A row that every batch so far left at zero (a side no light
 * reaches: the outside of a closed room, the inside of a block) has a zero mean and spread,
 * which a zero batch keeps: the merge skips it, and its running sums, fresh mappings, take no
 * memory until a batch brings light there. Skipping changes no bit.
 */
class BatchSpread
{
public:
  BatchSpread(Solution& result, int workers)
    : Result(result)
    , Workers(workers)
    , Frames(std::max<std::size_t>(result.frameCount(), 1))
    , MeanDirect(result.directData().size())
    , MeanIndirect(result.directData().size())
    , MeanPatch(result.patchData().size())
    , SquaredDeviations(result.directData().size())
    , ElementRowSeen(result.directData().size() / Frames)
    , PatchRowSeen(result.patchData().size() / Frames)
  {
  }

  std::uint64_t count() const { return this->Count; }

  /// Merges batch number count() + 1. Every element side and frame is updated on its own, so
  /// the bits do not depend on the workers.
  void add(Solution& batch)
  {
    ++this->Count;
    const double inverse = 1.0 / static_cast<double>(this->Count);
    const StoredArray& batchDirect = batch.directData();
    const StoredArray& batchIndirect = batch.indirectData();
    const StoredArray& batchPatch = batch.patchData();
    const std::size_t frames = this->Frames;
    this->forEachRow(
      [&](std::size_t row)
      {
        const std::size_t begin = row * frames, end = begin + frames;
        if (!this->ElementRowSeen[row])
        {
          if (zeroRow(&batchDirect[begin], frames) && zeroRow(&batchIndirect[begin], frames))
          {
            return;
          }
          this->ElementRowSeen[row] = 1;
        }
        for (std::size_t i = begin; i < end; ++i)
        {
          const Rgb xDirect = batchDirect[i], xIndirect = batchIndirect[i];
          const Rgb meanDirect = this->MeanDirect[i], meanIndirect = this->MeanIndirect[i];
          const Rgb before = meanDirect + meanIndirect;
          this->MeanDirect[i] = FloatRgb(meanDirect + (xDirect - meanDirect) * inverse);
          this->MeanIndirect[i] = FloatRgb(meanIndirect + (xIndirect - meanIndirect) * inverse);
          const Rgb after = Rgb(this->MeanDirect[i]) + Rgb(this->MeanIndirect[i]);
          const Rgb x = xDirect + xIndirect;
          this->SquaredDeviations[i] =
            FloatRgb(Rgb(this->SquaredDeviations[i]) + (x - before) * (x - after));
        }
      },
      [&](std::size_t row)
      {
        const std::size_t begin = row * frames, end = begin + frames;
        if (!this->PatchRowSeen[row])
        {
          if (zeroRow(&batchPatch[begin], frames))
          {
            return;
          }
          this->PatchRowSeen[row] = 1;
        }
        for (std::size_t i = begin; i < end; ++i)
        {
          const Rgb mean = this->MeanPatch[i];
          this->MeanPatch[i] = FloatRgb(mean + (Rgb(batchPatch[i]) - mean) * inverse);
        }
      });
  }

  /// Rounds the running mean into the result's stored arrays (zero where no batch brought
  /// light, as they are), for whatever reads the result next: the lit sides, a round's error
  /// figures, the caller.
  void publish()
  {
    StoredArray& direct = this->Result.directData();
    StoredArray& indirect = this->Result.indirectData();
    StoredArray& patch = this->Result.patchData();
    this->forEachLitRow(
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t i = begin; i < end; ++i)
        {
          direct[i] = PackedRgb(this->MeanDirect[i]);
          indirect[i] = PackedRgb(this->MeanIndirect[i]);
        }
      },
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t i = begin; i < end; ++i)
        {
          patch[i] = PackedRgb(this->MeanPatch[i]);
        }
      });
  }

  /// Writes every element side and frame's standard error into the result's (zero) array.
  void publishStdErrors()
  {
    StoredArray& stdError = this->Result.stdErrorData();
    stdError = StoredArray(this->MeanDirect.size());
    this->forEachLitRow(
      [&](std::size_t begin, std::size_t end)
      {
        for (std::size_t i = begin; i < end; ++i)
        {
          stdError[i] = PackedRgb(this->stdError(i));
        }
      },
      [](std::size_t, std::size_t) {});
  }

  /// The standard error of the mean irradiance at storage index i, in the storage unit (the
  /// batches are the result's scene's: Solution::storageScale): the batches' unbiased
  /// standard deviation over sqrt(B).
  Rgb stdError(std::size_t i) const
  {
    if (this->Count < 2)
    {
      return Rgb();
    }
    const double n = static_cast<double>(this->Count);
    const Rgb m2 = this->SquaredDeviations[i];
    const double scale = 1.0 / ((n - 1) * n);
    return Rgb(std::sqrt(std::max(0.0, m2.r * scale)), std::sqrt(std::max(0.0, m2.g * scale)),
      std::sqrt(std::max(0.0, m2.b * scale)));
  }

  /// The irradiance's standard error of an element side in a frame.
  Rgb irradianceStdError(std::size_t frame, std::size_t element, Side side) const
  {
    return this->stdError(this->Result.elementIndex(frame, element, side)) *
      this->Result.storageScale();
  }

private:
  using Sums = std::vector<FloatRgb, ZeroedAllocator<FloatRgb>>;

  /// Calls `elementRow` on every element side's row and `patchRow` on every patch side's, on
  /// the workers, in blocks of MergeSidesPerTask rows.
  template <typename ElementRow, typename PatchRow>
  void forEachRow(const ElementRow& elementRow, const PatchRow& patchRow)
  {
    const std::size_t elementRows = this->ElementRowSeen.size();
    const std::size_t patchRows = this->PatchRowSeen.size();
    const std::size_t elementTasks = (elementRows + MergeSidesPerTask - 1) / MergeSidesPerTask;
    const std::size_t patchTasks = (patchRows + MergeSidesPerTask - 1) / MergeSidesPerTask;
    parallelFor(
      elementTasks + patchTasks, this->Workers,
      [&](std::size_t task, int)
      {
        const bool element = task < elementTasks;
        const std::size_t first = (element ? task : task - elementTasks) * MergeSidesPerTask;
        const std::size_t last =
          std::min(element ? elementRows : patchRows, first + MergeSidesPerTask);
        for (std::size_t row = first; row < last; ++row)
        {
          if (element)
          {
            elementRow(row);
          }
          else
          {
            patchRow(row);
          }
        }
      },
      [](std::size_t) { return true; });
  }

  /// forEachRow over the rows some batch lit, each as its range of storage indices.
  template <typename ElementRange, typename PatchRange>
  void forEachLitRow(const ElementRange& elementRange, const PatchRange& patchRange)
  {
    const std::size_t frames = this->Frames;
    this->forEachRow(
      [&](std::size_t row)
      {
        if (this->ElementRowSeen[row])
        {
          elementRange(row * frames, (row + 1) * frames);
        }
      },
      [&](std::size_t row)
      {
        if (this->PatchRowSeen[row])
        {
          patchRange(row * frames, (row + 1) * frames);
        }
      });
  }

  Solution& Result;
  int Workers;
  std::size_t Frames;
  std::uint64_t Count = 0;
  Sums MeanDirect, MeanIndirect, MeanPatch, SquaredDeviations;
  /// Whether a batch brought light to the row: 1 byte per side, written by the one worker
  /// that merges its row.
  std::vector<std::uint8_t> ElementRowSeen, PatchRowSeen;
};

std::string seconds(double value)
{
  std::ostringstream s;
  s.precision(3);
  s << value << " s";
  return s.str();
}

/// The worst p95 over frames, and its frame.
std::pair<double, std::size_t> worstFrame(const Solution& result, const BatchSpread& spread)
{
  std::pair<double, std::size_t> worst{ 0.0, 0 };
  for (std::size_t f = 0; f < result.frameCount(); ++f)
  {
    const FrameError e = frameError(result, f,
      [&](std::size_t element, Side side) { return spread.irradianceStdError(f, element, side); });
    if (e.p95 > worst.first)
    {
      worst = { e.p95, f };
    }
  }
  return worst;
}
}

std::string percent(double fraction)
{
  std::ostringstream s;
  s.precision(3);
  s << 100 * fraction << "%";
  return s.str();
}

void validateErrorOptions(const SolverOptions& options)
{
  if (options.errorBatches < 1 || options.errorBatches > MaximumErrorBatches)
  {
    throw Error("the error batch count (ErrorBatches, --error-batches) is " +
      std::to_string(options.errorBatches) + ": give 1 (no error estimate) up to " +
      std::to_string(MaximumErrorBatches) + " (16 is typical)");
  }
  if (options.errorBatches > options.pathsPerFrame)
  {
    throw Error("the paths per frame (NumberOfPaths, --paths), " +
      std::to_string(options.pathsPerFrame) + ", cannot make " +
      std::to_string(options.errorBatches) +
      " error batches (ErrorBatches, --error-batches): give at least as many paths as batches, "
      "or fewer batches");
  }
  if (!(options.targetRelativeError >= 0) || !std::isfinite(options.targetRelativeError))
  {
    throw Error("the target relative error (TargetRelativeError, --target-error) is " +
      formatNumber(options.targetRelativeError) +
      ": give 0 (no target) or a fraction such as 0.02 (2%)");
  }
  if (options.targetRelativeError > 0 && options.targetRelativeError < MinimumTargetRelativeError)
  {
    throw Error("the target relative error (TargetRelativeError, --target-error) is " +
      formatNumber(options.targetRelativeError) +
      ": below 0.0001 no solve would finish; give 0 (no target) or a fraction such as 0.02");
  }
  if (options.targetRelativeError >= 1)
  {
    // One batch holding all of an element's light gives SE = mean, its largest.
    throw Error("the target relative error (TargetRelativeError, --target-error) is " +
      formatNumber(options.targetRelativeError) +
      ": the batches' relative error is at most 1 (100%), so every solve would meet it; give "
      "a fraction below 1 such as 0.02 (2%), or 0 (no target)");
  }
  if (options.targetRelativeError > 0 && options.errorBatches < 2)
  {
    throw Error("a target relative error needs an error estimate: give 2 error batches or "
                "more (ErrorBatches, --error-batches; 16 is typical)");
  }
  if (!(options.timeLimitSeconds >= 0) || !std::isfinite(options.timeLimitSeconds))
  {
    throw Error("the time limit (TimeLimit, --time-limit) is " +
      formatNumber(options.timeLimitSeconds) + " s: give 0 (no limit) or a number of seconds");
  }
}

std::uint64_t pathsOfBatch(std::uint64_t paths, std::uint64_t batches, std::uint64_t batch)
{
  const std::uint64_t b = batch % batches;
  return paths / batches + (b < paths % batches ? 1 : 0);
}

std::uint64_t batchSeed(std::uint64_t seed, std::uint64_t batch)
{
  return batch == 0 ? seed : splitMix(seed ^ splitMix(batch ^ 0x6a09e667f3bcc909ULL));
}

void checkBatchPathsPerPosition(const LightSource& source, const SolverOptions& options)
{
  if (!estimatesError(options))
  {
    checkPathsPerPosition(source, options);
    return;
  }
  SolverOptions smallest = options;
  smallest.pathsPerFrame = options.pathsPerFrame / options.errorBatches;
  try
  {
    checkPathsPerPosition(source, smallest);
  }
  catch (const Error& e)
  {
    throw Error(std::string(e.what()) + " (each of the " + std::to_string(options.errorBatches) +
      " error batches has " + std::to_string(smallest.pathsPerFrame) +
      " paths per frame: give more paths or fewer batches)");
  }
}

std::uint64_t errorEstimateBytes(std::size_t patches, std::size_t elements, std::size_t frames,
  const SolverOptions& options, const std::vector<std::uint8_t>* reachable)
{
  if (!estimatesError(options))
  {
    return 0;
  }
  // BatchSpread merges, and writes, only the sides a batch lit: those light reaches.
  const bool perPatch = elements == patches * Scene::ElementsPerPatch;
  auto elementArray = [&](std::size_t valueBytes)
  {
    return perPatch
      ? writtenResultBytes(patches, Scene::ElementsPerPatch, frames, reachable, valueBytes)
      : saturatingProduct({ frames, elements, 2, valueBytes });
  };
  auto patchArray = [&](std::size_t valueBytes)
  { return writtenResultBytes(patches, 1, frames, reachable, valueBytes); };
  // The mean in the result's stored arrays and in single precision, direct and indirect; the
  // patches' the same; the flags of the sides a batch lit.
  const std::uint64_t mean =
    saturatingSum(saturatingSum(saturatingProduct(elementArray(sizeof(PackedRgb)), 2),
                    saturatingProduct(elementArray(sizeof(FloatRgb)), 2)),
      saturatingSum(saturatingSum(patchArray(sizeof(PackedRgb)), patchArray(sizeof(FloatRgb))),
        saturatingProduct({ 2, saturatingSum(elements, patches) })));
  // The squared deviations and the standard errors.
  const std::uint64_t spread =
    saturatingSum(elementArray(sizeof(FloatRgb)), elementArray(sizeof(PackedRgb)));
  return saturatingSum(mean, spread);
}

FrameError frameError(const Solution& solution, std::size_t frame,
  const std::function<Rgb(std::size_t element, Side side)>& stdError)
{
  const std::size_t elements = solution.elementCount();
  std::vector<double> totals(elements);
  double sum = 0;
  for (std::size_t e = 0; e < elements; ++e)
  {
    // The light arriving, not the radiosity: black surfaces have illuminance to judge too, and
    // an emitter's own emission, which is exact, would call it lit and accurate whatever light
    // reaches it. Where rho_e > 0 the relative error is the reflected radiosity's.
    totals[e] = solution.irradiance(frame, e, solution.litSide(e)).sum();
    sum += totals[e];
  }
  const double threshold =
    LitFractionOfMean * sum / static_cast<double>(std::max<std::size_t>(elements, 1));
  std::vector<double> relative;
  for (std::size_t e = 0; e < elements; ++e)
  {
    if (totals[e] > threshold && totals[e] > 0)
    {
      relative.push_back(stdError(e, solution.litSide(e)).sum() / totals[e]);
    }
  }
  return relativeErrorFigures(relative);
}

FrameError relativeErrorFigures(std::vector<double>& relative)
{
  FrameError result;
  result.litElements = relative.size();
  if (relative.empty())
  {
    return result;
  }
  // Nearest rank: the smallest value with at least the fraction q of the values at or below.
  auto rank = [&](double q)
  {
    const auto k = static_cast<std::size_t>(
      std::max(1.0, std::ceil(q * static_cast<double>(relative.size()))) - 1);
    std::nth_element(
      relative.begin(), relative.begin() + static_cast<std::ptrdiff_t>(k), relative.end());
    return relative[k];
  };
  result.median = rank(0.5);
  result.p95 = rank(0.95);
  return result;
}

std::uint64_t nextBatchCount(std::uint64_t batches, double p95, double target)
{
  const double wanted = 1.1 * (p95 / target) * (p95 / target);
  const double growth = std::clamp(wanted, MinimumRoundGrowth, MaximumRoundGrowth);
  const auto next = static_cast<std::uint64_t>(std::ceil(static_cast<double>(batches) * growth));
  return std::max(next, batches + 1);
}

void solveInBatches(const Scene& scene, const SolverOptions& options, const BatchSolve& solveBatch,
  const std::function<bool(double fraction)>& progress, std::uint64_t memoryBytes,
  double& secondsReducing, Solution& result)
{
  const auto start = Clock::now();
  const std::uint64_t roundBatches = options.errorBatches;
  const double target = options.targetRelativeError;
  auto log = [&](const std::string& message)
  {
    if (options.log)
    {
      options.log(message);
    }
  };
  {
    std::ostringstream s;
    s << "error estimate: " << roundBatches << " batches of about "
      << options.pathsPerFrame / roundBatches << " paths per frame";
    if (target > 0)
    {
      s << ", more rounds until the lit elements' p95 relative error is at most " << percent(target)
        << " in every frame";
    }
    s << "; memory estimate " << gibibytes(memoryBytes)
      << " (more rounds need no more); the time is estimated after the first batch";
    log(s.str());
  }
  result.allocateIndirect();
  const int workers = resolveThreadCount(options.threads);
  BatchSpread spread(result, workers);
  ErrorEstimateSummary& summary = result.errorEstimate;
  summary.target = target;
  summary.rounds = 1;
  std::uint64_t planned = roundBatches;
  double shown = 0;
  // Every rank stops at the same batch: the first rank out of time stops all.
  auto outOfTime = [&]
  {
    if (!(target > 0 && options.timeLimitSeconds > 0))
    {
      return false;
    }
    std::int64_t late = secondsSince(start) > options.timeLimitSeconds ? 1 : 0;
    sumAcrossRanks(options, &late, 1, secondsReducing);
    return late > 0;
  };
  std::string stoppedBy;
  for (;;)
  {
    while (spread.count() < planned)
    {
      const std::uint64_t done = spread.count();
      SolverOptions batchOptions = options;
      batchOptions.pathsPerFrame = pathsOfBatch(options.pathsPerFrame, roundBatches, done);
      batchOptions.seed = batchSeed(options.seed, done);
      batchOptions.errorBatches = 1;
      batchOptions.targetRelativeError = 0;
      Solution& batch = solveBatch(batchOptions,
        [&](double f)
        {
          // Monotone, although a new round stretches the plan.
          shown = std::max(shown, (static_cast<double>(done) + f) / static_cast<double>(planned));
          return !progress || progress(std::min(shown, 1.0));
        });
      spread.add(batch);
      summary.pathsPerFrame += batchOptions.pathsPerFrame;
      if (spread.count() == 1)
      {
        const double each = secondsSince(start);
        log("error estimate: the first batch took " + seconds(each) + ", so the first " +
          std::to_string(roundBatches) + " take about " +
          seconds(each * static_cast<double>(roundBatches)));
      }
      // The first round always completes: it gives the first estimate.
      if (summary.rounds > 1 && spread.count() < planned && outOfTime())
      {
        stoppedBy = "time limit";
        break;
      }
    }
    if (!stoppedBy.empty())
    {
      break;
    }
    if (!(target > 0))
    {
      stoppedBy = "batches";
      break;
    }
    spread.publish();
    result.chooseLitSides(scene, workers);
    const auto [p95, frame] = worstFrame(result, spread);
    std::ostringstream s;
    s << "error estimate, round " << summary.rounds << ": " << spread.count() << " batches, "
      << summary.pathsPerFrame << " paths per frame, p95 relative error " << percent(p95)
      << " (frame " << options.firstFrame + frame << "), target " << percent(target);
    if (p95 <= target)
    {
      log(s.str() + ": reached");
      stoppedBy = "target";
      break;
    }
    if (outOfTime())
    {
      log(s.str() + ": the time limit stops it");
      stoppedBy = "time limit";
      break;
    }
    const std::uint64_t perBatch = options.pathsPerFrame / roundBatches + 1;
    const std::uint64_t cap = std::min(
      MaximumTotalErrorBatches, std::max<std::uint64_t>(1, MaximumPathsPerFrame / perBatch));
    if (spread.count() >= cap)
    {
      log(s.str() + ": the path limit stops it");
      stoppedBy = "path limit";
      break;
    }
    if (options.batchLimit > 0 && spread.count() >= options.batchLimit)
    {
      log(s.str() + ": the batches of the first solve stop it");
      stoppedBy = "batch limit";
      break;
    }
    planned = std::min(cap, nextBatchCount(spread.count(), p95, target));
    if (options.batchLimit > 0)
    {
      planned = std::min(planned, options.batchLimit);
    }
    ++summary.rounds;
    const double perSecond = static_cast<double>(spread.count()) / secondsSince(start);
    s << ": " << planned - spread.count() << " batches more, about "
      << seconds(static_cast<double>(planned - spread.count()) / perSecond);
    log(s.str());
  }

  spread.publish();
  result.chooseLitSides(scene, workers);
  summary.batches = spread.count();
  summary.stoppedBy = stoppedBy;
  spread.publishStdErrors();
  double worst = 0;
  std::size_t worstAt = 0;
  for (std::size_t f = 0; f < result.frameCount(); ++f)
  {
    const FrameError e = frameError(result, f,
      [&](std::size_t element, Side side) { return result.irradianceStdError(f, element, side); });
    summary.relativeErrorMedian.push_back(e.median);
    summary.relativeErrorP95.push_back(e.p95);
    summary.litElements.push_back(e.litElements);
    if (e.p95 > worst)
    {
      worst = e.p95;
      worstAt = f;
    }
  }
  if (target > 0 && stoppedBy != "target")
  {
    std::ostringstream s;
    s << TargetNotReached << " " << percent(target) << " was not reached: the " << stoppedBy
      << " stopped the solve after " << summary.batches << " batches (" << summary.pathsPerFrame
      << " paths per frame), with a p95 relative error of " << percent(worst) << " in frame "
      << options.firstFrame + worstAt;
    result.warnings.push_back(s.str());
  }
}

} // namespace mlr
