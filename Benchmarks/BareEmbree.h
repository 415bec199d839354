// Bare Embree ray throughput on a Scene, for the same ray kinds the solver casts.
#pragma once

#include "MovingLight.h"
#include "Scene.h"
#include "Solution.h"

#include <cstddef>

namespace mlr::bench
{

/// Rays per second of plain Embree calls, with rays generated ahead of timing.
struct BareRates
{
  double lightRays = 0;   ///< rtcIntersect1, cosine rays leaving the light
  double surfaceRays = 0; ///< rtcIntersect1, cosine rays leaving surfaces (walks, gathering)
  double shadowRays = 0;  ///< rtcOccluded16, from a surface point to the light positions
};

/// Measures the three rates on `threads` threads with `samples` rays of each kind.
BareRates measureBareEmbree(
  const Scene& scene, const MovingLight& light, int threads, std::size_t samples);

/**
 * Where a full-reuse solve's shadow rays go, and their rate beside bare Embree's; returns the
 * solver's rate. Every first hit could ask for the other n - 1 positions; a zero unoccluded
 * kernel (the hit behind the light's plane or outside its beam, or the light behind the hit's)
 * needs no ray. The solver's rate is shooting's time left once its nearest-hit rays are
 * counted at bare Embree's rate, per shadow ray: it includes the weights and the scoring of
 * every frame, so it is a lower bound on the rate of the rays alone.
 */
double printShadowRays(const SolverStatistics& full, std::size_t frames, const BareRates& bare);

} // namespace mlr::bench
