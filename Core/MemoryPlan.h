// How a solve uses memory, planned before it allocates, and the check against the limit of
// the one memory policy (MemoryBudget).
#pragma once

#include "MemoryBudget.h"
#include "Scene.h"
#include "SolverOptions.h"

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mlr
{

/// What gathering holds beside the results (Gathering.h).
struct GatheringBudget
{
  /// What its rays read, a stored value per element side, for a block of frames at a time.
  std::uint64_t rowBytes = std::uint64_t(128) << 20;
  /// With reuse and several blocks, the element side each ray of a group of sides reached
  /// (4 bytes a ray).
  std::uint64_t hitBytes = std::uint64_t(64) << 20;
};

/**
 * How a solve uses memory: the one policy behind the estimate, the limit check and the
 * allocations. Results take 16 bits per channel (PackedRgb, rounded to within 0.1%): direct
 * irradiance per element side and patch radiosity per patch side, which take memory only
 * once the shooting accumulators are turned into them (after the workers' copies are
 * collapsed into one, and, with reuse, as the accumulators' pages are given back), and
 * indirect irradiance per element side, allocated when gathering starts, after the shooting
 * accumulators are freed. The peak is the larger of the two
 * phases. Shooting accumulators (64-bit fixed point, for the reachable sides once they are
 * known; see planSolveMemory) take one copy per worker (plain
 * adds, the fastest) when that peak fits in half the memory limit, and otherwise one copy
 * shared by the workers (atomic adds: memory independent of the core count; shooting 1.5x to
 * 1.8x slower where the sums stay in cache, faster on large scenes that wait on memory).
 * Sizes saturate at UINT64_MAX instead of overflowing.
 */
struct MemoryPlan
{
  bool accumulatorCopyPerWorker = true;
  std::uint64_t results = 0;      ///< direct and indirect irradiance, patch radiosity, per frame
  std::uint64_t accumulators = 0; ///< the shooting accumulators of one source, all copies
  std::uint64_t other = 0;        ///< per-thread scratch, the ray-tracing scene, reachability
  /// A batched solve's mean and spread, on top of the batch being solved (errorEstimateBytes
  /// of ErrorEstimate.h); 0 without batches. The rounds of a target add none.
  std::uint64_t errorEstimate = 0;
  std::uint64_t peak = 0; ///< the estimate: the larger phase, shooting or gathering
  /// What gathering may hold beside the results: its default, or what the limit leaves.
  GatheringBudget gathering;
};

/// The plan of a solve of `frames` frames lit by `lights` light sources (area lights, scene
/// emitters and directional lights; their per-frame data is counted). `reachable`: the flags
/// of the patch sides light can reach (patch * 2 + side, Reachability.h), which alone, with
/// their elements' sides, have shooting accumulators and results written; null, the bound
/// before the probes, counts every side. `firstHits`: of those, the sides the probes from
/// the lights hit first (reachableSides), where alone direct light is written, in the
/// results and in the elements' shooting sums; null counts every reachable side.
MemoryPlan planSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights = 1,
  const std::vector<std::uint8_t>* reachable = nullptr,
  const std::vector<std::uint8_t>* firstHits = nullptr);

/**
 * The bytes of a result array that writing the frames of the reachable sides makes
 * resident: the array holds `frames` values of `valueBytes` (PackedRgb, or FloatRgb for the
 * error batches' running sums) per (record, side), side-major, records `recordsPerPatch` to a
 * patch (Solution::elementIndex, patchIndex); it is a fresh mapping aligned to 2 MiB
 * (ZeroedAllocator) whose pages become resident whole once written. Null `reachable`: every
 * side, the whole array.
 */
std::uint64_t writtenResultBytes(std::size_t patches, std::size_t recordsPerPatch,
  std::size_t frames, const std::vector<std::uint8_t>* reachable,
  std::size_t valueBytes = sizeof(PackedRgb));

/// planSolveMemory(...).peak: the bytes a solve will allocate at its peak.
std::uint64_t estimateSolveMemory(
  const Scene& scene, std::size_t frames, const SolverOptions& options, std::size_t lights = 1);

/// The same estimate from counts alone, e.g. for a scene not remeshed yet.
std::uint64_t estimateSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights = 1);

/**
 * The peak of a solve of `frames` frames in chunks of `framesPerChunk` (Chunks.h; 0 or
 * `frames` and more: one chunk, the plain solve): one chunk's solve, the estimate of its seam
 * kept for the next, and the finished frames, those of one chunk when they are `streamed` to
 * the caller, else all. A caller that keeps the frames streamed to it holds up to
 * `keptChunks` chunks' frames of those it gets (0: none beyond the one handed on): over
 * R = options.ranks ranks that take whole chunks (at least R chunks, Chunks.h) every R-th
 * chunk's, else every chunk's. `fixedBytes` (the caller's
 * outputs) is added. `reachable` and `firstHits`: those of the whole animation (SolveSetup),
 * which bound every chunk's; null, the bound of every side.
 */
std::uint64_t estimateChunkedMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, std::size_t framesPerChunk, const SolverOptions& options, std::size_t lights,
  std::uint64_t fixedBytes, bool streamed, std::size_t keptChunks = 0,
  const std::vector<std::uint8_t>* reachable = nullptr,
  const std::vector<std::uint8_t>* firstHits = nullptr);

/// C: options.framesPerChunk when set, else every frame when that fits the memory limit,
/// else the most frames per chunk whose estimateChunkedMemory does (at least 2: the memory
/// check then says what does not fit).
std::size_t chooseFramesPerChunk(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights, std::uint64_t fixedBytes,
  bool streamed, std::size_t keptChunks = 0, const std::vector<std::uint8_t>* reachable = nullptr,
  const std::vector<std::uint8_t>* firstHits = nullptr);

/// options.memoryLimitBytes, or the default when it is 0.
std::uint64_t memoryLimitBytes(const SolverOptions& options);

/**
 * Throws mlr::Error when `estimate` bytes exceed the memory limit of `options`; the message
 * gives the estimate, the limit and what it is made of (`frames`, `patches`, `elements`;
 * `approximate` says the counts are expected ones, before remeshing; `sensorBytes` of the
 * estimate are the `sensors`', and when they are most of it the advice is about them;
 * `couldStream`: every frame is kept where the frames could be kept a few chunks at a time,
 * which the advice then offers; `skyBytes` of the estimate are the skies' tables, likewise;
 * `framesPerChunk`: the `frames` are solved and handed on in chunks of this many, and the
 * message names a chunk's positions and advises about the chunks' length).
 */
void checkSolveMemory(std::uint64_t estimate, std::size_t frames, std::size_t patches,
  std::size_t elements, const SolverOptions& options, bool approximate = false,
  std::size_t sensors = 0, std::uint64_t sensorBytes = 0, bool couldStream = false,
  std::uint64_t skyBytes = 0, std::size_t framesPerChunk = 0);

} // namespace mlr
