// The moving-light radiosity solver: shooting random walks and final gathering, with reuse
// of both across all light positions (Sbert & Castro). The
// public entry point: its parts live in topic headers it includes, the options
// (SolverOptions.h), the lights (LightSource.h), the result (Solution.h), the memory plan
// (MemoryPlan.h) and the ranks (Ranks.h).
#pragma once

#include "DirectionalLight.h"
#include "LightSource.h"
#include "MemoryBudget.h"
#include "MemoryPlan.h"
#include "MovingLight.h"
#include "Ranks.h"
#include "Reachability.h"
#include "Rgb.h"
#include "Scene.h"
#include "Solution.h"
#include "SolverOptions.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace mlr
{

class RayTracer;

/// Paper eq. (4): predicted speed-up of full reuse over classic, in ray casts.
double predictedSpeedup(
  std::size_t frames, double gatheringRatio, double lambda, double meanPathLength);

/// Receives the fraction done in [0, 1]; return false to cancel the solve.
using ProgressCallback = std::function<bool(double fraction)>;

/**
 * Solves every frame of the animation lit by `rig` and the scene's emissive surfaces.
 * Throws mlr::Error on bad options or a memory estimate over the limit (checked before
 * allocating), and mlr::Cancelled when the progress callback asks to stop (within a few
 * milliseconds: tasks are small).
 */
Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress = {});

/**
 * What the solves of one animation's chunks share (Chunks.h), built once instead of per
 * chunk: the ray-tracing scene, and the patch sides light can reach from any position of the
 * whole rig. The probes cost a fixed number of rays per patch side (64 million on a million
 * patches, as much as gathering there), the same in every chunk; from every position at
 * once they reach every side a chunk's own would (light in a chunk reaches only sides it
 * would reach from the whole rig), so a chunk solved with it gives the same result as alone
 * wherever its own probes would have found the same sides, and gathers a side they missed.
 */
class SolveSetup
{
public:
  /// Validates the options, builds the tracer and probes from every frame of `rig`.
  /// `progress` gets the fraction of the probes done; throws mlr::Cancelled when it asks to
  /// stop, and as solve() does on bad options.
  SolveSetup(const Scene& scene, const LightRig& rig, const SolverOptions& options,
    const ProgressCallback& progress = {});
  ~SolveSetup();
  SolveSetup(const SolveSetup&) = delete;
  SolveSetup& operator=(const SolveSetup&) = delete;

  const RayTracer& tracer() const { return *this->Tracer; }
  /// reachableSides() from every light's positions, and the sides they hit first.
  const std::vector<std::uint8_t>& reachable() const { return this->Reachable; }
  const std::vector<std::uint8_t>& firstHits() const { return this->FirstHits; }
  std::uint64_t reachabilityRays() const { return this->ReachabilityRays; }
  double seconds() const { return this->Seconds; }

  /// The expected cost of a setup of `scene` (its probe rays and the tracer's build), in
  /// solveCost's units, to weigh its share of progress.
  static double cost(const Scene& scene, const SolverOptions& options);

private:
  std::unique_ptr<RayTracer> Tracer;
  std::vector<std::uint8_t> Reachable, FirstHits;
  std::uint64_t ReachabilityRays = 0;
  double Seconds = 0;
};

/// solve() with the tracer and the reachable sides of `setup`, built for `scene` and a rig
/// `rig` is a slice of (sliceRig): the chunks' solve.
Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress, const SolveSetup& setup);

/// The element sides of `scene` (two per element when options.twoSided), which the work per
/// side and frame of a solve scales with.
double elementSides(const Scene& scene, const SolverOptions& options);

/// The expected cost of a solve of `rig` (or, with `positions`, of a slice of that many
/// positions of it) past its setup, to weigh progress: shooting every source, gathering and
/// the work per element side and frame of every batch, in units of one shooting path's rays
/// (Documentation/Performance.md, "Progress").
double solveCost(
  const Scene& scene, const LightRig& rig, const SolverOptions& options, std::size_t positions = 0);

/**
 * The unit a solve of `rig` stores its results in (Solution::storageScale): the scene's mean
 * irradiance were its lights all at their brightest (every light's largest power over its
 * positions, the scene's emitters included, over the scene's area), as a power of two.
 */
double storageScaleFor(const Scene& scene, const LightRig& rig);

/// The same for one area light (and the scene's emitters).
Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress = {});

} // namespace mlr
