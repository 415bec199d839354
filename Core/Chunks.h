// Animations of any length: the frames solved in chunks of consecutive frames, each a
// full-reuse solve of its own, blended where chunks overlap and handed on chunk by chunk, so
// that memory depends on the chunk's length, not the animation's (Documentation/Method.md,
// "Long animations: chunks").
#pragma once

#include "LightSource.h"
#include "Solution.h"
#include "Solver.h"
#include "SolverOptions.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr
{

/// The fewest frames a chunk may have: with fewer, the blends of a chunk's two seams would
/// overlap.
constexpr std::size_t MinimumFramesPerChunk = 2;

/// Why a chunk length and an overlap asked for cannot be used, empty when they can: a chunk of
/// 1 frame, or an overlap above half a chunk, would let the blends at a chunk's two seams
/// overlap. A length of 0 (the memory limit chooses) passes with any overlap, which is cut to
/// half the length chosen. The message names the setting with the caller's names (an option,
/// a property) so that it says what to fix.
std::string chunkSettingsProblem(std::uint64_t framesPerChunk, std::uint64_t overlap,
  const std::string& framesPerChunkName, const std::string& overlapName);

/// The positions a chunk of C frames solves beyond its own frames on each side: `asked`
/// (SolverOptions::chunkOverlap) cut to C / 2, or C / 8 for 0; at least 1.
std::size_t chunkOverlap(std::size_t framesPerChunk, std::uint64_t asked = 0);

/**
 * How the frames of an animation are split. Chunk k owns frames [begin, end) (C of them, the
 * last may have fewer) and solves the positions [solveBegin, solveEnd): its own and m more on
 * each side, clipped at the animation's ends. Around the seam s between chunks k and k+1 both
 * solve the 2m frames [s - m, s + m), whose result is the blend of the two estimates.
 */
struct ChunkPlan
{
  struct Chunk
  {
    std::size_t begin = 0, end = 0;
    std::size_t solveBegin = 0, solveEnd = 0;
  };
  std::size_t frames = 0;
  std::size_t framesPerChunk = 0;
  std::size_t overlap = 0; ///< m
  std::vector<Chunk> chunks;

  /// The weight of chunk `chunk`'s estimate of `frame` in the result: 1 away from the seams, a
  /// linear ramp across the 2m frames of a seam, where the two chunks' weights sum to one; 0
  /// for the frames the chunk does not solve.
  double weight(std::size_t chunk, std::size_t frame) const;

  /// The frames whose result is final once chunk `chunk` is solved (and the one before it):
  /// from the start of its first seam's blend to the start of its second's.
  std::size_t finishedBegin(std::size_t chunk) const;
  std::size_t finishedEnd(std::size_t chunk) const;
};

/// The chunks of `frames` frames in chunks of `framesPerChunk` (0 or at least `frames`: one
/// chunk), overlapping by chunkOverlap(framesPerChunk, overlap). Throws mlr::Error for 1 frame
/// per chunk.
ChunkPlan planChunks(std::size_t frames, std::size_t framesPerChunk, std::uint64_t overlap = 0);

/// The rig restricted to frames [first, first + count): every moving light keeps those poses,
/// static lights stay as they are, and its firstFrame says where the slice starts, so that its
/// positions cast the paths they cast in any other slice.
LightRig sliceRig(const LightRig& rig, std::size_t first, std::size_t count);

/// Receives frames [firstFrame, firstFrame + frames.frameCount()) once they are final; the
/// Solution may be moved from. Chunk by chunk, in frame order.
using ChunkFramesCallback = std::function<void(std::size_t firstFrame, Solution& frames)>;

/// A figure the caller derives from the first chunk's finished frames (a display's exposure),
/// the same on every rank: `compute` runs on the rank that solved that chunk, before the
/// frames go to the ChunkFramesCallback, and every rank gets the value through `receive`
/// before its first frames do.
struct FirstChunkFigure
{
  std::function<double(const Solution& frames)> compute;
  std::function<void(double value)> receive;
};

/// The expected cost of solveInChunks past its setup, in solveCost's units, to weigh its
/// share of a progress: every chunk's solve and the finishing of its frames.
double chunksCost(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  std::size_t framesPerChunk);

/**
 * Solves the animation in the chunks of planChunks(frames, framesPerChunk,
 * options.chunkOverlap). With one chunk
 * this is solve(scene, rig, options, progress), bit for bit. With several, each is a solve of
 * sliceRig over its positions with the same seed, so that chunks cast the same paths from the
 * positions they share; the result is bit-identical for any thread count.
 * With `onFrames` the finished frames of each chunk go to it and are then freed (the returned
 * Solution holds the statistics only); without, the returned Solution holds every frame. Lit
 * sides: with onFrames, those of the first chunk for every chunk (a frame streamed cannot wait
 * for the last); without, chosen over the whole animation.
 * Over ranks (options.ranks > 1) with onFrames and at least as many chunks as ranks, the ranks
 * take whole chunks: rank r solves chunks r, r + R, ... alone and hands on their frames only,
 * the same bits as a serial solve's; the returned statistics are the animation's on every
 * rank, the warnings this rank's. Otherwise the ranks split each chunk's paths and every rank
 * gets every frame. Throws as solve() does; a failure or cancel on one rank stops every rank
 * after the chunks of that round.
 * `setup`: a SolveSetup of this scene and rig (the caller chose the chunks' length from its
 * reachable sides), else one is built here when there are several chunks. The same bits.
 */
Solution solveInChunks(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  std::size_t framesPerChunk, const ProgressCallback& progress = {},
  const ChunkFramesCallback& onFrames = {}, const FirstChunkFigure& figure = {},
  const SolveSetup* setup = nullptr);

/**
 * The frames that chunk `chunk` of planChunks(frames, framesPerChunk, options.chunkOverlap)
 * finishes, solved again alone (a cache that dropped them): that chunk and, for the blend at
 * its first seam, the chunk before it, so about twice one chunk's solve. The same bits as the
 * frames solveInChunks hands on for it with the same scene, rig and options (any thread
 * count), with `litSides` and `patchLitSides` (those solveInChunks gave: the first chunk's)
 * and `chunkBatches` (its ErrorEstimateSummary::chunkBatches: each chunk then runs the
 * batches it ran, where a time limit cut its rounds; empty: the options' rounds). One rank
 * only. Throws as solve() does, and mlr::Error for a chunk past the last.
 */
Solution solveChunk(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  std::size_t framesPerChunk, std::size_t chunk, const std::vector<Side>& litSides,
  const std::vector<Side>& patchLitSides, const std::vector<std::uint64_t>& chunkBatches = {},
  const ProgressCallback& progress = {});

} // namespace mlr
