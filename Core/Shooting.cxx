#include "Shooting.h"

#include "Error.h"
#include "FixedPointAccumulator.h"
#include "Parallel.h"
#include "Random.h"
#include "Ranks.h"
#include "RayTracer.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace mlr
{

namespace
{
/// A walk longer than this is cut, which bounds the time between two cancellation checks.
/// Roulette survives with the largest reflectance channel rho_max < 1, so a walk reaches
/// this length with probability rho_max^(2^24): the power the cut loses is below 1e-7 of the
/// walk's for every rho_max <= 1 - 1e-6 (TestOccluders checks rho = 0.999).
constexpr int MaximumBounces = 1 << 24;

/// Shooting paths per task: small enough that cancellation is noticed within
/// milliseconds, large enough that scheduling costs nothing.
constexpr std::uint64_t ReusedPathsPerTask = 256;
constexpr std::uint64_t ClassicPathsPerTask = 2048;

/// The pilot that balances the frames keeps one float per pilot and position: at most this
/// many (32 MiB).
constexpr std::uint64_t PilotValues = 1 << 23;
/// Bounds on a position's share of the paths, in units of the equal share 1/n: the ends of
/// an animation may take up to four times the middle's, and no position falls below a
/// quarter, which keeps every frame's weights bounded.
constexpr double BalanceLowest = 0.25;
constexpr double BalanceHighest = 4.0;
constexpr int BalanceIterations = 40;

/// The rounding quantum of a fixed-point channel whose value per path is about `scale` / N
/// for N `paths` per frame: a power of two that makes that value 2^20 to 2^21 quanta
/// (FixedPointTypicalAddBits). Above 2^30 paths the quantum stays that of 2^30, so that a
/// slot holds at least 2^13 times `scale` (a closed white box reflects its light about
/// 1 / (1 - rho) times).
double quantumFor(double scale, std::uint64_t paths)
{
  const int pathBits =
    std::min(30, std::ilogb(static_cast<double>(std::max<std::uint64_t>(paths, 1))));
  return scale > 0 && std::isfinite(scale) ? std::ldexp(scale, -FixedPointTypicalAddBits - pathBits)
                                           : 1.0;
}

/// M_k for the k-th of `active` positions, adding up to N: equal counts for empty `shares`;
/// else floor(alpha_k N), at least one, and the remainder to the largest fractions (the lower
/// position first on a tie).
std::vector<std::uint64_t> pathCounts(
  const std::vector<double>& shares, std::size_t active, std::uint64_t N)
{
  std::vector<std::uint64_t> counts(active);
  if (shares.empty())
  {
    for (std::uint64_t a = 0; a < active; ++a)
    {
      counts[a] = N / active + (a < N % active ? 1 : 0);
    }
    return counts;
  }
  std::uint64_t given = 0;
  std::vector<std::pair<double, std::size_t>> fractions(active);
  for (std::size_t a = 0; a < active; ++a)
  {
    const double exact = shares[a] * double(N);
    counts[a] = std::max<std::uint64_t>(1, static_cast<std::uint64_t>(exact));
    fractions[a] = { exact - std::floor(exact), a };
    given += counts[a];
  }
  std::stable_sort(fractions.begin(), fractions.end(),
    [](const auto& x, const auto& y) { return x.first > y.first; });
  for (std::size_t i = 0; given < N; i = (i + 1) % active, ++given)
  {
    ++counts[fractions[i].second];
  }
  while (given > N)
  {
    --*std::max_element(counts.begin(), counts.end());
    --given;
  }
  return counts;
}

/// The shooting of one LightSource into its own accumulators, added to the solution at the end.
class ShootingRun
{
public:
  ShootingRun(const Scene& scene, const LightSource& source, const SolverOptions& options,
    const RayTracer& tracer, int workers, bool copyPerWorker, const std::vector<double>& shares,
    const std::vector<std::uint8_t>& reachable)
    : SceneRef(scene)
    , SourceRef(source)
    , Options(options)
    , Tracer(tracer)
    , Frames(source.positions())
    , Reuse(options.reuseShooting && source.positions() > 1)
    , StoredElementSides(reachable.empty() ? std::vector<std::uint8_t>() : expand(reachable))
    , ElementShare(workers, copyPerWorker, scene.elementCount(), source.positions(),
        quantumFor(1.0, options.pathsPerFrame),
        Reuse ? FrameLayout::FramesInner : FrameLayout::FramesOuter,
        reachable.empty() ? nullptr : &StoredElementSides)
    , PatchPower(workers, copyPerWorker, scene.patchCount(), source.positions(),
        { quantumFor(source.power().r, options.pathsPerFrame),
          quantumFor(source.power().g, options.pathsPerFrame),
          quantumFor(source.power().b, options.pathsPerFrame) },
        Reuse ? FrameLayout::FramesInner : FrameLayout::FramesOuter,
        reachable.empty() ? nullptr : &reachable)
    , Counters(static_cast<std::size_t>(workers))
    , Scratch(static_cast<std::size_t>(workers))
  {
    for (KernelScratch& s : this->Scratch)
    {
      s.resize(this->Frames);
    }
    // M_k paths start from active position k; they add up to N exactly. Positions that are
    // off cast nothing: their frames are zero, and every active frame j still has M_j > 0 in
    // its weights' denominator, so no light is lost.
    this->setPathCounts(pathCounts(shares, source.activePositions().size(), options.pathsPerFrame));
  }

  bool reuses() const { return this->Reuse; }

  /// Element sides (element * 2 + side) of the reachable patch sides.
  static std::vector<std::uint8_t> expand(const std::vector<std::uint8_t>& patchSides)
  {
    std::vector<std::uint8_t> sides(patchSides.size() * Scene::ElementsPerPatch);
    for (std::size_t i = 0; i < sides.size(); ++i)
    {
      sides[i] = patchSides[Scene::patchOfElement(i / 2) * 2 + i % 2];
    }
    return sides;
  }

  void shootReused(std::uint64_t path, int worker);
  void shootClassic(std::size_t position, std::uint64_t path, int worker);
  /// Adds this source's light to `solution` (the elements' irradiance, the patches'
  /// radiosity): frame f gets position f, or the one position of a static source, times
  /// that position's power factor.
  /// The sums' pages are given back as they are read (releaseBefore): the run ends here.
  void addTo(Solution& solution);

  const std::vector<WorkerCounters>& counters() const { return this->Counters; }

  /// Sums the workers' scores, and then those of the ranks (SolverOptions::sumAcrossRanks):
  /// integers, so every rank then holds exactly the serial sums, whatever rank and worker
  /// traced each path. The sides that overflowed on any rank get an entry on every rank.
  /// Returns the sides without slots that paths scored, elements' and patches'.
  std::uint64_t sumAcrossWorkersAndRanks(double& secondsReducing)
  {
    return sumOne(this->ElementShare, this->SceneRef.elementCount(), secondsReducing) +
      sumOne(this->PatchPower, this->SceneRef.patchCount(), secondsReducing);
  }

  /// Which active position path `path` of a reuse solve starts from, and its index among that
  /// position's paths: paths are numbered position by position, M_k of them for the k-th
  /// active position.
  std::size_t positionOfPath(std::uint64_t path, std::uint64_t& index) const
  {
    const auto next = std::upper_bound(this->FirstPath.begin(), this->FirstPath.end(), path);
    const auto a = static_cast<std::size_t>(next - this->FirstPath.begin() - 1);
    index = path - this->FirstPath[a];
    return this->SourceRef.activePositions()[a];
  }

  /// M_k of every position (0 for positions that are off).
  const std::vector<double>& pathsFromPosition() const { return this->PathsFromPosition; }

private:
  template <int Channels>
  std::uint64_t sumOne(
    FixedPointAccumulator<Channels>& sums, std::size_t records, double& secondsReducing)
  {
    const bool ranks = this->Options.ranks > 1;
    std::int64_t* first = sums.collapse();
    if (ranks)
    {
      mlr::sumAcrossRanks(this->Options, first, sums.copySize(), secondsReducing);
    }
    std::vector<std::int64_t> flags(records * 2, 0);
    sums.markOverflow(flags);
    if (ranks)
    {
      mlr::sumAcrossRanks(this->Options, flags.data(), flags.size(), secondsReducing);
    }
    std::size_t count = 0;
    std::int64_t* merged = sums.mergeOverflow(flags, count);
    if (ranks)
    {
      mlr::sumAcrossRanks(this->Options, merged, count, secondsReducing);
    }
    return static_cast<std::uint64_t>(
      std::count_if(flags.begin(), flags.end(), [](std::int64_t f) { return f != 0; }));
  }

  bool emit(RandomStream& random, std::size_t position, int worker, EmittedPath& path, RayHit& hit);
  void scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
    std::size_t firstFrame, std::size_t frameCount, int worker);
  // Always inlined, like the prefetch it calls: GCC would delete the call otherwise.
  [[gnu::always_inline]] inline void prefetchFirstHit(
    const RayHit& hit, std::size_t firstFrame, std::size_t frameCount, int worker);

  const Scene& SceneRef;
  const LightSource& SourceRef;
  const SolverOptions& Options;
  const RayTracer& Tracer;
  std::size_t Frames;
  bool Reuse;
  /// The element sides with accumulator slots: those of the reachable patch sides (empty:
  /// every side).
  std::vector<std::uint8_t> StoredElementSides;
  // Direct light needs one scalar per element side and frame: the share of the source's
  // power whose first hit lands there. Its colour rho_e Phi is the same for every hit, and
  // a scalar is a third of the memory traffic of RGB in the hottest loop.
  FixedPointAccumulator<1> ElementShare;
  // The patch solution's reflected power (W), RGB, from the second hit of a walk on; the
  // first hits come from ElementShare.
  FixedPointAccumulator<3> PatchPower;
  std::vector<WorkerCounters> Counters;
  std::vector<KernelScratch> Scratch;
  std::vector<double> PathsFromPosition;
  /// The first path of each active position, and N at the end.
  std::vector<std::uint64_t> FirstPath;

  void setPathCounts(const std::vector<std::uint64_t>& counts)
  {
    const std::vector<std::size_t>& positions = this->SourceRef.activePositions();
    this->PathsFromPosition.assign(this->Frames, 0.0);
    this->FirstPath.assign(counts.size() + 1, 0);
    for (std::size_t a = 0; a < counts.size(); ++a)
    {
      this->PathsFromPosition[positions[a]] = static_cast<double>(counts[a]);
      this->FirstPath[a + 1] = this->FirstPath[a] + counts[a];
    }
  }
};

/**
 * Scores a walk's first hit on the element (direct) and patch, then follows it: continue
 * with probability lambda, and at every later hit score the patch and play Russian
 * roulette with the maximum reflectance channel. shares[f] is the fraction of the source's
 * power the walk carries to its first hit in frame firstFrame + f: 1/N for a classic path,
 * G_j(y) / sum_k M_k G_k(y) for a reused one. A walk's power in frame f is then
 * colour * shares[f], with one RGB colour for all frames: the frames differ only by scalar
 * weights (and the power factors, applied when the sums become radiosity).
 *
 * A surviving walk carries rho * P / lambda, not P / lambda: the power that leaves the first
 * hit is the reflected power (Documentation/Method.md, section 2; the energy balance test
 * checks this).
 */
void ShootingRun::scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
  std::size_t firstFrame, std::size_t frameCount, int worker)
{
  // The first hit scores only the element's share: the patch's first-hit power is
  // rho_p Phi times the shares of its four elements, added when shooting ends. That keeps
  // the RGB patch slots (3n values) out of the one write every path makes.
  const int firstSide = static_cast<int>(firstHit.side);
  const Rgb& firstRho = this->SceneRef.elementReflectance(firstHit.element);
  Rgb colour = firstRho * this->SourceRef.power();
  {
    const SlotRun elementSlots = this->ElementShare.slots(worker, firstHit.element, firstSide);
    for (std::size_t f = 0; f < frameCount; ++f)
    {
      this->ElementShare.add(elementSlots, firstFrame + f, &shares[f]);
    }
    const double lambda = this->Options.firstBounceSurvival;
    if (random.uniform() >= lambda)
    {
      return;
    }
    colour = colour / lambda;
  }

  // A bounce's score is written after the next ray is traced: its slots were prefetched
  // when the hit was found, so the trace hides the cache miss.
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  SlotRun pendingSlots;
  Rgb pendingPower;
  auto scorePending = [&]
  {
    if (pendingSlots.low)
    {
      for (std::size_t f = 0; f < frameCount; ++f)
      {
        const double power[3] = { pendingPower.r * shares[f], pendingPower.g * shares[f],
          pendingPower.b * shares[f] };
        this->PatchPower.add(pendingSlots, firstFrame + f, power);
      }
      pendingSlots.low = nullptr;
    }
  };
  RayHit hit = firstHit;
  for (int bounce = 0; bounce < MaximumBounces; ++bounce)
  {
    const Vec3 normal = this->SceneRef.elementSideNormal(hit.element, hit.side);
    const Vec3 direction = sampleCosineDirection(normal, random);
    ++counters.shootingRays;
    RayHit next;
    const bool found =
      this->Tracer.intersect(this->Tracer.liftOff(hit.point, normal), direction, next);
    scorePending();
    if (!found)
    {
      ++counters.missedRays;
      return;
    }
    if (!this->Options.twoSided && next.side == Side::Back)
    {
      return;
    }
    const std::size_t patch = Scene::patchOfElement(next.element);
    const Rgb& rho = this->SceneRef.patchReflectance(patch);
    pendingPower = rho * colour;
    pendingSlots = this->PatchPower.slots(worker, patch, static_cast<int>(next.side));
    this->PatchPower.prefetch(pendingSlots, firstFrame, frameCount);
    const double survival = rho.maxComponent();
    if (!(survival > 0) || random.uniform() >= survival)
    {
      scorePending();
      return;
    }
    colour = pendingPower / survival;
    hit = next;
  }
  scorePending();
}

/// Called as soon as a walk's first hit is known, so that the weights and shadow rays
/// computed before scoring hide the cache misses of the slots it will score.
inline void ShootingRun::prefetchFirstHit(
  const RayHit& hit, std::size_t firstFrame, std::size_t frameCount, int worker)
{
  this->ElementShare.prefetch(
    this->ElementShare.slots(worker, hit.element, static_cast<int>(hit.side)), firstFrame,
    frameCount);
}

/// Starts a walk from the source at `position` and traces its first ray. False when the walk
/// ends there: a miss (the power leaves the scene) or, with one-sided surfaces, a back face.
bool ShootingRun::emit(
  RandomStream& random, std::size_t position, int worker, EmittedPath& path, RayHit& hit)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  this->SourceRef.emit(position, random, this->Tracer.surfaceOffset(), path);
  ++counters.shootingRays;
  if (!this->Tracer.intersect(path.start, path.direction, hit))
  {
    ++counters.missedRays;
    return false;
  }
  ++counters.firstHits;
  if (!this->Options.twoSided && hit.side == Side::Back)
  {
    ++counters.firstHitsOnBack;
    return false;
  }
  return true;
}

void ShootingRun::shootReused(std::uint64_t path, int worker)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  KernelScratch& scratch = this->Scratch[static_cast<std::size_t>(worker)];
  // Keyed by the position's frame and the path's index there, not by `path`: a chunk that
  // solves the same position with as many paths casts the same ones, so that two chunks'
  // estimates of the frames they share are correlated and their blend does not flicker.
  std::uint64_t index = 0;
  const std::size_t origin = this->positionOfPath(path, index);
  RandomStream random(
    this->Options.seed, StreamPurpose::Shooting, index, this->SourceRef.positionStream(origin));

  EmittedPath emitted;
  RayHit hit;
  if (!this->emit(random, origin, worker, emitted, hit))
  {
    return;
  }
  this->prefetchFirstHit(hit, 0, this->Frames, worker);

  // Mixture weights w_j = G_j(y) / sum_k M_k G_k(y), with real visibility: one shadow ray
  // per other position whose unoccluded kernel is not zero (the origin's is known).
  const std::size_t shadowCount = this->SourceRef.kernel(emitted, hit.point,
    this->SceneRef.elementSideNormal(hit.element, hit.side), origin, this->Tracer, scratch);
  double* kernel = scratch.kernel.data();
  counters.shadowRays += shadowCount;
  for (std::size_t s = 0; s < shadowCount; ++s)
  {
    if (!scratch.visible[s])
    {
      kernel[scratch.targetFrames[s]] = 0;
      ++counters.shadowRaysBlocked;
    }
  }
  // Four running sums, so that the additions do not wait on each other (one chain of n
  // dependent additions per path).
  const double* counts = this->PathsFromPosition.data();
  double sums[4] = { 0, 0, 0, 0 };
  std::size_t k = 0;
  for (; k + 4 <= this->Frames; k += 4)
  {
    for (std::size_t l = 0; l < 4; ++l)
    {
      sums[l] += counts[k + l] * kernel[k + l];
    }
  }
  for (; k < this->Frames; ++k)
  {
    sums[0] += counts[k] * kernel[k];
  }
  const double mixture = (sums[0] + sums[1]) + (sums[2] + sums[3]);
  if (!(mixture > 0))
  {
    return; // grazing to the last bit: the path carries nothing
  }
  const double inverseMixture = 1.0 / mixture;
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    kernel[j] *= inverseMixture;
  }
  this->scoreAndWalk(random, hit, kernel, 0, this->Frames, worker);
}

} // namespace

std::vector<double> positionShares(const Scene& scene, const LightSource& source,
  const SolverOptions& options, const RayTracer& tracer, int workers,
  const std::function<bool(double fraction)>& fraction, std::uint64_t& pilotRays)
{
  const std::vector<std::size_t>& positions = source.activePositions();
  const std::size_t n = positions.size();
  const std::uint64_t N = options.pathsPerFrame;
  // With a few paths per position there is nothing to move, and the pilot would cost more
  // than the paths it places.
  if (!options.reuseShooting || source.positions() < 2 || !options.balanceFrames || n < 3 ||
    N < 8 * n)
  {
    return {};
  }
  // About N/32 pilots (at least 1,000 unless that is over N/4), and at most PilotValues values.
  const std::size_t pilots =
    static_cast<std::size_t>(std::min(std::max(N / 32, std::min<std::uint64_t>(N / 4, 1000)),
      std::max<std::uint64_t>(1000, PilotValues / n)));

  // u[s][a] = G_a(y_s) / sum_m G_m(y_s), with visibility: pilot s from the equal mixture
  // (its position drawn uniformly, so the pilots are exact samples of it).
  std::vector<float> u(pilots * n, 0.0f);
  constexpr std::size_t PilotsPerTask = 64;
  std::vector<std::uint64_t> rays(static_cast<std::size_t>(workers), 0);
  std::vector<KernelScratch> scratches(static_cast<std::size_t>(workers));
  for (KernelScratch& s : scratches)
  {
    s.resize(source.positions());
  }
  parallelFor((pilots + PilotsPerTask - 1) / PilotsPerTask, workers,
    [&](std::size_t task, int worker)
    {
      KernelScratch& scratch = scratches[static_cast<std::size_t>(worker)];
      std::uint64_t& traced = rays[static_cast<std::size_t>(worker)];
      for (std::size_t s = task * PilotsPerTask; s < std::min(pilots, (task + 1) * PilotsPerTask);
           ++s)
      {
        RandomStream random(options.seed, StreamPurpose::Pilot, s, source.stream());
        const std::size_t origin =
          positions[std::min(n - 1, static_cast<std::size_t>(random.uniform() * double(n)))];
        EmittedPath emitted;
        RayHit hit;
        source.emit(origin, random, tracer.surfaceOffset(), emitted);
        ++traced;
        if (!tracer.intersect(emitted.start, emitted.direction, hit) ||
          (!options.twoSided && hit.side == Side::Back))
        {
          continue; // scores nothing in any frame
        }
        const std::size_t shadowCount = source.kernel(emitted, hit.point,
          scene.elementSideNormal(hit.element, hit.side), origin, tracer, scratch);
        traced += shadowCount;
        for (std::size_t r = 0; r < shadowCount; ++r)
        {
          if (!scratch.visible[r])
          {
            scratch.kernel[scratch.targetFrames[r]] = 0;
          }
        }
        double sum = 0;
        for (std::size_t a = 0; a < n; ++a)
        {
          sum += scratch.kernel[positions[a]];
        }
        if (sum > 0)
        {
          for (std::size_t a = 0; a < n; ++a)
          {
            u[s * n + a] = static_cast<float>(scratch.kernel[positions[a]] / sum);
          }
        }
      }
    },
    [&](std::size_t) { return !fraction || fraction(0.0); });
  for (std::uint64_t r : rays)
  {
    pilotRays += r;
  }

  // Frame j's variance against classic's at equal N, for shares alpha (sum 1): with paths
  // drawn from q' = sum_a alpha_a q_a, R_j = E_q'[(q_j / q')^2] / c_j, c_j the share of
  // frame j's own paths that hit the scene, estimated from the pilots by reweighting them
  // from the equal mixture to q'. Shares move by the square root of R until every frame has
  // the same. The sums over the pilots run over fixed blocks of them, added in block order:
  // the choice does not depend on the threads, and the passes over S x n values use them all.
  constexpr std::size_t PilotsPerBlock = 256;
  const std::size_t blocks = (pilots + PilotsPerBlock - 1) / PilotsPerBlock;
  std::vector<double> alpha(n, 1.0 / double(n)), ratio(n), first(n, 0.0), second(n);
  std::vector<double> blockSums(blocks * n);
  for (std::size_t s = 0; s < pilots; ++s)
  {
    for (std::size_t a = 0; a < n; ++a)
    {
      first[a] += u[s * n + a];
    }
  }
  const double low = BalanceLowest / double(n), high = BalanceHighest / double(n);
  for (int iteration = 0; iteration < BalanceIterations; ++iteration)
  {
    parallelFor(
      blocks, workers,
      [&](std::size_t block, int)
      {
        double* sums = blockSums.data() + block * n;
        std::fill(sums, sums + n, 0.0);
        for (std::size_t s = block * PilotsPerBlock;
             s < std::min(pilots, (block + 1) * PilotsPerBlock); ++s)
        {
          const float* values = u.data() + s * n;
          // Four running sums, so that the additions do not wait on each other.
          double d[4] = { 0, 0, 0, 0 };
          std::size_t a = 0;
          for (; a + 4 <= n; a += 4)
          {
            for (std::size_t l = 0; l < 4; ++l)
            {
              d[l] += alpha[a + l] * values[a + l];
            }
          }
          for (; a < n; ++a)
          {
            d[0] += alpha[a] * values[a];
          }
          const double denominator = (d[0] + d[1]) + (d[2] + d[3]);
          if (denominator > 0)
          {
            const double inverse = 1.0 / denominator;
            for (a = 0; a < n; ++a)
            {
              const double value = values[a];
              sums[a] += value * value * inverse;
            }
          }
        }
      },
      [&](std::size_t) { return !fraction || fraction(0.0); });
    std::fill(second.begin(), second.end(), 0.0);
    for (std::size_t block = 0; block < blocks; ++block)
    {
      for (std::size_t a = 0; a < n; ++a)
      {
        second[a] += blockSums[block * n + a];
      }
    }
    double lowest = 1e300, highest = 0;
    for (std::size_t a = 0; a < n; ++a)
    {
      ratio[a] = first[a] > 0 ? second[a] / first[a] : 0;
      if (ratio[a] > 0)
      {
        lowest = std::min(lowest, ratio[a]);
        highest = std::max(highest, ratio[a]);
      }
    }
    if (!(highest > 0) || highest < 1.01 * lowest)
    {
      break;
    }
    double total = 0;
    for (std::size_t a = 0; a < n; ++a)
    {
      // A frame no pilot reached keeps its share: nothing says how it fares.
      alpha[a] *= ratio[a] > 0 ? std::sqrt(ratio[a]) : 1.0;
      total += alpha[a];
    }
    for (std::size_t a = 0; a < n; ++a)
    {
      alpha[a] = std::clamp(alpha[a] / total, low, high);
    }
  }

  double total = 0;
  for (double a : alpha)
  {
    total += a;
  }
  for (double& a : alpha)
  {
    a /= total;
  }
  return alpha;
}

namespace
{
void ShootingRun::shootClassic(std::size_t position, std::uint64_t path, int worker)
{
  RandomStream random(
    this->Options.seed, StreamPurpose::Shooting, path, this->SourceRef.positionStream(position));
  EmittedPath emitted;
  RayHit hit;
  if (!this->emit(random, position, worker, emitted, hit))
  {
    return;
  }
  const double share = 1.0 / static_cast<double>(this->Options.pathsPerFrame);
  this->scoreAndWalk(random, hit, &share, position, 1, worker);
}

void ShootingRun::addTo(Solution& solution)
{
  // The sums are collapsed and merged (sumAcrossWorkersAndRanks): each side's run is looked
  // up once, and sides nothing scored (the unreachable ones) are skipped.
  const std::size_t elements = this->SceneRef.elementCount();
  const std::size_t patches = this->SceneRef.patchCount();
  const std::size_t frames = solution.frameCount();
  StoredArray& direct = solution.directData();
  StoredArray& patch = solution.patchData();
  auto positionOf = [&](std::size_t f) { return this->SourceRef.isStatic() ? 0 : f; };
  for (std::size_t e = 0; e < elements; ++e)
  {
    // Irradiance, not radiosity: the Solution applies rho_e, so black elements have it too.
    const Rgb irradiance = this->SourceRef.power() / this->SceneRef.elementArea(e);
    for (int s = 0; s < 2; ++s)
    {
      const SummedRun run = this->ElementShare.summed(e, s);
      if (!run.base)
      {
        continue;
      }
      for (std::size_t f = 0; f < frames; ++f)
      {
        double share = 0;
        this->ElementShare.read(run, positionOf(f), &share);
        if (share != 0)
        {
          solution.addTo(direct[solution.elementIndex(f, e, static_cast<Side>(s))],
            irradiance * this->SourceRef.factor(positionOf(f)) * share);
        }
      }
    }
    this->ElementShare.releaseBefore(e + 1);
  }
  // The patches keep the light that has bounced (Solution::patchBounced): their direct part is
  // their elements', which the Solution adds where the whole patch radiosity is asked for.
  for (std::size_t p = 0; p < patches; ++p)
  {
    const double inverseArea = 1.0 / this->SceneRef.patchArea(p);
    for (int s = 0; s < 2; ++s)
    {
      const SummedRun power = this->PatchPower.summed(p, s);
      if (!power.base)
      {
        continue; // zeros: adding them changes no bit
      }
      for (std::size_t f = 0; f < frames; ++f)
      {
        const std::size_t k = positionOf(f);
        double sums[3];
        this->PatchPower.read(power, k, sums);
        solution.addTo(patch[solution.patchIndex(f, p, static_cast<Side>(s))],
          Rgb(sums[0], sums[1], sums[2]) * this->SourceRef.factor(k) * inverseArea);
      }
    }
    this->PatchPower.releaseBefore(p + 1);
  }
}

} // namespace

void checkPathsPerPosition(const LightSource& source, const SolverOptions& options)
{
  const std::size_t active = source.activePositions().size();
  if (options.reuseShooting && source.positions() > 1 && options.pathsPerFrame < active)
  {
    // With M_k = 0 for some position k, the mixture has holes where only k lights: light
    // would be lost, and the weights would be unbounded.
    throw Error("reusing shooting paths needs at least one path per light position: " +
      std::to_string(options.pathsPerFrame) + " paths per frame is fewer than the " +
      std::to_string(active) + " light positions that emit; give at least " +
      std::to_string(active) + " paths per frame, or turn shooting reuse off");
  }
}

double shootingCost(const LightSource& source, const SolverOptions& options)
{
  return shootingCost(source.positions(), options);
}

double shootingCost(std::size_t positions, const SolverOptions& options)
{
  const double N = static_cast<double>(options.pathsPerFrame);
  const double lambda = options.firstBounceSurvival;
  const double n = static_cast<double>(positions);
  const bool reuse = options.reuseShooting && positions > 1;
  return reuse ? N * (1 + 1.5 * lambda + 0.2 * (n - 1)) : n * N * (1 + 1.5 * lambda);
}

ShootingResult shoot(const Scene& scene, const LightSource& source, const SolverOptions& options,
  const RayTracer& tracer, int workers, bool copyPerWorker, const std::vector<double>& shares,
  const std::vector<std::uint8_t>& reachable, const std::function<bool(double fraction)>& fraction,
  double& secondsReducing, Solution& solution)
{
  ShootingRun run(scene, source, options, tracer, workers, copyPerWorker, shares, reachable);
  const std::uint64_t paths = options.pathsPerFrame;
  const std::vector<std::size_t>& positions = source.activePositions();
  ShootingResult result;
  if (positions.empty())
  {
    // Off in every frame: nothing to add.
  }
  else if (run.reuses())
  {
    const std::uint64_t tasks = (paths + ReusedPathsPerTask - 1) / ReusedPathsPerTask;
    runOnRanks(
      tasks, workers, options,
      [&](std::size_t task, int worker)
      {
        const std::uint64_t end = std::min<std::uint64_t>(paths, (task + 1) * ReusedPathsPerTask);
        for (std::uint64_t p = task * ReusedPathsPerTask; p < end; ++p)
        {
          run.shootReused(p, worker);
        }
      },
      fraction, secondsReducing);
    result.pathsCast = paths;
    const double equal = double(paths) / double(positions.size());
    result.smallestShare = 1e300;
    for (std::size_t k : positions)
    {
      result.smallestShare = std::min(result.smallestShare, run.pathsFromPosition()[k] / equal);
      result.largestShare = std::max(result.largestShare, run.pathsFromPosition()[k] / equal);
    }
  }
  else
  {
    const std::uint64_t tasksPerFrame = (paths + ClassicPathsPerTask - 1) / ClassicPathsPerTask;
    const std::uint64_t tasks = tasksPerFrame * positions.size();
    runOnRanks(
      tasks, workers, options,
      [&](std::size_t task, int worker)
      {
        const std::size_t position = positions[task / tasksPerFrame];
        const std::uint64_t first = (task % tasksPerFrame) * ClassicPathsPerTask;
        const std::uint64_t end = std::min<std::uint64_t>(paths, first + ClassicPathsPerTask);
        for (std::uint64_t p = first; p < end; ++p)
        {
          run.shootClassic(position, p, worker);
        }
      },
      fraction, secondsReducing);
    result.pathsCast = paths * positions.size();
  }
  if (!positions.empty())
  {
    result.overflowSides = run.sumAcrossWorkersAndRanks(secondsReducing);
    run.addTo(solution);
  }
  for (const WorkerCounters& c : run.counters())
  {
    result.counters += c;
  }
  return result;
}

} // namespace mlr
