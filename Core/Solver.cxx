#include "Solver.h"

#include "Error.h"
#include "FixedPointAccumulator.h"
#include "Parallel.h"
#include "Random.h"
#include "RayTracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <exception>
#include <initializer_list>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>

#include <unistd.h>

namespace mlr
{

namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// A walk longer than this is cut, which bounds the time between two cancellation checks.
/// Roulette survives with the largest reflectance channel rho_max < 1, so a walk reaches
/// this length with probability rho_max^(2^24): the power the cut loses is below 1e-7 of the
/// walk's for every rho_max <= 1 - 1e-6 (TestOccluders checks rho = 0.999).
constexpr int MaximumBounces = 1 << 24;

/// Shooting paths per task: small enough that cancellation is noticed within
/// milliseconds, large enough that scheduling costs nothing.
constexpr std::uint64_t ReusedPathsPerTask = 256;
constexpr std::uint64_t ClassicPathsPerTask = 2048;
constexpr std::size_t GatheringSidesPerTask = 32;
constexpr std::size_t ReachabilityPatchesPerTask = 64;

/// Probe walks from each light (spread over its positions) that find the sides it lights
/// first; a fixed number, so that reachability does not depend on N or the seed.
constexpr std::uint64_t ReachabilityProbesPerLight = 16384;
/// The fixed seed of the reachability probes.
constexpr std::uint64_t ReachabilitySeed = 0x5eed;

/// A phase shared by several ranks runs in this many rounds, with an agreement between them:
/// a rank cancelled or failed stops the others within one round. Each agreement waits for
/// the slowest rank, so fewer rounds waste less (measured on 2 ranks: 32 rounds cost a
/// quarter of the solve on a busy machine).
constexpr std::size_t RoundsPerPhase = 8;

/**
 * Runs `tasks` tasks of one phase over this rank's workers. One rank runs them all in one
 * parallelFor. Several ranks cut the phase into rounds and rank r runs the tasks r, r + R,
 * r + 2R, ... of each: every task (path block or side block, keyed by its global index) runs
 * on exactly one rank, and interleaving spreads the dearer light positions over all ranks.
 * `fraction` gets this rank's share done, in [0, 1].
 */
void runOnRanks(std::size_t tasks, int workers, const SolverOptions& options,
  const std::function<void(std::size_t task, int worker)>& body,
  const std::function<bool(double fraction)>& fraction, double& secondsReducing)
{
  const std::size_t ranks = static_cast<std::size_t>(options.ranks);
  const std::size_t rank = static_cast<std::size_t>(options.rank);
  if (ranks <= 1)
  {
    parallelFor(tasks, workers, body, [&](std::size_t done) {
      return fraction(static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(tasks, 1)));
    });
    return;
  }
  const std::size_t rounds = std::min(RoundsPerPhase, std::max<std::size_t>(tasks, 1));
  auto mineOf = [&](std::size_t length) { return length > rank ? (length - rank + ranks - 1) / ranks : 0; };
  std::size_t mineTotal = 0;
  for (std::size_t q = 0; q < rounds; ++q)
  {
    mineTotal += mineOf(tasks * (q + 1) / rounds - tasks * q / rounds);
  }
  std::size_t doneBefore = 0;
  for (std::size_t q = 0; q < rounds; ++q)
  {
    const std::size_t begin = tasks * q / rounds;
    const std::size_t mine = mineOf(tasks * (q + 1) / rounds - begin);
    agreeAcrossRanks(options,
      [&] {
        parallelFor(mine, workers,
          [&](std::size_t task, int worker) { body(begin + rank + task * ranks, worker); },
          [&](std::size_t done) {
            return fraction(static_cast<double>(doneBefore + done) /
              static_cast<double>(std::max<std::size_t>(mineTotal, 1)));
          });
      },
      &secondsReducing);
    doneBefore += mine;
  }
}

struct alignas(64) WorkerCounters
{
  std::uint64_t shootingRays = 0;
  std::uint64_t shadowRays = 0;
  std::uint64_t shadowRaysBlocked = 0;
  std::uint64_t gatheringRays = 0;
  std::uint64_t missedRays = 0;
  std::uint64_t firstHits = 0;
  std::uint64_t firstHitsOnBack = 0; ///< one-sided mode: first hits absorbed by a back face
};

/// Scratch vectors one worker reuses for every path.
struct WorkerScratch
{
  std::vector<double> kernel;
  /// The shadow rays of one path, from the hit to each position still unknown: float
  /// offsets in the layout of Embree's packets.
  std::vector<float> dx, dy, dz;
  std::vector<std::uint32_t> targetFrames;
  std::vector<std::uint8_t> visible;
  std::vector<Rgb> gathered;
};

/**
 * One light the solver shoots from, seen through one interface: an area light (a moving or
 * static lamp, or a group of the scene's emissive patches of one emission) or a directional
 * light. It has `positions` poses; one pose is a static light, added to every frame.
 */
struct Source
{
  enum class Kind
  {
    Area,
    Directional,
  };
  Kind kind = Kind::Area;
  const MovingLight* area = nullptr;
  const DirectionalLight* directional = nullptr;
  std::size_t positions = 1;
  /// The power a whole path set carries before weights: Phi for an area light, E times the
  /// disc's area for a directional one.
  Rgb power;
  /// Per position, a factor on the power (0: that position is off and casts no path).
  std::vector<Rgb> factors;
  /// Directional lights: paths start on a disc of this radius, centred on the scene's
  /// bounding sphere and pushed out of it along the direction towards the light.
  Vec3 sphereCentre;
  double sphereRadius = 0;
  /// The scene's emissive patches rather than a lamp: they occlude, and they are in the
  /// scene's own geometry.
  bool sceneEmitter = false;
  /// Keys this source's shooting streams apart from the other sources' (0 for the first):
  /// lights of one rig are independent estimates, not the same random numbers replayed.
  std::uint64_t stream = 0;

  bool isStatic() const { return this->positions == 1; }
  bool isActive(std::size_t position) const { return this->factors[position].maxComponent() > 0; }

  /// A path's start at `position`: the point (lifted off the light), the direction, and for
  /// area lights the point and normal in the light's own frame (the weights need them).
  void emit(std::size_t position, RandomStream& random, double offset, Vec3& start,
    Vec3& direction, Vec3& ownPoint, Vec3& ownNormal) const
  {
    if (this->kind == Kind::Area)
    {
      const double u0 = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
      this->area->samplePoint(u0, u1, u2, ownPoint, ownNormal);
      const Vec3 normal = this->area->turn(position, ownNormal);
      direction = sampleCosineDirection(normal, random);
      start = this->area->place(position, ownPoint) + normal * offset;
      return;
    }
    const Vec3& s = this->directional->direction(position);
    Vec3 t, b;
    orthonormalBasis(s, t, b);
    // A uniform point of the disc by rejection, as sampleCosineDirection does.
    double u, v;
    do
    {
      u = 2.0 * random.uniform() - 1.0;
      v = 2.0 * random.uniform() - 1.0;
    } while (u * u + v * v >= 1.0);
    const double radius = this->sphereRadius;
    start = this->sphereCentre + s * (radius + 2 * offset) + (t * u + b * v) * radius;
    direction = -s;
    ownPoint = start;
    ownNormal = direction;
  }
};

/// The rounding quantum of a fixed-point channel whose largest value per path is `scale`:
/// one per channel, so that a channel 10^6 weaker than the others keeps its precision.
double quantumFor(double scale)
{
  return scale > 0 && std::isfinite(scale) ? scale * 0x1.0p-40 : 1.0;
}

/// The shooting of one Source into its own accumulators, added to the solution at the end.
class ShootingRun
{
public:
  ShootingRun(const Scene& scene, const Source& source, const SolverOptions& options,
    const RayTracer& tracer, int workers, bool copyPerWorker)
    : SceneRef(scene)
    , SourceRef(source)
    , Options(options)
    , Tracer(tracer)
    , Frames(source.positions)
    , Reuse(options.reuseShooting && source.positions > 1)
    , ElementShare(workers, copyPerWorker, scene.elementCount(), source.positions, 0x1.0p-50,
        Reuse ? FrameLayout::FramesInner : FrameLayout::FramesOuter)
    , PatchPower(workers, copyPerWorker, scene.patchCount(), source.positions,
        { quantumFor(source.power.r), quantumFor(source.power.g), quantumFor(source.power.b) },
        Reuse ? FrameLayout::FramesInner : FrameLayout::FramesOuter)
    , Counters(static_cast<std::size_t>(workers))
    , Scratch(static_cast<std::size_t>(workers))
  {
    for (WorkerScratch& s : this->Scratch)
    {
      s.kernel.resize(this->Frames);
      s.dx.resize(this->Frames);
      s.dy.resize(this->Frames);
      s.dz.resize(this->Frames);
      s.targetFrames.resize(this->Frames);
      s.visible.resize(this->Frames);
    }
    for (std::size_t k = 0; k < this->Frames; ++k)
    {
      if (source.isActive(k))
      {
        this->ActivePositions.push_back(k);
      }
    }
    // M_k paths start from active position k; they add up to N exactly. Positions that are
    // off cast nothing: their frames are zero, and every active frame j still has M_j > 0 in
    // its weights' denominator, so no light is lost.
    const std::uint64_t active = this->ActivePositions.size();
    const std::uint64_t N = options.pathsPerFrame;
    this->PathsFromPosition.assign(this->Frames, 0.0);
    for (std::uint64_t a = 0; a < active; ++a)
    {
      this->PathsFromPosition[this->ActivePositions[a]] =
        static_cast<double>(N / active + (a < N % active ? 1 : 0));
    }
    // The poses as a structure of arrays, for the vectorised weights: x_j = R_j x + o_j and
    // n_j = R_j n for an area light, s_j for a directional one.
    this->Pose.assign(12, std::vector<double>(this->Frames, 0.0));
    for (std::size_t j = 0; j < this->Frames; ++j)
    {
      if (source.kind == Source::Kind::Area)
      {
        const LightPose& pose = source.area->pose(j);
        const Rotation& r = pose.rotation;
        const Vec3 o = pose.position - r.apply(source.area->centroid());
        const double values[12] = { r.row0.x, r.row0.y, r.row0.z, r.row1.x, r.row1.y, r.row1.z,
          r.row2.x, r.row2.y, r.row2.z, o.x, o.y, o.z };
        for (int i = 0; i < 12; ++i)
        {
          this->Pose[i][j] = values[i];
        }
      }
      else
      {
        const Vec3& s = source.directional->direction(j);
        this->Pose[0][j] = s.x;
        this->Pose[1][j] = s.y;
        this->Pose[2][j] = s.z;
      }
    }
  }

  bool reuses() const { return this->Reuse; }
  const std::vector<std::size_t>& activePositions() const { return this->ActivePositions; }

  void shootReused(std::uint64_t path, int worker);
  void shootClassic(std::size_t position, std::uint64_t path, int worker);
  /// Adds this source's radiosity to `solution`: frame f gets position f, or the one
  /// position of a static source, times that position's power factor.
  void addTo(Solution& solution) const;

  const std::vector<WorkerCounters>& counters() const { return this->Counters; }

  /// Sums the scores over ranks (SolverOptions::sumAcrossRanks): integers, so every rank then
  /// holds exactly the serial sums, whatever rank and worker traced each path.
  void sumAcrossRanks()
  {
    this->Options.sumAcrossRanks(this->ElementShare.collapse(), this->ElementShare.copySize());
    this->Options.sumAcrossRanks(this->PatchPower.collapse(), this->PatchPower.copySize());
  }

  /// Which active position path `path` of a reuse solve starts from.
  std::size_t positionOfPath(std::uint64_t path) const
  {
    const std::uint64_t n = this->ActivePositions.size();
    const std::uint64_t base = this->Options.pathsPerFrame / n;
    const std::uint64_t extra = this->Options.pathsPerFrame % n;
    const std::uint64_t firstBlock = extra * (base + 1);
    const std::uint64_t index = path < firstBlock ? path / (base + 1) : extra + (path - firstBlock) / base;
    return this->ActivePositions[static_cast<std::size_t>(index)];
  }

private:
  bool emit(RandomStream& random, std::size_t position, int worker, Vec3& x, Vec3& lightNormal,
    RayHit& hit);
  void scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
    std::size_t firstFrame, std::size_t frameCount, int worker);
  // Always inlined, like the prefetch it calls: GCC would delete the call otherwise.
  [[gnu::always_inline]] inline void prefetchFirstHit(
    const RayHit& hit, std::size_t firstFrame, std::size_t frameCount, int worker);
  std::size_t areaKernel(const Vec3& x, const Vec3& n, const RayHit& hit, std::size_t origin,
    WorkerScratch& scratch) const;
  std::size_t directionalKernel(const RayHit& hit, std::size_t origin, WorkerScratch& scratch) const;

  const Scene& SceneRef;
  const Source& SourceRef;
  const SolverOptions& Options;
  const RayTracer& Tracer;
  std::size_t Frames;
  bool Reuse;
  // Direct light needs one scalar per element side and frame: the share of the source's
  // power whose first hit lands there. Its colour rho_e Phi is the same for every hit, and
  // a scalar is a third of the memory traffic of RGB in the hottest loop.
  FixedPointAccumulator<1> ElementShare;
  // The patch solution's reflected power (W), RGB, from the second hit of a walk on; the
  // first hits come from ElementShare.
  FixedPointAccumulator<3> PatchPower;
  std::vector<WorkerCounters> Counters;
  std::vector<WorkerScratch> Scratch;
  std::vector<std::size_t> ActivePositions;
  std::vector<double> PathsFromPosition;
  std::vector<std::vector<double>> Pose;
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
 * METHOD.md writes step 3 as P <- P / lambda; the power that leaves the first hit is the
 * reflected power, so we carry rho * P / lambda (the energy balance test checks this).
 */
void ShootingRun::scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
  std::size_t firstFrame, std::size_t frameCount, int worker)
{
  // The first hit scores only the element's share: the patch's first-hit power is
  // rho_p Phi times the shares of its four elements, added when shooting ends. That keeps
  // the RGB patch slots (3n values) out of the one write every path makes.
  const int firstSide = static_cast<int>(firstHit.side);
  const Rgb& firstRho = this->SceneRef.elementReflectance(firstHit.element);
  Rgb colour = firstRho * this->SourceRef.power;
  {
    std::int64_t* elementSlots = this->ElementShare.slots(worker, firstHit.element, firstSide);
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
  std::int64_t* pendingSlots = nullptr;
  Rgb pendingPower;
  auto scorePending = [&] {
    if (pendingSlots)
    {
      for (std::size_t f = 0; f < frameCount; ++f)
      {
        const double power[3] = { pendingPower.r * shares[f], pendingPower.g * shares[f],
          pendingPower.b * shares[f] };
        this->PatchPower.add(pendingSlots, firstFrame + f, power);
      }
      pendingSlots = nullptr;
    }
  };
  RayHit hit = firstHit;
  for (int bounce = 0; bounce < MaximumBounces; ++bounce)
  {
    const Vec3 normal = this->SceneRef.elementSideNormal(hit.element, hit.side);
    const Vec3 direction = sampleCosineDirection(normal, random);
    ++counters.shootingRays;
    RayHit next;
    const bool found = this->Tracer.intersect(this->Tracer.liftOff(hit.point, normal), direction, next);
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
    this->ElementShare.slots(worker, hit.element, static_cast<int>(hit.side)), firstFrame, frameCount);
}

/// Starts a walk from the source at `position` and traces its first ray. x and lightNormal
/// are the start in the light's own frame (area lights). False when the walk ends there: a
/// miss (the power leaves the scene) or, with one-sided surfaces, a back face.
bool ShootingRun::emit(RandomStream& random, std::size_t position, int worker, Vec3& x,
  Vec3& lightNormal, RayHit& hit)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  Vec3 start, direction;
  this->SourceRef.emit(position, random, this->Tracer.surfaceOffset(), start, direction, x, lightNormal);
  ++counters.shootingRays;
  if (!this->Tracer.intersect(start, direction, hit))
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

/**
 * The unoccluded kernel of an area light at every position, into scratch.kernel, and the
 * positions whose visibility is still unknown, into scratch.targetFrames, with the offsets
 * from the lifted hit to their lifted emission points in scratch.dx, dy and dz. G_j = (n_j.d)(-n_y.d) / |d|^4 with d = y - x_j: the pi of G
 * cancels in the weights. The loop is branch-free over the positions (structure of arrays)
 * so that it vectorises.
 */
std::size_t ShootingRun::areaKernel(const Vec3& x, const Vec3& n, const RayHit& hit,
  std::size_t origin, WorkerScratch& scratch) const
{
  const Vec3 ny = this->SceneRef.elementSideNormal(hit.element, hit.side);
  const Vec3& y = hit.point;
  double* kernel = scratch.kernel.data();
  const double* pose[12];
  for (int i = 0; i < 12; ++i)
  {
    pose[i] = this->Pose[static_cast<std::size_t>(i)].data();
  }
  const double* active = this->PathsFromPosition.data();
  const double offset = this->Tracer.surfaceOffset();
  std::size_t count = 0;
  if (!this->SourceRef.area->rotates())
  {
    // Translations only (the common case): x_j = x + o_j and n_j = n, a third of the work.
    const Vec3 toHit = y - x;
    for (std::size_t j = 0; j < this->Frames; ++j)
    {
      const double dx = toHit.x - pose[9][j], dy = toHit.y - pose[10][j], dz = toHit.z - pose[11][j];
      const double cosX = n.x * dx + n.y * dy + n.z * dz;
      const double cosY = -(ny.x * dx + ny.y * dy + ny.z * dz);
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double g = cosX * cosY / std::max(r2 * r2, std::numeric_limits<double>::min());
      // Positions that are off cast no path and light nothing: their weight is never needed.
      kernel[j] = cosX > 0 && cosY > 0 && active[j] > 0 ? g : 0.0;
    }
    // From y lifted along n_y to x_j lifted along n: o_j - (y - x) + (n - n_y) offset.
    const Vec3 base = (n - ny) * offset - toHit;
    for (std::size_t j = 0; j < this->Frames; ++j)
    {
      if (kernel[j] > 0 && j != origin)
      {
        scratch.dx[count] = static_cast<float>(base.x + pose[9][j]);
        scratch.dy[count] = static_cast<float>(base.y + pose[10][j]);
        scratch.dz[count] = static_cast<float>(base.z + pose[11][j]);
        scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
        ++count;
      }
    }
  }
  else
  {
    for (std::size_t j = 0; j < this->Frames; ++j)
    {
      const double xj = pose[0][j] * x.x + pose[1][j] * x.y + pose[2][j] * x.z + pose[9][j];
      const double yj = pose[3][j] * x.x + pose[4][j] * x.y + pose[5][j] * x.z + pose[10][j];
      const double zj = pose[6][j] * x.x + pose[7][j] * x.y + pose[8][j] * x.z + pose[11][j];
      const double nx = pose[0][j] * n.x + pose[1][j] * n.y + pose[2][j] * n.z;
      const double nyj = pose[3][j] * n.x + pose[4][j] * n.y + pose[5][j] * n.z;
      const double nz = pose[6][j] * n.x + pose[7][j] * n.y + pose[8][j] * n.z;
      const double dx = y.x - xj, dy = y.y - yj, dz = y.z - zj;
      const double cosX = nx * dx + nyj * dy + nz * dz;
      const double cosY = -(ny.x * dx + ny.y * dy + ny.z * dz);
      const double r2 = dx * dx + dy * dy + dz * dz;
      const double g = cosX * cosY / std::max(r2 * r2, std::numeric_limits<double>::min());
      kernel[j] = cosX > 0 && cosY > 0 && active[j] > 0 ? g : 0.0;
    }
    const Vec3 from = this->Tracer.liftOff(y, ny);
    for (std::size_t j = 0; j < this->Frames; ++j)
    {
      if (kernel[j] > 0 && j != origin)
      {
        const Vec3 normal = this->SourceRef.area->turn(j, n);
        const Vec3 d = this->SourceRef.area->place(j, x) + normal * offset - from;
        scratch.dx[count] = static_cast<float>(d.x);
        scratch.dy[count] = static_cast<float>(d.y);
        scratch.dz[count] = static_cast<float>(d.z);
        scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
        ++count;
      }
    }
  }
  if (count > 0)
  {
    this->Tracer.visibleFrom(this->Tracer.liftOff(y, ny), scratch.dx.data(), scratch.dy.data(),
      scratch.dz.data(), count, scratch.visible.data());
  }
  return count;
}

/// The same for a directional light: G_j = max(0, n_y.s_j), visibility towards s_j to
/// infinity (the disc is outside the scene's bounding sphere).
std::size_t ShootingRun::directionalKernel(
  const RayHit& hit, std::size_t origin, WorkerScratch& scratch) const
{
  const Vec3 ny = this->SceneRef.elementSideNormal(hit.element, hit.side);
  double* kernel = scratch.kernel.data();
  const double* sx = this->Pose[0].data();
  const double* sy = this->Pose[1].data();
  const double* sz = this->Pose[2].data();
  const double* active = this->PathsFromPosition.data();
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    const double c = ny.x * sx[j] + ny.y * sy[j] + ny.z * sz[j];
    kernel[j] = c > 0 && active[j] > 0 ? c : 0.0;
  }
  std::size_t count = 0;
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    if (kernel[j] > 0 && j != origin)
    {
      scratch.dx[count] = static_cast<float>(sx[j]);
      scratch.dy[count] = static_cast<float>(sy[j]);
      scratch.dz[count] = static_cast<float>(sz[j]);
      scratch.targetFrames[count] = static_cast<std::uint32_t>(j);
      ++count;
    }
  }
  if (count > 0)
  {
    this->Tracer.visibleAlong(this->Tracer.liftOff(hit.point, ny), scratch.dx.data(),
      scratch.dy.data(), scratch.dz.data(), count, scratch.visible.data());
  }
  return count;
}

void ShootingRun::shootReused(std::uint64_t path, int worker)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  WorkerScratch& scratch = this->Scratch[static_cast<std::size_t>(worker)];
  const std::size_t origin = this->positionOfPath(path);
  RandomStream random(this->Options.seed, StreamPurpose::Shooting, path, this->SourceRef.stream);

  Vec3 x, lightNormal;
  RayHit hit;
  if (!this->emit(random, origin, worker, x, lightNormal, hit))
  {
    return;
  }
  this->prefetchFirstHit(hit, 0, this->Frames, worker);

  // Mixture weights w_j = G_j(y) / sum_k M_k G_k(y), with real visibility: one shadow ray
  // per other position whose unoccluded kernel is not zero (the origin's is known).
  const std::size_t shadowCount = this->SourceRef.kind == Source::Kind::Area
    ? this->areaKernel(x, lightNormal, hit, origin, scratch)
    : this->directionalKernel(hit, origin, scratch);
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
  double mixture = 0;
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    mixture += this->PathsFromPosition[j] * kernel[j];
  }
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

void ShootingRun::shootClassic(std::size_t position, std::uint64_t path, int worker)
{
  RandomStream random(
    this->Options.seed, StreamPurpose::Shooting, path, this->SourceRef.stream + position + 1);
  Vec3 x, lightNormal;
  RayHit hit;
  if (!this->emit(random, position, worker, x, lightNormal, hit))
  {
    return;
  }
  const double share = 1.0 / static_cast<double>(this->Options.pathsPerFrame);
  this->scoreAndWalk(random, hit, &share, position, 1, worker);
}

void ShootingRun::addTo(Solution& solution) const
{
  const std::size_t elements = this->SceneRef.elementCount();
  const std::size_t patches = this->SceneRef.patchCount();
  const std::size_t frames = solution.frameCount();
  std::vector<PackedRgb>& direct = solution.directData();
  std::vector<PackedRgb>& patch = solution.patchData();
  const std::vector<Rgb>& factors = this->SourceRef.factors;
  auto positionOf = [&](std::size_t f) { return this->SourceRef.isStatic() ? 0 : f; };
  for (std::size_t e = 0; e < elements; ++e)
  {
    const Rgb exitance =
      this->SceneRef.elementReflectance(e) * this->SourceRef.power / this->SceneRef.elementArea(e);
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < frames; ++f)
      {
        double share = 0;
        this->ElementShare.total(e, s, positionOf(f), &share);
        if (share != 0)
        {
          direct[solution.elementIndex(f, e, static_cast<Side>(s))] +=
            exitance * factors[positionOf(f)] * share;
        }
      }
    }
  }
  for (std::size_t p = 0; p < patches; ++p)
  {
    const double inverseArea = 1.0 / this->SceneRef.patchArea(p);
    const Rgb firstHitColour = this->SceneRef.patchReflectance(p) * this->SourceRef.power;
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < frames; ++f)
      {
        const std::size_t k = positionOf(f);
        double power[3];
        this->PatchPower.total(p, s, k, power);
        double share = 0;
        for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch; ++e)
        {
          double elementShare = 0;
          this->ElementShare.total(e, s, k, &elementShare);
          share += elementShare;
        }
        patch[solution.patchIndex(f, p, static_cast<Side>(s))] +=
          (Rgb(power[0], power[1], power[2]) + firstHitColour * share) * factors[k] * inverseArea;
      }
    }
  }
}

/**
 * Which patch sides light can reach, from geometry alone (the same for any N, seed and
 * thread count). Seeds: the sides that probe walks from every light's positions hit first.
 * Then a side is reachable when one of ReachabilityProbesPerSide cosine rays from it reaches
 * a reachable side, or one from a reachable side reaches it (light paths are reversible).
 * The inside of a closed block is never reached; a side that random shooting happened to
 * miss still is.
 */
std::vector<std::uint8_t> reachableSides(const Scene& scene, const RayTracer& tracer,
  const std::vector<Source>& sources, const SolverOptions& options, int workers,
  const std::function<bool(double)>& keepGoing, std::uint64_t& rays)
{
  const std::size_t patches = scene.patchCount();
  const std::size_t sides = 2 * patches;
  const bool twoSided = options.twoSided;
  constexpr std::uint32_t None = std::numeric_limits<std::uint32_t>::max();
  auto sideOf = [&](std::uint32_t element, Side side) -> std::uint32_t {
    if (!twoSided && side == Side::Back)
    {
      return None;
    }
    return static_cast<std::uint32_t>(Scene::patchOfElement(element) * 2 + static_cast<std::size_t>(side));
  };

  // Seeds, one slot per probe so that the result does not depend on scheduling.
  std::vector<std::uint32_t> seeds;
  for (std::size_t l = 0; l < sources.size(); ++l)
  {
    const Source& source = sources[l];
    std::vector<std::size_t> active;
    for (std::size_t k = 0; k < source.positions; ++k)
    {
      if (source.isActive(k))
      {
        active.push_back(k);
      }
    }
    if (active.empty())
    {
      continue;
    }
    const std::uint64_t perPosition =
      std::max<std::uint64_t>(64, ReachabilityProbesPerLight / active.size());
    const std::uint64_t total = perPosition * active.size();
    const std::size_t first = seeds.size();
    seeds.resize(first + total, None);
    const std::uint64_t perTask = 1024;
    parallelFor((total + perTask - 1) / perTask, workers,
      [&](std::size_t task, int) {
        for (std::uint64_t i = task * perTask; i < std::min(total, (task + 1) * perTask); ++i)
        {
          RandomStream random(ReachabilitySeed + l, StreamPurpose::Reachability, i, 0);
          Vec3 start, direction, x, n;
          source.emit(active[i / perPosition], random, tracer.surfaceOffset(), start, direction, x, n);
          std::uint32_t element = 0;
          Side side = Side::Front;
          if (tracer.nearestSide(start, direction, element, side))
          {
            seeds[first + i] = sideOf(element, side);
          }
        }
      },
      [&](std::size_t) { return keepGoing(0.0); });
    rays += total;
  }

  // Probes from every side.
  constexpr std::size_t K = ReachabilityProbesPerSide;
  std::vector<std::uint32_t> probe(sides * K, None);
  const auto& points = scene.points();
  const std::size_t tasks = (patches + ReachabilityPatchesPerTask - 1) / ReachabilityPatchesPerTask;
  parallelFor(tasks, workers,
    [&](std::size_t task, int) {
      for (std::size_t p = task * ReachabilityPatchesPerTask;
           p < std::min(patches, (task + 1) * ReachabilityPatchesPerTask); ++p)
      {
        const Triangle& t = scene.patchTriangles()[p];
        for (int s = 0; s < (twoSided ? 2 : 1); ++s)
        {
          const Vec3 normal = s == 0 ? scene.patchNormal(p) : -scene.patchNormal(p);
          const std::size_t side = 2 * p + static_cast<std::size_t>(s);
          RandomStream random(ReachabilitySeed, StreamPurpose::Reachability, side, 1);
          for (std::size_t r = 0; r < K; ++r)
          {
            const double u1 = random.uniform(), u2 = random.uniform();
            const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
            const Vec3 direction = sampleCosineDirection(normal, random);
            std::uint32_t element = 0;
            Side hitSide = Side::Front;
            if (tracer.nearestSide(tracer.liftOff(origin, normal), direction, element, hitSide))
            {
              probe[side * K + r] = sideOf(element, hitSide);
            }
          }
        }
      }
    },
    [&](std::size_t done) { return keepGoing(static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(tasks, 1))); });
  rays += patches * (twoSided ? 2 : 1) * K;

  // Reverse edges (compressed rows), then a breadth-first search from the seeds over both.
  std::vector<std::uint32_t> reverseStart(sides + 1, 0);
  for (std::uint32_t to : probe)
  {
    if (to != None)
    {
      ++reverseStart[to + 1];
    }
  }
  for (std::size_t i = 0; i < sides; ++i)
  {
    reverseStart[i + 1] += reverseStart[i];
  }
  std::vector<std::uint32_t> reverse(reverseStart[sides]);
  {
    std::vector<std::uint32_t> fill(reverseStart.begin(), reverseStart.end() - 1);
    for (std::size_t from = 0; from < sides; ++from)
    {
      for (std::size_t r = 0; r < K; ++r)
      {
        const std::uint32_t to = probe[from * K + r];
        if (to != None)
        {
          reverse[fill[to]++] = static_cast<std::uint32_t>(from);
        }
      }
    }
  }
  std::vector<std::uint8_t> reached(sides, 0);
  std::vector<std::uint32_t> queue;
  auto visit = [&](std::uint32_t side) {
    if (side != None && !reached[side])
    {
      reached[side] = 1;
      queue.push_back(side);
    }
  };
  for (std::uint32_t s : seeds)
  {
    visit(s);
  }
  for (std::size_t head = 0; head < queue.size(); ++head)
  {
    const std::uint32_t side = queue[head];
    for (std::size_t r = 0; r < K; ++r)
    {
      visit(probe[side * K + r]);
    }
    for (std::uint32_t i = reverseStart[side]; i < reverseStart[side + 1]; ++i)
    {
      visit(reverse[i]);
    }
  }
  return reached;
}

/**
 * The element sides that gather: those of reachable patch sides whose reflectance is not
 * zero (a black element reflects nothing it gathers). Returns them as element * 2 + side,
 * in element order, and sets `rays` to the rays each casts so that together they cast about
 * `total` (at least one each: equal counts keep every side's estimate equally accurate).
 */
std::vector<std::uint32_t> gatheringSides(const Scene& scene,
  const std::vector<std::uint8_t>& reachable, std::uint64_t& rays, std::uint64_t total)
{
  std::vector<std::uint32_t> sides;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    if (!(scene.patchReflectance(p).maxComponent() > 0))
    {
      continue;
    }
    for (int s = 0; s < 2; ++s)
    {
      if (reachable[2 * p + static_cast<std::size_t>(s)])
      {
        for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch; ++e)
        {
          sides.push_back(static_cast<std::uint32_t>(e * 2 + static_cast<std::size_t>(s)));
        }
      }
    }
  }
  std::sort(sides.begin(), sides.end());
  rays = sides.empty()
    ? 0
    : static_cast<std::uint64_t>(std::max<long long>(
        1, std::llround(static_cast<double>(total) / static_cast<double>(sides.size()))));
  return sides;
}

/**
 * Final gathering for one element side: `rays` cosine-distributed rays from uniform points
 * on it; each ray that reaches a patch side adds that side's shooting radiosity. With reuse
 * one set of rays serves every frame; otherwise each frame casts its own.
 */
void gather(const Scene& scene, const RayTracer& tracer, const SolverOptions& options,
  std::uint32_t elementSide, std::uint64_t rays, Solution& solution, std::vector<Rgb>& sum,
  WorkerCounters& counters)
{
  const std::size_t frames = solution.frameCount();
  const bool reuse = options.reuseGathering;
  const std::size_t element = elementSide / 2;
  const Side side = static_cast<Side>(elementSide % 2);
  const Triangle& t = scene.elementTriangles()[element];
  const auto& points = scene.points();
  const Vec3 normal = scene.elementSideNormal(element, side);
  sum.assign(frames, Rgb());

  // A hit's row of patch radiosity is added after the next ray is traced: the row was
  // prefetched when the hit was found, so the trace hides its cache miss.
  const std::size_t passes = reuse ? 1 : frames;
  const std::size_t rowLength = reuse ? frames : 1;
  for (std::size_t pass = 0; pass < passes; ++pass)
  {
    Rgb* into = reuse ? sum.data() : &sum[pass];
    const PackedRgb* pending = nullptr;
    auto addPending = [&] {
      if (pending)
      {
        for (std::size_t f = 0; f < rowLength; ++f)
        {
          into[f] += pending[f];
        }
        pending = nullptr;
      }
    };
    RandomStream random(options.seed, StreamPurpose::Gathering, elementSide, reuse ? 0 : pass + 1);
    for (std::uint64_t r = 0; r < rays; ++r)
    {
      const double u1 = random.uniform(), u2 = random.uniform();
      const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
      const Vec3 direction = sampleCosineDirection(normal, random);
      ++counters.gatheringRays;
      std::uint32_t hitElement = 0;
      Side hitSide = Side::Front;
      const bool found = tracer.nearestSide(tracer.liftOff(origin, normal), direction, hitElement, hitSide);
      addPending();
      if (!found)
      {
        ++counters.missedRays;
        continue;
      }
      if (!options.twoSided && hitSide == Side::Back)
      {
        continue;
      }
      pending = solution.patchData().data() +
        solution.patchIndex(reuse ? 0 : pass, Scene::patchOfElement(hitElement), hitSide);
      const char* row = reinterpret_cast<const char*>(pending);
      for (std::size_t byte = 0; byte < rowLength * sizeof(PackedRgb); byte += 64)
      {
        __builtin_prefetch(row + byte);
      }
    }
    addPending();
  }
  const Rgb scale = scene.elementReflectance(element) / static_cast<double>(rays);
  for (std::size_t f = 0; f < frames; ++f)
  {
    solution.indirectData()[solution.elementIndex(f, element, side)] = PackedRgb(scale * sum[f]);
  }
}

/// Without gathering (k = 0) an element's indirect light is its patch's shooting solution
/// minus the patch's direct part (the area-weighted direct of its four elements).
void indirectFromPatches(const Scene& scene, Solution& solution)
{
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < solution.frameCount(); ++f)
      {
        Rgb directPower;
        for (std::size_t e = p * 4; e < p * 4 + 4; ++e)
        {
          directPower += solution.direct(f, e, static_cast<Side>(s)) * scene.elementArea(e);
        }
        const Rgb patchDirect = directPower / scene.patchArea(p);
        const Rgb b = solution.patchRadiosity(f, p, static_cast<Side>(s));
        const Rgb rest(std::max(0.0, b.r - patchDirect.r), std::max(0.0, b.g - patchDirect.g),
          std::max(0.0, b.b - patchDirect.b));
        for (std::size_t e = p * 4; e < p * 4 + 4; ++e)
        {
          solution.indirectData()[solution.elementIndex(f, e, static_cast<Side>(s))] = PackedRgb(rest);
        }
      }
    }
  }
}

void chooseLitSides(const Scene& scene, Solution& solution)
{
  std::vector<Side>& lit = solution.litSideData();
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    double front = 0, back = 0;
    for (std::size_t f = 0; f < solution.frameCount(); ++f)
    {
      front += solution.total(f, e, Side::Front).sum();
      back += solution.total(f, e, Side::Back).sum();
    }
    lit[e] = back > front ? Side::Back : Side::Front;
  }
}
}

Solution::Solution(std::size_t frames, std::size_t elements, std::size_t patches)
  : Frames(frames)
  , Elements(elements)
  , Patches(patches)
  , Direct(frames * elements * 2)
  , Patch(frames * patches * 2)
  , LitSide(elements, Side::Front)
{
}

double predictedSpeedup(
  std::size_t frames, double gatheringRatio, double lambda, double meanPathLength)
{
  const double n = static_cast<double>(frames);
  const double walk = lambda * (meanPathLength - 1.0);
  return (n * (1.0 + walk) + gatheringRatio * n) / (n + walk + gatheringRatio);
}

void validateOptions(const SolverOptions& options)
{
  if (options.pathsPerFrame == 0)
  {
    throw Error("the number of paths per frame is 0: give at least 1 (600000 is typical)");
  }
  if (options.pathsPerFrame > MaximumPathsPerFrame)
  {
    throw Error("the number of paths per frame, " + std::to_string(options.pathsPerFrame) +
      ", is over the maximum of " + std::to_string(MaximumPathsPerFrame) +
      ": such a solve would not finish");
  }
  if (!(options.firstBounceSurvival >= MinimumFirstBounceSurvival &&
        options.firstBounceSurvival <= 1.0))
  {
    throw Error("the first-bounce survival probability lambda is " +
      std::to_string(options.firstBounceSurvival) +
      ": it must be in [0.001, 1] (0.25 is typical; a surviving walk carries 1/lambda of its "
      "power, and below 0.001 the fixed-point sums could overflow)");
  }
  if (!(options.gatheringRatio >= 0.0) || !std::isfinite(options.gatheringRatio))
  {
    throw Error("the gathering ratio k is " + std::to_string(options.gatheringRatio) +
      ": it must be 0 (no final gathering) or positive (1 is typical)");
  }
  if (options.gatheringRatio * static_cast<double>(options.pathsPerFrame) >
    static_cast<double>(MaximumPathsPerFrame))
  {
    throw Error("the gathering ratio k times the paths per frame is over the maximum of " +
      std::to_string(MaximumPathsPerFrame) + " rays per frame");
  }
  if (options.threads < 0 || options.threads > 1024)
  {
    throw Error("the thread count is " + std::to_string(options.threads) +
      ": give 0 (every core) or a count from 1 to 1024");
  }
  if (options.ranks < 1 || options.rank < 0 || options.rank >= options.ranks)
  {
    throw Error("rank " + std::to_string(options.rank) + " of " + std::to_string(options.ranks) +
      " ranks: give 1 rank or more, and a rank from 0 to ranks - 1");
  }
  if (options.ranks > 1 && (!options.sumAcrossRanks || !options.sumDoublesAcrossRanks))
  {
    throw Error("a solve over " + std::to_string(options.ranks) +
      " ranks needs the sums over ranks (SolverOptions::sumAcrossRanks and "
      "sumDoublesAcrossRanks)");
  }
}

void agreeAcrossRanks(
  const SolverOptions& options, const std::function<void()>& phase, double* secondsAgreeing)
{
  if (options.ranks <= 1)
  {
    phase();
    return;
  }
  if (!options.sumAcrossRanks)
  {
    throw Error("a solve over several ranks needs SolverOptions::sumAcrossRanks");
  }
  std::exception_ptr failure;
  std::int64_t status[2] = { 0, 0 }; // ranks cancelled, ranks failed
  try
  {
    phase();
  }
  catch (const Cancelled&)
  {
    failure = std::current_exception();
    status[0] = 1;
  }
  catch (...)
  {
    failure = std::current_exception();
    status[1] = 1;
  }
  const auto start = Clock::now();
  options.sumAcrossRanks(status, 2);
  if (secondsAgreeing)
  {
    *secondsAgreeing += secondsSince(start);
  }
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (status[1] > 0)
  {
    throw FailedOnAnotherRank("the solve failed on " + std::to_string(status[1]) + " other rank" +
      (status[1] > 1 ? "s" : "") + " of " + std::to_string(options.ranks));
  }
  if (status[0] > 0)
  {
    throw Cancelled();
  }
}

MemoryPlan planSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options)
{
  const std::uint64_t workers = static_cast<std::uint64_t>(resolveThreadCount(options.threads));
  const auto times = [](std::initializer_list<std::uint64_t> factors) {
    std::uint64_t product = 1;
    for (std::uint64_t f : factors)
    {
      product = saturatingProduct(product, f);
    }
    return product;
  };
  MemoryPlan plan;
  const std::uint64_t direct = times({ frames, elements, 2, sizeof(PackedRgb) });
  const std::uint64_t patch = times({ frames, patches, 2, sizeof(PackedRgb) });
  const std::uint64_t indirect = direct;
  plan.results = saturatingSum(saturatingSum(direct, patch), indirect);
  // One copy of the accumulators (FixedPointAccumulator::bytes): a scalar share per element
  // side and RGB power per patch side, for every frame.
  const std::uint64_t copy = saturatingSum(times({ elements, 2, frames, sizeof(std::int64_t) }),
    times({ patches, 2, frames, 3, sizeof(std::int64_t) }));
  // Per worker: the weights, targets, frames and visibility of one path, and a gathering row.
  const std::uint64_t scratch = times({ workers, frames,
    sizeof(double) + 3 * sizeof(float) + sizeof(std::uint32_t) + sizeof(std::uint8_t) + sizeof(Rgb) });
  // Embree's BVH and buffers (generously), the emission and lit side of every element.
  const std::uint64_t tracing = saturatingSum(times({ elements, 256 }), times({ points, 16 }));
  const std::uint64_t perElement = times({ elements, sizeof(Rgb) + sizeof(Side) });
  // Reachability: the probes' hits and their reverse edges (gone before gathering rays).
  const std::uint64_t reachability =
    times({ patches, 2, 2 * ReachabilityProbesPerSide + 2, sizeof(std::uint32_t) });
  plan.other = saturatingSum(saturatingSum(scratch, tracing), saturatingSum(perElement, reachability));
  const std::uint64_t base = saturatingSum(saturatingSum(scratch, tracing), perElement);
  const std::uint64_t gathering =
    saturatingSum(saturatingSum(direct, patch), saturatingSum(indirect, reachability));
  const auto peakWith = [&](std::uint64_t copies) {
    return saturatingSum(base,
      std::max(saturatingSum(saturatingSum(direct, patch), times({ copies, copy })), gathering));
  };
  plan.accumulatorCopyPerWorker = workers == 1 || peakWith(workers) <= memoryLimitBytes(options) / 2;
  const std::uint64_t copies = plan.accumulatorCopyPerWorker ? workers : 1;
  plan.accumulators = times({ copies, copy });
  plan.peak = peakWith(copies);
  return plan;
}

std::uint64_t estimateSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options)
{
  return planSolveMemory(patches, elements, points, frames, options).peak;
}

std::uint64_t estimateSolveMemory(
  const Scene& scene, std::size_t frames, const SolverOptions& options)
{
  return estimateSolveMemory(
    scene.patchCount(), scene.elementCount(), scene.points().size(), frames, options);
}

std::uint64_t memoryLimitBytes(const SolverOptions& options)
{
  return options.memoryLimitBytes > 0 ? options.memoryLimitBytes : defaultMemoryLimitBytes();
}

void checkSolveMemory(std::uint64_t estimate, std::size_t frames, std::size_t patches,
  std::size_t elements, const SolverOptions& options, bool approximate)
{
  const std::uint64_t limit = memoryLimitBytes(options);
  if (estimate <= limit)
  {
    return;
  }
  std::ostringstream s;
  const char* about = approximate ? "about " : "";
  s << "the solve needs an estimated " << gibibytes(estimate) << " (" << frames << " frames x ("
    << about << patches << " patches + " << about << elements
    << " elements) x 2 sides x RGB, plus per-thread buffers), over the memory limit of "
    << gibibytes(limit)
    << ": use fewer frames or a larger patch size, or raise the limit";
  throw Error(s.str());
}

std::size_t frameCount(const LightRig& rig, bool sceneEmits)
{
  std::size_t frames = 0;
  std::string first;
  auto take = [&](std::size_t n, const std::string& what) {
    if (n <= 1)
    {
      return;
    }
    if (frames == 0)
    {
      frames = n;
      first = what;
    }
    else if (n != frames)
    {
      throw Error(what + " has " + std::to_string(n) + " positions but " + first + " has " +
        std::to_string(frames) + ": every moving light needs one position per frame");
    }
  };
  for (std::size_t i = 0; i < rig.areaLights.size(); ++i)
  {
    take(rig.areaLights[i].frameCount(), "light " + std::to_string(i));
  }
  for (std::size_t i = 0; i < rig.directionalLights.size(); ++i)
  {
    take(rig.directionalLights[i].frameCount(), "directional light " + std::to_string(i));
  }
  if (rig.areaLights.empty() && rig.directionalLights.empty() && !sceneEmits)
  {
    throw Error("nothing emits light: give a light, a directional light or scene surfaces with "
                "emission");
  }
  return std::max<std::size_t>(frames, 1);
}

namespace
{
/// The scene's emissive patches as static area lights, one per distinct emission (an area
/// light has one colour). They are part of the geometry too, so they occlude.
std::vector<MovingLight> sceneEmitters(const Scene& scene)
{
  std::vector<MovingLight> lights;
  if (!scene.hasEmission())
  {
    return lights;
  }
  std::vector<Rgb> emissions;
  std::vector<std::vector<std::vector<Vec3>>> polygons;
  std::vector<double> areas;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    const Rgb e = scene.patchEmission(p);
    if (!(e.maxComponent() > 0))
    {
      continue;
    }
    std::size_t group = std::find(emissions.begin(), emissions.end(), e) - emissions.begin();
    if (group == emissions.size())
    {
      emissions.push_back(e);
      polygons.emplace_back();
      areas.push_back(0);
    }
    const Triangle& t = scene.patchTriangles()[p];
    const auto& points = scene.points();
    polygons[group].push_back({ points[t[0]], points[t[1]], points[t[2]] });
    areas[group] += scene.patchArea(p);
  }
  for (std::size_t g = 0; g < emissions.size(); ++g)
  {
    // One pose, moved by nothing: the emitter stays where the scene has it.
    lights.emplace_back(polygons[g], emissions[g] * areas[g], std::vector<Vec3>{ Vec3() });
  }
  return lights;
}

std::vector<Source> sourcesOf(const Scene& scene, const LightRig& rig,
  const std::vector<MovingLight>& emitters)
{
  std::vector<Source> sources;
  auto addArea = [&](const MovingLight& light, bool sceneEmitter) {
    Source s;
    s.kind = Source::Kind::Area;
    s.area = &light;
    s.positions = light.frameCount();
    s.power = light.power();
    s.sceneEmitter = sceneEmitter;
    s.stream = static_cast<std::uint64_t>(sources.size()) << 32;
    for (const LightPose& pose : light.poses())
    {
      s.factors.push_back(pose.power);
    }
    sources.push_back(s);
  };
  for (const MovingLight& light : rig.areaLights)
  {
    addArea(light, false);
  }
  for (const MovingLight& light : emitters)
  {
    addArea(light, true);
  }
  const Vec3 centre = (scene.boundsMin() + scene.boundsMax()) * 0.5;
  const double radius = std::max(0.5 * scene.diagonal(), 1e-9 * std::max(1.0, length(centre)));
  for (const DirectionalLight& light : rig.directionalLights)
  {
    Source s;
    s.kind = Source::Kind::Directional;
    s.directional = &light;
    s.positions = light.frameCount();
    s.sphereCentre = centre;
    s.stream = static_cast<std::uint64_t>(sources.size()) << 32;
    s.sphereRadius = radius;
    s.power = light.irradiance() * (M_PI * radius * radius);
    for (std::size_t k = 0; k < light.frameCount(); ++k)
    {
      s.factors.push_back(light.powerFactor(k));
    }
    sources.push_back(s);
  }
  return sources;
}
}

Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress)
{
  LightRig rig;
  rig.areaLights.push_back(light);
  return solve(scene, rig, options, progress);
}

Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress)
{
  const auto start = Clock::now();
  // Setup, up to the allocations, is one phase the ranks agree on: a rank over its memory
  // limit (checked per rank) or cancelled stops every rank here.
  std::size_t frames = 0;
  int workers = 1;
  std::uint64_t memory = 0;
  MemoryPlan plan;
  std::vector<MovingLight> emitters;
  std::vector<Source> sources;
  std::vector<double> shootingCost;
  double totalCost = 0, reachabilityCost = 0, gatheringCost = 0;
  std::optional<RayTracer> tracerStorage;
  Solution solution;
  double secondsReducing = 0;
  agreeAcrossRanks(options, [&] {
  validateOptions(options);
  frames = frameCount(rig, scene.hasEmission());
  workers = resolveThreadCount(options.threads);
  plan = planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), frames, options);
  memory = plan.peak;
  checkSolveMemory(memory, frames, scene.patchCount(), scene.elementCount(), options);

  emitters = sceneEmitters(scene);
  sources = sourcesOf(scene, rig, emitters);
  for (std::size_t i = 0; i < sources.size(); ++i)
  {
    const Source& source = sources[i];
    std::size_t active = 0;
    for (std::size_t k = 0; k < source.positions; ++k)
    {
      active += source.isActive(k) ? 1 : 0;
    }
    if (options.reuseShooting && source.positions > 1 && options.pathsPerFrame < active)
    {
      // With M_k = 0 for some position k, the mixture has holes where only k lights: light
      // would be lost, and the weights would be unbounded.
      throw Error("reusing shooting paths needs at least one path per light position: " +
        std::to_string(options.pathsPerFrame) + " paths per frame is fewer than the " +
        std::to_string(active) + " light positions that emit; give at least " +
        std::to_string(active) + " paths per frame, or turn shooting reuse off");
    }
  }

  // Progress: phases weighted by their expected ray counts.
  const double N = static_cast<double>(options.pathsPerFrame);
  const double lambda = options.firstBounceSurvival;
  for (const Source& source : sources)
  {
    const double n = static_cast<double>(source.positions);
    const bool reuse = options.reuseShooting && source.positions > 1;
    shootingCost.push_back(reuse ? N * (1 + 1.5 * lambda + 0.2 * (n - 1)) : n * N * (1 + 1.5 * lambda));
    totalCost += shootingCost.back();
  }
  reachabilityCost = static_cast<double>(scene.patchCount() * 2 * ReachabilityProbesPerSide);
  gatheringCost =
    options.gatheringRatio * N * (options.reuseGathering ? 1.0 : static_cast<double>(frames));
  totalCost += reachabilityCost + gatheringCost;
  if (progress && !progress(0.0))
  {
    throw Cancelled();
  }

  tracerStorage.emplace(scene);
  solution = Solution(frames, scene.elementCount(), scene.patchCount());
  if (scene.hasEmission())
  {
    solution.emissionData().resize(scene.elementCount());
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      solution.emissionData()[e] = scene.elementEmission(e);
    }
  }
  }, &secondsReducing);
  const RayTracer& tracer = *tracerStorage;
  const double N = static_cast<double>(options.pathsPerFrame);
  const double lambda = options.firstBounceSurvival;
  double progressBase = 0;
  auto phaseTick = [&](double share) {
    const double base = progressBase;
    return [&progress, base, share](double fraction) {
      return !progress || progress(base + share * fraction);
    };
  };
  SolverStatistics& stats = solution.statistics;
  stats.secondsSetup = secondsSince(start);

  // Shooting, one source at a time: each has its own accumulators, added to the solution.
  const auto shootingStart = Clock::now();
  std::uint64_t firstHits = 0, backAbsorbed = 0;
  for (std::size_t i = 0; i < sources.size(); ++i)
  {
    const Source& source = sources[i];
    ShootingRun run(scene, source, options, tracer, workers, plan.accumulatorCopyPerWorker);
    const double share = shootingCost[i] / totalCost;
    const std::uint64_t paths = options.pathsPerFrame;
    std::uint64_t cast = 0;
    if (run.activePositions().empty())
    {
      // Off in every frame: nothing to add.
    }
    else if (run.reuses())
    {
      const std::uint64_t tasks = (paths + ReusedPathsPerTask - 1) / ReusedPathsPerTask;
      runOnRanks(tasks, workers, options,
        [&](std::size_t task, int worker) {
          const std::uint64_t end = std::min<std::uint64_t>(paths, (task + 1) * ReusedPathsPerTask);
          for (std::uint64_t p = task * ReusedPathsPerTask; p < end; ++p)
          {
            run.shootReused(p, worker);
          }
        },
        phaseTick(share), secondsReducing);
      cast = paths;
    }
    else
    {
      const std::vector<std::size_t>& positions = run.activePositions();
      const std::uint64_t tasksPerFrame = (paths + ClassicPathsPerTask - 1) / ClassicPathsPerTask;
      const std::uint64_t tasks = tasksPerFrame * positions.size();
      runOnRanks(tasks, workers, options,
        [&](std::size_t task, int worker) {
          const std::size_t position = positions[task / tasksPerFrame];
          const std::uint64_t first = (task % tasksPerFrame) * ClassicPathsPerTask;
          const std::uint64_t end = std::min<std::uint64_t>(paths, first + ClassicPathsPerTask);
          for (std::uint64_t p = first; p < end; ++p)
          {
            run.shootClassic(position, p, worker);
          }
        },
        phaseTick(share), secondsReducing);
      cast = paths * positions.size();
    }
    progressBase += share;
    if (options.ranks > 1 && !run.activePositions().empty())
    {
      const auto sumStart = Clock::now();
      run.sumAcrossRanks();
      secondsReducing += secondsSince(sumStart);
    }
    run.addTo(solution);
    stats.pathsCast += cast;
    stats.staticPathsCast += source.isStatic() ? cast : 0;
    for (const WorkerCounters& c : run.counters())
    {
      stats.shootingRays += c.shootingRays;
      stats.shadowRays += c.shadowRays;
      stats.shadowRaysBlocked += c.shadowRaysBlocked;
      stats.gatheringRays += c.gatheringRays;
      stats.missedRays += c.missedRays;
      firstHits += c.firstHits;
      backAbsorbed += c.firstHitsOnBack;
    }
  }
  stats.sources = sources.size();
  stats.secondsShooting = secondsSince(shootingStart);

  // Final gathering, once, on the sum of every source's patch solution. The accumulators
  // are gone: the indirect light takes their memory.
  const auto gatheringStart = Clock::now();
  solution.allocateIndirect();
  if (options.gatheringRatio > 0)
  {
    const double share = reachabilityCost / totalCost;
    const double base = progressBase;
    // Deterministic and cheap: every rank probes every side.
    std::vector<std::uint8_t> reachable;
    agreeAcrossRanks(options, [&] {
      reachable = reachableSides(scene, tracer, sources, options, workers,
        [&](double fraction) { return !progress || progress(base + share * fraction); },
        stats.reachabilityRays);
    }, &secondsReducing);
    progressBase += share;
    stats.reachableSides = static_cast<std::uint64_t>(std::count(reachable.begin(), reachable.end(), 1));
    std::uint64_t raysPerSide = 0;
    const auto total = static_cast<std::uint64_t>(std::llround(options.gatheringRatio * N));
    const std::vector<std::uint32_t> sides = gatheringSides(scene, reachable, raysPerSide, total);
    stats.gatheringSides = sides.size();
    std::vector<WorkerCounters> counters(static_cast<std::size_t>(workers));
    std::vector<std::vector<Rgb>> sums(static_cast<std::size_t>(workers));
    const std::size_t tasks = (sides.size() + GatheringSidesPerTask - 1) / GatheringSidesPerTask;
    runOnRanks(tasks, workers, options,
      [&](std::size_t task, int worker) {
        const std::size_t end = std::min(sides.size(), (task + 1) * GatheringSidesPerTask);
        for (std::size_t i = task * GatheringSidesPerTask; i < end; ++i)
        {
          gather(scene, tracer, options, sides[i], raysPerSide, solution,
            sums[static_cast<std::size_t>(worker)], counters[static_cast<std::size_t>(worker)]);
        }
      },
      phaseTick(1.0 - progressBase), secondsReducing);
    if (options.ranks > 1)
    {
      // Each element side gathered on one rank and is exactly zero on the others, so the sum
      // over ranks is that rank's value, bit for bit.
      // Summed as doubles (exact for floats), a block at a time so that no copy of the whole
      // array is needed.
      static_assert(sizeof(PackedRgb) == 3 * sizeof(float), "PackedRgb is three floats");
      const auto sumStart = Clock::now();
      std::vector<PackedRgb>& indirect = solution.indirectData();
      float* values = reinterpret_cast<float*>(indirect.data());
      const std::size_t count = 3 * indirect.size();
      constexpr std::size_t block = std::size_t(1) << 20;
      std::vector<double> buffer(std::min(count, block));
      for (std::size_t first = 0; first < count; first += block)
      {
        const std::size_t n = std::min(block, count - first);
        std::copy(values + first, values + first + n, buffer.begin());
        options.sumDoublesAcrossRanks(buffer.data(), n);
        for (std::size_t i = 0; i < n; ++i)
        {
          values[first + i] = static_cast<float>(buffer[i]);
        }
      }
      secondsReducing += secondsSince(sumStart);
    }
    for (const WorkerCounters& c : counters)
    {
      stats.gatheringRays += c.gatheringRays;
      stats.missedRays += c.missedRays;
    }
  }
  else
  {
    indirectFromPatches(scene, solution);
  }
  stats.secondsGathering = secondsSince(gatheringStart);
  if (options.ranks > 1)
  {
    // The counters of the rays each rank traced (reachability's are every rank's own).
    std::int64_t counts[7] = { static_cast<std::int64_t>(stats.shootingRays),
      static_cast<std::int64_t>(stats.shadowRays), static_cast<std::int64_t>(stats.gatheringRays),
      static_cast<std::int64_t>(stats.missedRays), static_cast<std::int64_t>(firstHits),
      static_cast<std::int64_t>(backAbsorbed), static_cast<std::int64_t>(stats.shadowRaysBlocked) };
    const auto sumStart = Clock::now();
    options.sumAcrossRanks(counts, 7);
    secondsReducing += secondsSince(sumStart);
    stats.shootingRays = static_cast<std::uint64_t>(counts[0]);
    stats.shadowRays = static_cast<std::uint64_t>(counts[1]);
    stats.gatheringRays = static_cast<std::uint64_t>(counts[2]);
    stats.missedRays = static_cast<std::uint64_t>(counts[3]);
    firstHits = static_cast<std::uint64_t>(counts[4]);
    backAbsorbed = static_cast<std::uint64_t>(counts[5]);
    stats.shadowRaysBlocked = static_cast<std::uint64_t>(counts[6]);
  }
  stats.secondsReducing = secondsReducing;
  chooseLitSides(scene, solution);

  stats.frames = frames;
  stats.patches = scene.patchCount();
  stats.elements = scene.elementCount();
  stats.effectivePathsPerFrame = options.pathsPerFrame;
  stats.meanPathLength = stats.pathsCast > 0
    ? 1.0 + (static_cast<double>(stats.shootingRays) / static_cast<double>(stats.pathsCast) - 1.0) / lambda
    : 0.0;
  stats.memoryEstimateBytes = memory;
  stats.accumulatorCopyPerWorker = plan.accumulatorCopyPerWorker;
  stats.firstHits = firstHits - backAbsorbed;
  stats.threads = workers;
  stats.reuseShooting = options.reuseShooting;
  stats.reuseGathering = options.reuseGathering;
  stats.twoSided = options.twoSided;
  stats.secondsTotal = secondsSince(start);

  if (firstHits == 0)
  {
    solution.warnings.push_back(
      "no light reached the scene: the light may face away from it (it emits along its "
      "normal), lie outside it, or be off in every frame; the result is all zero");
  }
  else if (!options.twoSided && backAbsorbed * 2 > firstHits)
  {
    std::ostringstream s;
    s << "one-sided surfaces: " << backAbsorbed << " of " << firstHits
      << " first hits reached back faces, which absorb everything; the surfaces probably face "
         "away from the light: flip their normals or turn two-sided surfaces on";
    solution.warnings.push_back(s.str());
  }
  return solution;
}

} // namespace mlr
