// Which patch sides light can reach, from geometry alone: the sides that stay dark (inside a
// closed block) need not gather.
#pragma once

#include "LightSource.h"
#include "Scene.h"
#include "SolverOptions.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace mlr
{

class RayTracer;

/// Probe rays cast from every patch side to decide which sides light can reach.
constexpr int ReachabilityProbesPerSide = 32;

/**
 * Which patch sides (patch * 2 + side) light can reach, from geometry alone (the same for any
 * N, seed and thread count). Seeds: the sides that probe walks from every light's positions
 * hit first. Then a side is reachable when one of ReachabilityProbesPerSide cosine rays from
 * it reaches a reachable side, or one from a reachable side reaches it (light paths are
 * reversible). The inside of a closed block is never reached; a side that random shooting
 * happened to miss still is. `rays` is increased by the probes cast. `firstHits`, when
 * given, gets the flags of the seeds alone: a sample of the sides the lights reach directly,
 * for the memory plan (the results of direct light are written there alone).
 */
std::vector<std::uint8_t> reachableSides(const Scene& scene, const RayTracer& tracer,
  const std::vector<LightSource>& sources, const SolverOptions& options, int workers,
  const std::function<bool(double)>& keepGoing, std::uint64_t& rays,
  std::vector<std::uint8_t>* firstHits = nullptr);

} // namespace mlr
