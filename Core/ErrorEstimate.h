// The error estimate: a solve run as independent batches, whose mean is the result and whose
// spread is every element's standard error, and the rounds of batches that reach a target
// relative error (Documentation/Method.md, section 17).
#pragma once

#include "LightSource.h"
#include "Solution.h"
#include "SolverOptions.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr
{

/// An element is lit in a frame when its irradiance there (lit side, sum over channels) is
/// above this fraction of the frame's mean over all elements: the relative error statistics
/// and the target are over the lit elements only.
constexpr double LitFractionOfMean = 0.01;

/// The factor by which a round multiplies the batch count, from (p95 / target)^2, is kept in
/// this range: at least a quarter more (a round has a cost of its own), at most 4 times (the
/// estimate of p95 from few batches is itself noisy).
constexpr double MinimumRoundGrowth = 1.25;
constexpr double MaximumRoundGrowth = 4.0;

/// The most batches a solve with a target runs, all rounds together.
constexpr std::uint64_t MaximumTotalErrorBatches = 1ULL << 20;

/// Whether `options` ask for batches: errorBatches > 1 or a target.
inline bool estimatesError(const SolverOptions& options)
{
  return options.errorBatches > 1 || options.targetRelativeError > 0;
}

/// Throws mlr::Error naming the error option that is out of range.
void validateErrorOptions(const SolverOptions& options);

/// N_b, the paths per frame of batch `batch`: N / B, the first N mod B batches one more, so
/// that a round of B batches casts N paths per frame. Later rounds repeat the pattern.
std::uint64_t pathsOfBatch(std::uint64_t paths, std::uint64_t batches, std::uint64_t batch);

/// The seed of batch `batch`: the solve's own seed for batch 0, so that one batch is the
/// solve without an estimate, and a mix of seed and batch for the others, so that no two
/// batches (of this seed or of another) share a random stream.
std::uint64_t batchSeed(std::uint64_t seed, std::uint64_t batch);

/// checkPathsPerPosition for the smallest batch, with a message that names the batches.
void checkBatchPathsPerPosition(const LightSource& source, const SolverOptions& options);

/// The bytes a batched solve needs on top of one solve of a batch: the running mean of the
/// results (direct, indirect, patches; single precision, and stored in the result), the
/// batches' sum of squared deviations (single precision) and the standard errors (stored) of
/// every element side and frame. Like the results, they are written for the sides light
/// reaches alone, in the pages of those sides' runs: `reachable` as in planSolveMemory (null
/// counts every side). 0 without batches.
std::uint64_t errorEstimateBytes(std::size_t patches, std::size_t elements, std::size_t frames,
  const SolverOptions& options, const std::vector<std::uint8_t>* reachable = nullptr);

/// The relative error statistics of one frame's lit elements.
struct FrameError
{
  double median = 0;             ///< nearest-rank median of the relative error
  double p95 = 0;                ///< nearest-rank 95th percentile
  std::uint64_t litElements = 0; ///< 0: nothing lit, both statistics 0
};

/**
 * The relative error of frame `frame` over its lit elements, those whose irradiance is over
 * LitFractionOfMean of the frame's mean. An element's relative error is the sum over
 * channels of its irradiance's standard error (`stdError`, on its lit side) over the sum over
 * channels of its irradiance: where the element reflects, that of the radiosity it reflects
 * (its radiosity less its emission, which has no error), and black elements count too.
 */
FrameError frameError(const Solution& solution, std::size_t frame,
  const std::function<Rgb(std::size_t element, Side side)>& stdError);

/// The median and 95th percentile (nearest rank) of `relative`, which it reorders, and its
/// size as litElements: frameError's figures of the relative errors given.
FrameError relativeErrorFigures(std::vector<double>& relative);

/// The batch count of the next round: `batches` times (p95 / target)^2, a tenth more so that
/// the round lands under the target, clamped to [MinimumRoundGrowth, MaximumRoundGrowth]
/// times `batches` and rounded up.
std::uint64_t nextBatchCount(std::uint64_t batches, double p95, double target);

/// A relative error as the messages give it: "12.5%" (3 significant digits).
std::string percent(double fraction);

/// How the warning that a solve stopped short of its target begins.
constexpr const char* TargetNotReached = "the target relative error";

/// Solves one batch with `batchOptions` (its paths per frame and seed) into a Solution it
/// returns; `fraction` gets the share of the batch done, false cancels.
using BatchSolve = std::function<Solution&(
  const SolverOptions& batchOptions, const std::function<bool(double fraction)>& fraction)>;

/**
 * Runs the batches of `options` in batch order through `solveBatch` and leaves in `result`
 * (allocated, its reflectance and emission set) their mean, its lit sides (on `scene`'s
 * surfaces), the standard error of every element side and frame, and errorEstimate. With a
 * target it adds rounds until every frame's p95 is at most the target, or the time limit or
 * the path limit stops it (a warning then says so). Every rank runs the same batches and
 * takes the same decisions: the time limit is agreed over ranks. `memoryBytes` is the
 * solve's memory estimate, for the log. Throws mlr::Cancelled when `progress` returns false.
 */
void solveInBatches(const Scene& scene, const SolverOptions& options, const BatchSolve& solveBatch,
  const std::function<bool(double fraction)>& progress, std::uint64_t memoryBytes,
  double& secondsReducing, Solution& result);

} // namespace mlr
