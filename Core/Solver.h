// The moving-light radiosity solver: shooting random walks and final gathering, with reuse
// of both across all light positions (Sbert & Castro; see shared/docs/METHOD.md).
#pragma once

#include "DirectionalLight.h"
#include "MemoryBudget.h"
#include "MovingLight.h"
#include "Rgb.h"
#include "Scene.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr
{

struct SolverOptions
{
  /// N: effective shooting paths per frame.
  std::uint64_t pathsPerFrame = 600000;
  /// k: gathering rays per frame = k * N, shared over the element sides that gather.
  double gatheringRatio = 1.0;
  /// lambda: probability that a path continues after its first hit, in [0.001, 1]. A walk
  /// that survives carries 1/lambda of its power; the bound keeps the fixed-point sums (2^23
  /// times the light's power per slot) far from overflow.
  double firstBounceSurvival = 0.25;
  /// Cast M = N/n paths from each position and weight them for every frame.
  bool reuseShooting = true;
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
};

/// The largest pathsPerFrame accepted: past it a solve would run for months.
constexpr std::uint64_t MaximumPathsPerFrame = 100000000000ULL;

/// The smallest lambda accepted (SolverOptions::firstBounceSurvival).
constexpr double MinimumFirstBounceSurvival = 0.001;

/// Probe rays cast from every patch side to decide which sides light can reach.
constexpr int ReachabilityProbesPerSide = 32;

/**
 * Everything that emits in an animation besides the scene's own emissive surfaces (which
 * Scene::patchEmission gives). Lights with one pose or direction are static: solved once and
 * added to every frame. All moving lights must have the same number of poses: the frames.
 * Transport is linear, so every light is shot on its own and the results add up; gathering
 * then runs once on the sum.
 */
struct LightRig
{
  std::vector<MovingLight> areaLights;
  std::vector<DirectionalLight> directionalLights;
};

/// The number of frames of a rig: the pose count of its moving lights, or 1 when nothing
/// moves. Throws mlr::Error when moving lights disagree or nothing can emit.
std::size_t frameCount(const LightRig& rig, bool sceneEmits);

struct SolverStatistics
{
  std::uint64_t frames = 0;
  std::uint64_t patches = 0;
  std::uint64_t elements = 0;
  std::uint64_t effectivePathsPerFrame = 0;
  std::uint64_t pathsCast = 0;      ///< shooting paths actually traced, all frames
  std::uint64_t shootingRays = 0;   ///< nearest-hit rays of the shooting walks
  std::uint64_t shadowRays = 0;     ///< visibility rays for the reuse weights
  std::uint64_t shadowRaysBlocked = 0; ///< of shadowRays, those an occluder stopped
  /// Walks whose first ray hit the scene (and, one-sided, a front face): with reuse, each
  /// asks for the visibility of every other position whose unoccluded kernel is not zero.
  std::uint64_t firstHits = 0;
  std::uint64_t gatheringRays = 0;  ///< nearest-hit rays of the final gathering
  std::uint64_t missedRays = 0;     ///< nearest-hit rays that hit nothing
  std::uint64_t gatheringSides = 0; ///< element sides that gathered
  std::uint64_t reachabilityRays = 0; ///< probes that decided which sides light can reach
  std::uint64_t reachableSides = 0;   ///< patch sides light can reach (the others stay dark)
  std::uint64_t sources = 0;          ///< lights shot: moving, static, directional, emitters
  std::uint64_t staticPathsCast = 0;  ///< of pathsCast, from sources solved once for all frames
  /// l of the paper: mean number of hits of a path without the lambda cut, from
  /// shootingRays / pathsCast = 1 + lambda (l - 1).
  double meanPathLength = 0;
  double secondsRemeshing = 0; ///< set by callers that remesh before solving
  double secondsSetup = 0;     ///< validation, allocation and building the BVH
  double secondsShooting = 0;
  double secondsGathering = 0;
  /// Of shooting and gathering, the time spent in sums over ranks and the agreements
  /// between phases (waiting for slower ranks included); 0 on one rank.
  double secondsReducing = 0;
  double secondsTotal = 0;
  std::uint64_t memoryEstimateBytes = 0;
  /// The shooting accumulators had one copy per worker (else one shared copy, MemoryPlan).
  bool accumulatorCopyPerWorker = true;
  int threads = 0;
  bool reuseShooting = false;
  bool reuseGathering = false;
  bool twoSided = true;
};

/// Paper eq. (4): predicted speed-up of full reuse over classic, in ray casts.
double predictedSpeedup(std::size_t frames, double gatheringRatio, double lambda,
  double meanPathLength);

/**
 * Radiosity (W/m^2) of every element and patch side, for every frame.
 *
 * B_total = E + B_direct + B_indirect for elements, E the self-emission of the front side.
 * B_direct comes from the shooting walks' first hits (from every light and emitter);
 * B_indirect from final gathering of the patches' shooting solution. Both sides are kept;
 * litSide() picks the one to show.
 */
class Solution
{
public:
  Solution() = default;
  Solution(std::size_t frames, std::size_t elements, std::size_t patches);

  std::size_t frameCount() const { return this->Frames; }
  std::size_t elementCount() const { return this->Elements; }
  std::size_t patchCount() const { return this->Patches; }

  Rgb direct(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Direct[this->elementIndex(frame, element, side)];
  }
  /// Zero until gathering has run.
  Rgb indirect(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Indirect.empty() ? Rgb() : Rgb(this->Indirect[this->elementIndex(frame, element, side)]);
  }
  /// Self-emission (W/m^2): the scene's emission on the front side, zero on the back.
  Rgb emitted(std::size_t element, Side side) const
  {
    return side == Side::Front && !this->Emission.empty() ? this->Emission[element] : Rgb();
  }
  Rgb total(std::size_t frame, std::size_t element, Side side) const
  {
    return this->emitted(element, side) + this->direct(frame, element, side) +
      this->indirect(frame, element, side);
  }
  /// The patch-level shooting solution (all bounces), which gathering reads.
  Rgb patchRadiosity(std::size_t frame, std::size_t patch, Side side) const
  {
    return this->Patch[this->patchIndex(frame, patch, side)];
  }
  /// The side of an element that received more power over the whole animation.
  Side litSide(std::size_t element) const { return this->LitSide[element]; }

  SolverStatistics statistics;
  std::vector<std::string> warnings;

  // Storage is element- (patch-) major with frames innermost: scoring one hit for all
  // frames touches one contiguous run.
  std::size_t elementIndex(std::size_t frame, std::size_t element, Side side) const
  {
    return (element * 2 + static_cast<std::size_t>(side)) * this->Frames + frame;
  }
  std::size_t patchIndex(std::size_t frame, std::size_t patch, Side side) const
  {
    return (patch * 2 + static_cast<std::size_t>(side)) * this->Frames + frame;
  }
  // Results are stored in single precision (PackedRgb); see MemoryPlan.
  std::vector<PackedRgb>& directData() { return this->Direct; }
  /// Empty until allocateIndirect(): the solver allocates it once the shooting accumulators
  /// are freed, so that the two never take memory at once.
  std::vector<PackedRgb>& indirectData() { return this->Indirect; }
  void allocateIndirect() { this->Indirect.assign(this->Direct.size(), PackedRgb()); }
  std::vector<PackedRgb>& patchData() { return this->Patch; }
  std::vector<Side>& litSideData() { return this->LitSide; }
  /// One per element, or empty when nothing emits.
  std::vector<Rgb>& emissionData() { return this->Emission; }

private:
  std::size_t Frames = 0, Elements = 0, Patches = 0;
  std::vector<PackedRgb> Direct, Indirect, Patch;
  std::vector<Rgb> Emission;
  std::vector<Side> LitSide;
};

/// Receives the fraction done in [0, 1]; return false to cancel the solve.
using ProgressCallback = std::function<bool(double fraction)>;

/**
 * How a solve uses memory: the one policy behind the estimate, the limit check and the
 * allocations. Results are single precision (PackedRgb): direct light per element side,
 * patch radiosity per patch side, and indirect light per element side, allocated when
 * gathering starts, after the shooting accumulators are freed. The peak is the larger of the
 * two phases. Shooting accumulators (64-bit fixed point) take one copy per worker (plain
 * adds, the fastest) when that peak fits in half the memory limit, and otherwise one copy
 * shared by the workers (atomic adds: memory independent of the core count; shooting 1.5x to
 * 1.8x slower where the sums stay in cache, faster on large scenes that wait on memory).
 * Sizes saturate at UINT64_MAX instead of overflowing.
 */
struct MemoryPlan
{
  bool accumulatorCopyPerWorker = true;
  std::uint64_t results = 0;      ///< direct, indirect and patch radiosity of every frame
  std::uint64_t accumulators = 0; ///< the shooting accumulators of one source, all copies
  std::uint64_t other = 0;        ///< per-thread scratch, the ray-tracing scene, reachability
  std::uint64_t peak = 0;         ///< the estimate: the larger phase, shooting or gathering
};

MemoryPlan planSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options);

/// planSolveMemory(...).peak: the bytes a solve will allocate at its peak.
std::uint64_t estimateSolveMemory(
  const Scene& scene, std::size_t frames, const SolverOptions& options);

/// The same estimate from counts alone, e.g. for a scene not remeshed yet.
std::uint64_t estimateSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options);

/// options.memoryLimitBytes, or the default when it is 0.
std::uint64_t memoryLimitBytes(const SolverOptions& options);

/**
 * Throws mlr::Error when `estimate` bytes exceed the memory limit of `options`; the message
 * gives the estimate, the limit and what it is made of (`frames`, `patches`, `elements`;
 * `approximate` says the counts are expected ones, before remeshing).
 */
void checkSolveMemory(std::uint64_t estimate, std::size_t frames, std::size_t patches,
  std::size_t elements, const SolverOptions& options, bool approximate = false);

/// Throws mlr::Error naming the first option that is out of range.
void validateOptions(const SolverOptions& options);

/**
 * Runs `phase` on this rank and, when options.ranks > 1, agrees with the other ranks on how
 * it went before any rank goes on (one sum over ranks): when any rank was cancelled or
 * failed, every rank throws, mlr::Cancelled or mlr::Error (its own exception on the rank
 * that threw, mlr::FailedOnAnotherRank elsewhere), so that no rank is left waiting in a
 * later sum. Every rank must call it at the same points. With one rank it only runs `phase`.
 */
/// `secondsAgreeing`, when given, is increased by the time the agreement took (waiting for
/// the slowest rank included).
void agreeAcrossRanks(const SolverOptions& options, const std::function<void()>& phase,
  double* secondsAgreeing = nullptr);

/**
 * Solves every frame of the animation lit by `rig` and the scene's emissive surfaces.
 * Throws mlr::Error on bad options or a memory estimate over the limit (checked before
 * allocating), and mlr::Cancelled when the progress callback asks to stop (within a few
 * milliseconds: tasks are small).
 */
Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress = {});

/// The same for one area light (and the scene's emitters).
Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress = {});

} // namespace mlr
