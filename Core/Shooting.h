// Shooting: random walks from one light source, scored into its own fixed-point sums and
// added to the solution as direct light and the patches' shooting solution.
#pragma once

#include "LightSource.h"
#include "Solution.h"
#include "SolverOptions.h"
#include "WorkerCounters.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace mlr
{

class RayTracer;

/// Throws mlr::Error when `source` reuses paths but N is fewer than its active positions.
void checkPathsPerPosition(const LightSource& source, const SolverOptions& options);

/// The expected ray casts of shooting `source`, which weigh the progress of its phase.
double shootingCost(const LightSource& source, const SolverOptions& options);

/// The same for a source of `positions` positions.
double shootingCost(std::size_t positions, const SolverOptions& options);

/// What shooting one source traced: its paths and this rank's rays.
struct ShootingResult
{
  std::uint64_t pathsCast = 0;
  WorkerCounters counters;
  /// The fewest and most paths a position cast, over N/n; 1 and 1 unless reused and balanced.
  double smallestShare = 1, largestShare = 1;
  /// Element and patch sides without accumulator slots that paths scored (see shoot()).
  std::uint64_t overflowSides = 0;
};

/**
 * The share of the reused paths each active position of `source` casts, balanced so that
 * every frame is sampled as well as the others (Documentation/Method.md, "The ends of an
 * animation"): from a pilot of reused paths, the same on every rank and for any thread
 * count. Empty, meaning equal shares, when the source does not reuse, balancing is off or
 * there are too few paths per position. `pilotRays` gets the pilot's rays added.
 */
std::vector<double> positionShares(const Scene& scene, const LightSource& source,
  const SolverOptions& options, const RayTracer& tracer, int workers,
  const std::function<bool(double fraction)>& fraction, std::uint64_t& pilotRays);

/**
 * Shoots options.pathsPerFrame effective paths per frame from `source` (reused over its
 * positions, or classic: each position its own), shared by the ranks and summed over them,
 * and adds the source's radiosity to `solution`. `copyPerWorker`: one copy of the sums per
 * worker (MemoryPlan). `shares`: positionShares(), for this or a larger N. `reachable`:
 * reachableSides(), the patch sides (and their elements' sides) that get accumulator slots;
 * a hit elsewhere overflows into an entry of its own, so no light is lost; empty gives every
 * side slots. `fraction` gets the share done; false cancels.
 */
ShootingResult shoot(const Scene& scene, const LightSource& source, const SolverOptions& options,
  const RayTracer& tracer, int workers, bool copyPerWorker, const std::vector<double>& shares,
  const std::vector<std::uint8_t>& reachable, const std::function<bool(double fraction)>& fraction,
  double& secondsReducing, Solution& solution);

} // namespace mlr
