// Final gathering: the indirect light of every element side from the patches' shooting
// solution, with one set of rays for every frame (reuse) or one per frame.
#pragma once

#include "MemoryPlan.h"
#include "Solution.h"
#include "SolverOptions.h"
#include "WorkerCounters.h"

#include <cstdint>
#include <functional>
#include <vector>

namespace mlr
{

class RayTracer;

/// The frames of a block of rows: as many as fit in `rowBytes`, at least one.
std::size_t gatheringBlockFrames(std::size_t elements, std::size_t frames, std::uint64_t rowBytes);

/**
 * What a gathering ray (or a sensor's ray) that reaches element side (`element`, `side`) reads
 * in `frame`: the bounced light of its patch, reconstructed at the element
 * (LinearStencil::elementValues: the patch's mean moved along its limited gradient), plus its
 * own direct radiosity. The direct light, with its shadow edges, is known per element; the
 * light of later bounces is summed per patch, whose neighbours give its slope.
 */
Rgb gatheredRadiosity(
  const Scene& scene, const Solution& solution, std::size_t frame, std::size_t element, Side side);

/// gatheredRadiosity() of the four elements of side `side` of `patch` in `frame`, into `out`,
/// from one reconstruction of the patch's bounced light.
void gatheredRadiosities(const Scene& scene, const Solution& solution, std::size_t frame,
  std::size_t patch, Side side, Rgb* out);

/**
 * The element sides that gather: those of reachable patch sides whose reflectance is not
 * zero (a black element reflects nothing it gathers). Returns them as element * 2 + side,
 * in element order, and sets `rays` to the mean number each casts so that together they cast
 * `total`, at least one each (raysOfSide).
 */
std::vector<std::uint32_t> gatheringSides(const Scene& scene,
  const std::vector<std::uint8_t>& reachable, double& rays, std::uint64_t total);

/**
 * The rays one side casts for a mean of `raysPerSide` (at least 1): its whole part, and one
 * more with the probability of its fraction, drawn from a stream keyed by the seed and the
 * side. The sides together cast raysPerSide times their number on average. Rounding the mean
 * instead would cast up to a third fewer rays than asked (1.45 a side becomes 1). The counts
 * differ by one at most, so every side's estimate is nearly equally accurate, and they do not
 * depend on the threads, the ranks or the chunk.
 */
std::uint64_t raysOfSide(double raysPerSide, std::uint64_t seed, std::uint32_t elementSide);

/**
 * The reachable element sides of black patches, as element * 2 + side in element order: they
 * gather for their irradiance alone (their radiosity is zero), at the rate gatheringSides()
 * sets for the others.
 */
std::vector<std::uint32_t> blackSides(
  const Scene& scene, const std::vector<std::uint8_t>& reachable);

/// What gathering traced on this rank.
struct GatheringResult
{
  std::uint64_t sides = 0; ///< element sides that gathered (on every rank)
  WorkerCounters counters;
};

/**
 * Gathers k N rays (options.gatheringRatio) over the gathering sides of the `reachable` patch
 * sides (and as many per side over their blackSides()), shared by the ranks and summed over them,
 * into solution's indirect light (which must be allocated). `fraction` gets the share done; false
 * cancels. The result does not depend on `budget`: each frame sums its rays in the same order.
 */
GatheringResult gatherIndirect(const Scene& scene, const RayTracer& tracer,
  const SolverOptions& options, const std::vector<std::uint8_t>& reachable, int workers,
  const std::function<bool(double fraction)>& fraction, double& secondsReducing, Solution& solution,
  const GatheringBudget& budget = {});

/// Without gathering (k = 0) an element's indirect radiosity is its patch's bounced light
/// (Solution::patchBounced), and its indirect irradiance that divided by the patch's
/// reflectance: zero in a channel the patch does not reflect, so that a black patch shows only
/// its direct irradiance.
void indirectFromPatches(const Scene& scene, Solution& solution);

} // namespace mlr
