// Bare Embree ray throughput on a Scene, for the same ray kinds the solver casts.
#pragma once

#include "MovingLight.h"
#include "Scene.h"

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

} // namespace mlr::bench
