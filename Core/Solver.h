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
#include <functional>

namespace mlr
{

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
 * The unit a solve of `rig` stores its results in (Solution::storageScale): the scene's mean
 * irradiance were its lights all at their brightest (every light's largest power over its
 * positions, the scene's emitters included, over the scene's area), as a power of two.
 */
double storageScaleFor(const Scene& scene, const LightRig& rig);

/// The same for one area light (and the scene's emitters).
Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress = {});

} // namespace mlr
