// What a solve is asked to do: the options, their bounds and the one list of their fields.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>

namespace mlr
{

class Solution;

struct SolverOptions
{
  /// N: effective shooting paths per frame.
  std::uint64_t pathsPerFrame = 600000;
  /// k: gathering rays per frame = k * N, shared over the element sides that gather.
  double gatheringRatio = 1.0;
  /// lambda: probability that a path continues after its first hit, in [0.001, 1]. A walk
  /// that survives carries 1/lambda of its power; the bound keeps the fixed-point sums (a slot
  /// holds at least 2^13 times the light's power: quantumFor in Shooting.cxx) far from overflow.
  double firstBounceSurvival = 0.25;
  /// Cast M = N/n paths from each position and weight them for every frame.
  bool reuseShooting = true;
  /// With shooting reuse, share the N paths unequally over the light's positions so that
  /// every frame gets the same effective number of paths: a pilot of reused paths judges
  /// how well the mixture samples each frame, and the ends of a trajectory, which the
  /// mixture covers from one side only, get more (Documentation/Method.md, section 5).
  /// False casts N/n from every position.
  bool balanceFrames = true;
  /// Cast one set of gathering rays and use every ray for every frame.
  bool reuseGathering = true;
  /// Surfaces scatter light on both sides; when false, back faces absorb everything.
  bool twoSided = true;
  std::uint64_t seed = 0;
  /// Worker threads; 0 means every core. The result does not depend on it.
  int threads = 0;
  /// Refuse solves whose memory estimate exceeds this many bytes; 0 means half of the
  /// physical memory.
  std::uint64_t memoryLimitBytes = 0;
  /// C: solve the animation in chunks of this many consecutive frames, each a full-reuse
  /// solve of its own, so that memory depends on C, not on the frame count (Chunks.h);
  /// 0 lets the memory limit choose (the whole animation when it fits). At least 2.
  std::uint64_t framesPerChunk = 0;
  /// m: with chunks, each chunk also solves m positions beyond its frames on each side, and
  /// each seam blends the two chunks over those 2m frames. The seams' flicker falls as 1/m,
  /// and each chunk solves C + 2m positions (Documentation/Method.md, "Long animations:
  /// chunks"). 0 takes C / 8 (at least 1); at most C / 2 (a larger m is cut to C / 2 when the
  /// memory limit chooses C).
  std::uint64_t chunkOverlap = 0;

  /// B: the solve runs as B independent batches of N/B paths per frame (and k N/B gathering
  /// rays) whose mean is the result and whose spread gives every element's standard error
  /// (ErrorEstimate.h). 1 is one solve without an error estimate.
  std::uint64_t errorBatches = 1;
  /// Above 0: add rounds of batches (of N/B paths each) until, in every frame, the 95th
  /// percentile of the lit elements' relative error is at most this, or a limit stops it.
  double targetRelativeError = 0;
  /// With a target: start no more batches once this many seconds have passed (0: no limit).
  /// In chunks it is the whole solve's, what is left of it shared among the chunks still to
  /// solve, each of which completes its first round. The round count then depends on the
  /// machine's speed: the result is no longer reproducible.
  double timeLimitSeconds = 0;
  /// With a target: start no more rounds once this many batches, all rounds together, have
  /// run, and cut a round at it (0: only the path limit); the first round always completes.
  /// A chunk solved again runs the batches its first solve ran (solveChunk), so that the cut
  /// of a time limit is repeated bit for bit, whatever the time it now takes.
  std::uint64_t batchLimit = 0;
  /// The unit the results are stored in (Solution::storageScale), a power of two; 0 takes
  /// it from the scene and the rig solved (storageScaleFor). Solves whose results are
  /// blended, as the chunks of one animation, set the one of the whole rig.
  double storageScale = 0;
  /// The animation's frame number of the first position solved, for the messages only: a
  /// chunk's messages name the frames as the animation numbers them, not as the chunk does.
  std::size_t firstFrame = 0;

  /// A solve shared by `ranks` processes (MPI ranks of pvbatch or pvserver), this one being
  /// `rank`. Every rank gives the same scene, rig and options; each traces a disjoint share
  /// of the shooting paths and gathering sides, keyed by their global index, and the sums are
  /// added over ranks, so every rank ends with the serial solution, bit for bit.
  int rank = 0;
  int ranks = 1;
  /// Sums `count` values over every rank, in place, on every rank (an MPI AllReduce): every
  /// rank calls it at the same points of the solve. Required when ranks > 1; Core has no MPI.
  std::function<void(std::int64_t* values, std::size_t count)> sumAcrossRanks;
  std::function<void(double* values, std::size_t count)> sumDoublesAcrossRanks;
  /// Receives the solve's progress messages (the error estimate's rounds, its estimates of
  /// memory and time); may be empty.
  std::function<void(const std::string& message)> log;
  /// With batches: receives every batch once it is solved, before it is merged, with its index
  /// in the solve (from 0; each chunk of an animation is a solve of its own), the animation's
  /// frame of its frame 0 (LightRig::firstFrame) and its solution, for what reads the batches
  /// apart (the sensors' standard error, SensorBatchSpread in Sensors.h); may be empty. It runs
  /// on every rank, with the same solution on each.
  std::function<void(std::uint64_t batch, std::size_t firstFrame, const Solution& solution)>
    batchSolved;
};

/// The largest pathsPerFrame accepted: past it a solve would run for months.
constexpr std::uint64_t MaximumPathsPerFrame = 100000000000ULL;

/// The largest chunk overlap accepted (SolverOptions::chunkOverlap), far beyond any chunk.
constexpr std::uint64_t MaximumChunkOverlap = 1000000;

/// The most batches ErrorEstimate accepts for the first round (SolverOptions::errorBatches).
constexpr std::uint64_t MaximumErrorBatches = 4096;

/// The smallest target relative error accepted: below it no solve would finish.
constexpr double MinimumTargetRelativeError = 1e-4;

/// The smallest lambda accepted (SolverOptions::firstBounceSurvival).
constexpr double MinimumFirstBounceSurvival = 0.001;

/// Throws mlr::Error naming the first option that is out of range.
void validateOptions(const SolverOptions& options);

/// What an option decides, for the ranks' agreement (digestOf in Ranks.h).
enum class OptionRole
{
  Result,  ///< changes the solution: every rank must give the same value
  PerRank, ///< may differ between ranks without changing the solution (threads, rank)
  Hook,    ///< a function the caller supplies (the sums over ranks)
};

/**
 * Calls visit(name, value, role) for every field of `options`, in declaration order. The
 * structured binding names every field, so adding one to SolverOptions without adding it
 * here fails to compile: the ranks' digest cannot leave a new option out silently.
 */
template <typename Visitor>
void visitSolverOptions(const SolverOptions& options, Visitor&& visit)
{
  const auto& [pathsPerFrame, gatheringRatio, firstBounceSurvival, reuseShooting, balanceFrames,
    reuseGathering, twoSided, seed, threads, memoryLimitBytes, framesPerChunk, chunkOverlap,
    errorBatches, targetRelativeError, timeLimitSeconds, batchLimit, storageScale, firstFrame, rank,
    ranks, sumAcrossRanks, sumDoublesAcrossRanks, log, batchSolved] = options;
  visit("pathsPerFrame", pathsPerFrame, OptionRole::Result);
  visit("gatheringRatio", gatheringRatio, OptionRole::Result);
  visit("firstBounceSurvival", firstBounceSurvival, OptionRole::Result);
  visit("reuseShooting", reuseShooting, OptionRole::Result);
  visit("balanceFrames", balanceFrames, OptionRole::Result);
  visit("reuseGathering", reuseGathering, OptionRole::Result);
  visit("twoSided", twoSided, OptionRole::Result);
  visit("seed", seed, OptionRole::Result);
  visit("threads", threads, OptionRole::PerRank);
  // The limit decides whether a solve runs and how it holds its sums, never its result;
  // every rank checks its own.
  visit("memoryLimitBytes", memoryLimitBytes, OptionRole::PerRank);
  // The chunks decide the seeds and the blends: the ranks solve the same chunks.
  visit("framesPerChunk", framesPerChunk, OptionRole::Result);
  visit("chunkOverlap", chunkOverlap, OptionRole::Result);
  visit("errorBatches", errorBatches, OptionRole::Result);
  visit("targetRelativeError", targetRelativeError, OptionRole::Result);
  // The ranks stop together (the first to run out of time stops all), so they must agree on
  // the limit.
  visit("timeLimitSeconds", timeLimitSeconds, OptionRole::Result);
  visit("batchLimit", batchLimit, OptionRole::Result);
  visit("storageScale", storageScale, OptionRole::Result);
  visit("firstFrame", firstFrame, OptionRole::PerRank);
  visit("rank", rank, OptionRole::PerRank);
  visit("ranks", ranks, OptionRole::Result);
  visit("sumAcrossRanks", sumAcrossRanks, OptionRole::Hook);
  visit("sumDoublesAcrossRanks", sumDoublesAcrossRanks, OptionRole::Hook);
  visit("log", log, OptionRole::Hook);
  visit("batchSolved", batchSolved, OptionRole::Hook);
}

} // namespace mlr
