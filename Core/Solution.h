// What a solve gives: the radiosity of every element and patch side in every frame, the
// side of each that is lit, and the statistics of the run.
#pragma once

#include "Rgb.h"
#include "Scene.h"
#include "ZeroedMemory.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

namespace mlr
{

struct SolverStatistics
{
  std::uint64_t frames = 0;
  /// The chunks the frames were solved in, of framesPerChunk frames each (Chunks.h).
  std::uint64_t chunks = 1;
  std::uint64_t framesPerChunk = 0;
  /// m, the frames each seam's blend takes from either chunk (0 for one chunk).
  std::uint64_t chunkOverlap = 0;
  /// Of one chunk's frames handed on as it is solved (streamed): the chunk, counted from 1 as
  /// the progress lines count them, and the figures are its solve's (frames: its positions,
  /// its overlap's included) but for the chunks' layout above; -1 for the whole solve's.
  std::int64_t chunk = -1;
  std::uint64_t patches = 0;
  std::uint64_t elements = 0;
  std::uint64_t effectivePathsPerFrame = 0;
  std::uint64_t pathsCast = 0;         ///< shooting paths actually traced, all frames
  std::uint64_t shootingRays = 0;      ///< nearest-hit rays of the shooting walks
  std::uint64_t shadowRays = 0;        ///< visibility rays for the reuse weights
  std::uint64_t shadowRaysBlocked = 0; ///< of shadowRays, those an occluder stopped
  /// Walks whose first ray hit the scene (and, one-sided, a front face): with reuse, each
  /// asks for the visibility of every other position whose unoccluded kernel is not zero.
  std::uint64_t firstHits = 0;
  std::uint64_t gatheringRays = 0;    ///< nearest-hit rays of the final gathering
  std::uint64_t missedRays = 0;       ///< nearest-hit rays that hit nothing
  std::uint64_t gatheringSides = 0;   ///< element sides that gathered
  std::uint64_t reachabilityRays = 0; ///< probes that decided which sides light can reach
  std::uint64_t reachableSides = 0;   ///< patch sides light can reach (the others stay dark)
  /// Element and patch sides judged unreachable that shooting paths hit all the same, summed
  /// over sources and batches: their light went to overflow entries (nothing is lost).
  std::uint64_t overflowSides = 0;
  std::uint64_t sources = 0;         ///< lights shot: moving, static, directional, emitters
  std::uint64_t staticPathsCast = 0; ///< of pathsCast, from sources solved once for all frames
  /// Rays of the pilots that shared the paths out over a moving light's positions (traced
  /// alike on every rank, counted once; in none of the counts above).
  std::uint64_t pilotRays = 0;
  /// Over the reused moving lights, the fewest and most paths a position cast, in units of
  /// the equal share N/n: above 1 at the ends of a trajectory when the frames are balanced.
  double smallestPositionShare = 1;
  double largestPositionShare = 1;
  /// l of the paper: mean number of hits of a path without the lambda cut, from
  /// shootingRays / pathsCast = 1 + lambda (l - 1).
  double meanPathLength = 0;
  double secondsRemeshing = 0; ///< set by callers that remesh before solving
  /// The patch edge length the scene was remeshed to (scene units), by callers that remesh.
  double patchEdgeLength = 0;
  /// Validation, allocation, building the BVH, the pilot and the reachability probes (once
  /// for every chunk: SolveSetup).
  double secondsSetup = 0;
  double secondsShooting = 0;
  double secondsGathering = 0;
  /// Of shooting and gathering, the time spent in sums over ranks and the agreements
  /// between phases (waiting for slower ranks included); 0 on one rank.
  double secondsReducing = 0;
  double secondsTotal = 0;
  /// The memory plan the solve ran under (MemoryPlan): its peak, the results written and
  /// the shooting accumulators of one source, all copies.
  std::uint64_t memoryEstimateBytes = 0;
  std::uint64_t memoryResultBytes = 0;
  std::uint64_t memoryAccumulatorBytes = 0;
  /// What the memory check held against the limit (solveAnimation): the solve in its chunks
  /// with all that lives beside it, the finished frames, the caller's outputs, the scene, its
  /// input and the sensors. The process's peak is this plus the program's own (about 60 MB
  /// for the command line); 0 for a bare solve.
  std::uint64_t memoryCheckedBytes = 0;
  /// The shooting accumulators had one copy per worker (else one shared copy, MemoryPlan).
  bool accumulatorCopyPerWorker = true;
  int threads = 0;
  bool reuseShooting = false;
  bool reuseGathering = false;
  bool twoSided = true;
};

/// What the error estimate of a batched solve found (ErrorEstimate.h); empty without one.
struct ErrorEstimateSummary
{
  std::uint64_t batches = 0;       ///< batches run, all rounds; 0 without an error estimate
  std::uint64_t rounds = 0;        ///< rounds of batches (1 without a target)
  std::uint64_t pathsPerFrame = 0; ///< N of all batches together
  double target = 0;               ///< SolverOptions::targetRelativeError
  /// What ended the batches: "batches" (the fixed count, no target), "target" (reached),
  /// "time limit" or "path limit" (the target was not reached), "batch limit" (a chunk solved
  /// again, SolverOptions::batchLimit).
  std::string stoppedBy;
  /// Solved in chunks: each chunk's batches, in chunk order, for solving one again with the
  /// same bits (solveChunk).
  std::vector<std::uint64_t> chunkBatches;
  /// Per frame, over the lit elements (ErrorEstimate.h): the median and the 95th
  /// percentile of the relative error, and how many elements are lit.
  std::vector<double> relativeErrorMedian, relativeErrorP95;
  std::vector<std::uint64_t> litElements;
};

/// The results of every (element or patch) side and frame, stored (PackedRgb).
using StoredArray = std::vector<PackedRgb, ZeroedAllocator<PackedRgb>>;

/**
 * Radiosity (W/m^2) of every element and patch side, for every frame, and the irradiance
 * of every element side it comes from.
 *
 * B_total = E + B_direct + B_indirect for elements, E the self-emission of the front side.
 * B_direct comes from the shooting walks' first hits (from every light and emitter);
 * B_indirect from final gathering of the patches' shooting solution. Elements store the
 * irradiance (the power arriving per area, the emission of the surface itself excluded) and
 * B_direct = rho_e E_direct, B_indirect = rho_e E_indirect, so that a black element has its
 * irradiance too, at no memory per frame beyond the radiosity's (Documentation/Method.md,
 * section 15). Both sides are kept; litSide() and patchLitSide() pick the one to show,
 * chosen once when the solve ends, one per surface.
 */
class Solution
{
public:
  Solution() = default;
  Solution(std::size_t frames, std::size_t elements, std::size_t patches);

  std::size_t frameCount() const { return this->Frames; }
  std::size_t elementCount() const { return this->Elements; }
  std::size_t patchCount() const { return this->Patches; }

  /// rho_e, which turns an element's irradiance into radiosity.
  const Rgb& reflectance(std::size_t element) const { return this->Reflectance[element]; }
  Rgb direct(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Reflectance[element] * this->directIrradiance(frame, element, side);
  }
  /// Zero until gathering has run.
  Rgb indirect(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Reflectance[element] * this->indirectIrradiance(frame, element, side);
  }
  /// The irradiance (W/m^2) of an element side from the lights' and emitters' first hits.
  Rgb directIrradiance(std::size_t frame, std::size_t element, Side side) const
  {
    return this->load(this->Direct[this->elementIndex(frame, element, side)]);
  }
  /// The irradiance from the rest of the scene: gathering's mean of the patch radiosity its
  /// rays reach (k = 0: see indirectFromPatches). Zero until gathering has run.
  Rgb indirectIrradiance(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Indirect.empty()
      ? Rgb()
      : this->load(this->Indirect[this->elementIndex(frame, element, side)]);
  }
  /// All the light arriving on an element side: total() = emitted() + rho_e irradiance().
  Rgb irradiance(std::size_t frame, std::size_t element, Side side) const
  {
    return this->directIrradiance(frame, element, side) +
      this->indirectIrradiance(frame, element, side);
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
  /// The patch-level shooting solution (all bounces): its bounced light and the mean direct
  /// radiosity of its four elements (of equal areas: the midpoints split it).
  Rgb patchRadiosity(std::size_t frame, std::size_t patch, Side side) const
  {
    Rgb direct;
    for (std::size_t e = patch * Scene::ElementsPerPatch; e < (patch + 1) * Scene::ElementsPerPatch;
         ++e)
    {
      direct += this->direct(frame, e, side);
    }
    return this->patchBounced(frame, patch, side) +
      direct * (1.0 / static_cast<double>(Scene::ElementsPerPatch));
  }
  /// Of patchRadiosity(), the light that reached the patch after at least one bounce (W/m^2),
  /// reflected: the part gathering reads per patch (gatheredRadiosity() in Gathering.h).
  Rgb patchBounced(std::size_t frame, std::size_t patch, Side side) const
  {
    return this->load(this->Patch[this->patchIndex(frame, patch, side)]);
  }
  /// The side of an element that is shown: its surface's (chooseLitSides).
  Side litSide(std::size_t element) const { return this->LitSide[element]; }
  /// The same for a patch: its surface's side, the side its elements show.
  Side patchLitSide(std::size_t patch) const { return this->PatchLitSide[patch]; }
  /// Sums over frames of the light on an element's two sides (W/m^2, channels summed): its
  /// radiosity's total() and its irradiance's.
  struct SideTotals
  {
    double front = 0, back = 0, irradianceFront = 0, irradianceBack = 0;
    SideTotals& operator+=(const SideTotals& other)
    {
      this->front += other.front;
      this->back += other.back;
      this->irradianceFront += other.irradianceFront;
      this->irradianceBack += other.irradianceBack;
      return *this;
    }
  };
  /// Element `element`'s sums over the frames held, added in frame order; its irradiance's
  /// only when its radiosity's are both 0 (else 0: chooseLitSides reads them only then).
  SideTotals elementTotals(std::size_t element) const;
  /**
   * Chooses litSide() and patchLitSide() from the radiosity, once it is complete: every
   * surface of `scene` (Scene::patchRegion) shows one side, which litSideOf picks from the
   * area-weighted sums of its elements' totals (Documentation/Method.md, section 10). On
   * `workers` threads, the same sides for any count.
   */
  void chooseLitSides(const Scene& scene, int workers);
  /// The same from every element's totals given by `totals`, for callers that sum the frames
  /// elsewhere (ranks holding frames apart sum elementTotals over the ranks).
  void chooseLitSides(
    const Scene& scene, const std::function<SideTotals(std::size_t element)>& totals, int workers);
  /// The area-weighted sums of the elements' totals over each surface of `scene`, which
  /// chooseLitSides chooses from: one per region (Scene::patchRegion).
  std::vector<SideTotals> surfaceTotals(const Scene& scene, int workers) const;
  /// The rule chooseLitSides applies to a surface's totals on its two sides (its irradiance's,
  /// for a black surface whose totals are both 0): the larger, front on a tie.
  static Side litSideOf(double front, double back, double irradianceFront, double irradianceBack)
  {
    const bool black = front == 0 && back == 0;
    return (black ? irradianceBack > irradianceFront : back > front) ? Side::Back : Side::Front;
  }

  /// Whether the solve estimated its error (SolverOptions::errorBatches > 1).
  bool hasErrorEstimate() const { return !this->StdError.empty(); }
  /// The standard error of irradiance() (W/m^2, RGB) from the spread of the batches, direct
  /// and indirect light together; zero without an error estimate.
  Rgb irradianceStdError(std::size_t frame, std::size_t element, Side side) const
  {
    return this->StdError.empty()
      ? Rgb()
      : this->load(this->StdError[this->elementIndex(frame, element, side)]);
  }
  /// The standard error of total(): the emission is exact, so rho_e times irradianceStdError().
  Rgb radiosityStdError(std::size_t frame, std::size_t element, Side side) const
  {
    return this->Reflectance[element] * this->irradianceStdError(frame, element, side);
  }

  SolverStatistics statistics;
  ErrorEstimateSummary errorEstimate;
  std::vector<std::string> warnings;

  // Storage is side-major, then element- (patch-) major with frames innermost: scoring one
  // hit for all frames touches one contiguous run, and the sides light cannot reach (the
  // outsides of a closed room, the insides of its blocks) lie in long runs of one side's
  // array that shooting and gathering never write (ZeroedAllocator).
  std::size_t elementIndex(std::size_t frame, std::size_t element, Side side) const
  {
    return (static_cast<std::size_t>(side) * this->Elements + element) * this->Frames + frame;
  }
  std::size_t patchIndex(std::size_t frame, std::size_t patch, Side side) const
  {
    return (static_cast<std::size_t>(side) * this->Patches + patch) * this->Frames + frame;
  }
  // Results are stored in 16 bits per channel (PackedRgb: within 0.1% of the value, 6 bytes
  // per RGB; see MemoryPlan), divided by storageScale().
  /**
   * The unit of the stored values, a power of two (so that scaling is exact): a value is
   * stored as load() / storageScale(). The solver sets it to about the scene's mean
   * irradiance, its lights' power over its area (storageScaleFor), so that any scene in any
   * unit and of any power stores its irradiance as about 1, in the middle of PackedRgb's
   * range of 2^-62 to 2^64. Results of one scene share it, so blends and sums of stored
   * values need no scaling.
   */
  double storageScale() const { return this->Scale; }
  void setStorageScale(double scale) { this->Scale = scale; }
  /// 2^round(log2(power / area)); the area alone for a power that is not positive and
  /// finite (lights all off), and 1 for an area that is not.
  static double storageScaleFor(double totalArea, double power);
  Rgb load(const PackedRgb& stored) const { return Rgb(stored) * this->Scale; }
  PackedRgb store(const Rgb& value) const { return PackedRgb(value / this->Scale); }
  /// Adds `value` (W/m^2) to a stored value, rounded once.
  void addTo(PackedRgb& stored, const Rgb& value) const
  {
    stored = this->store(this->load(stored) + value);
  }
  /// The direct irradiance of every element side and frame.
  StoredArray& directData() { return this->Direct; }
  const StoredArray& directData() const { return this->Direct; }
  /// The indirect irradiance. Empty until allocateIndirect(): the solver allocates it once the
  /// shooting accumulators are freed, so that the two never take memory at once.
  StoredArray& indirectData() { return this->Indirect; }
  void allocateIndirect() { this->Indirect = StoredArray(this->Direct.size()); }
  /// Zeroes the direct light and the patches and frees the indirect light, for the next
  /// batch of a batched solve (the reflectance and emission stay).
  void clearRadiosity();
  /// The standard error of the irradiance of every element side and frame, or empty.
  StoredArray& stdErrorData() { return this->StdError; }
  /// The patches' bounced light (patchBounced()) of every patch side and frame.
  StoredArray& patchData() { return this->Patch; }
  std::vector<Side>& litSideData() { return this->LitSide; }
  std::vector<Side>& patchLitSideData() { return this->PatchLitSide; }
  /// One per element, or empty when nothing emits.
  std::vector<Rgb>& emissionData() { return this->Emission; }
  /// rho_e of every element, which turns irradiance into radiosity; 1 until the solver sets
  /// the scene's.
  std::vector<Rgb>& reflectanceData() { return this->Reflectance; }

private:
  std::size_t Frames = 0, Elements = 0, Patches = 0;
  double Scale = 1;
  StoredArray Direct, Indirect, Patch, StdError;
  std::vector<Rgb> Emission, Reflectance;
  std::vector<Side> LitSide, PatchLitSide;
};

} // namespace mlr
