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
#include <initializer_list>
#include <limits>
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

std::string gibibytes(std::uint64_t bytes)
{
  std::ostringstream s;
  s.precision(3);
  s << static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0) << " GiB";
  return s.str();
}

/// a * b, saturating at UINT64_MAX.
std::uint64_t saturatingProduct(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t product = 0;
  return __builtin_mul_overflow(a, b, &product) ? UINT64_MAX : product;
}

std::uint64_t saturatingSum(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t sum = 0;
  return __builtin_add_overflow(a, b, &sum) ? UINT64_MAX : sum;
}

/// A walk longer than this is cut: with reflectance < 1 it is astronomically unlikely,
/// and the cut bounds the time between two cancellation checks.
constexpr int MaximumBounces = 100000;

/// Shooting paths per task: small enough that cancellation is noticed within
/// milliseconds, large enough that scheduling costs nothing.
constexpr std::uint64_t ReusedPathsPerTask = 256;
constexpr std::uint64_t ClassicPathsPerTask = 2048;
constexpr std::size_t GatheringSidesPerTask = 32;

struct alignas(64) WorkerCounters
{
  std::uint64_t shootingRays = 0;
  std::uint64_t shadowRays = 0;
  std::uint64_t gatheringRays = 0;
  std::uint64_t missedRays = 0;
  std::uint64_t firstHits = 0;
  std::uint64_t firstHitsOnBack = 0; ///< one-sided mode: first hits absorbed by a back face
};

/// Scratch vectors one worker reuses for every path.
struct WorkerScratch
{
  std::vector<double> kernel;
  std::vector<Vec3> targets;
  std::vector<std::uint32_t> targetFrames;
  std::vector<std::uint8_t> visible;
  std::vector<Rgb> gathered;
};

/// Everything one solve shares between its phases and workers.
class SolveRun
{
public:
  SolveRun(const Scene& scene, const MovingLight& light, const SolverOptions& options,
    const RayTracer& tracer, int workers)
    : SceneRef(scene)
    , Light(light)
    , Options(options)
    , Tracer(tracer)
    , Frames(light.frameCount())
    , Workers(workers)
    , ElementShare(workers, scene.elementCount(), light.frameCount(), 0x1.0p-50,
        options.reuseShooting ? FrameLayout::FramesInner : FrameLayout::FramesOuter)
    , PatchPower(workers, scene.patchCount(), light.frameCount(),
        (light.power().maxComponent() > 0 ? light.power().maxComponent() : 1.0) * 0x1.0p-40,
        options.reuseShooting ? FrameLayout::FramesInner : FrameLayout::FramesOuter)
    , Counters(static_cast<std::size_t>(workers))
    , Scratch(static_cast<std::size_t>(workers))
  {
    for (WorkerScratch& s : this->Scratch)
    {
      s.kernel.resize(this->Frames);
      s.targets.resize(this->Frames);
      s.targetFrames.resize(this->Frames);
      s.visible.resize(this->Frames);
      s.gathered.resize(this->Frames);
    }
    // M_k paths start from position k; they add up to N exactly.
    const std::uint64_t n = this->Frames;
    const std::uint64_t N = options.pathsPerFrame;
    for (const Vec3& t : light.translations())
    {
      this->TranslationX.push_back(t.x);
      this->TranslationY.push_back(t.y);
      this->TranslationZ.push_back(t.z);
    }
    this->PathsFromPosition.resize(this->Frames);
    for (std::uint64_t k = 0; k < n; ++k)
    {
      this->PathsFromPosition[k] = static_cast<double>(N / n + (k < N % n ? 1 : 0));
    }
  }

  void shootReused(std::uint64_t path, int worker);
  void shootClassic(std::uint64_t frame, std::uint64_t path, int worker);
  void finishShooting(Solution& solution) const;
  std::vector<std::uint32_t> gatheringSides(std::uint64_t& rays, std::uint64_t total) const;
  void gather(std::uint32_t elementSide, std::uint64_t rays, bool reuse, const Solution& solution,
    Solution& out, int worker);

  const std::vector<WorkerCounters>& counters() const { return this->Counters; }

  /// True if side s of patch p received shooting power: a later bounce, or a first hit on
  /// one of its elements.
  bool patchReceived(std::size_t p, int s) const
  {
    if (this->PatchPower.received(p, s))
    {
      return true;
    }
    for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch; ++e)
    {
      if (this->ElementShare.received(e, s))
      {
        return true;
      }
    }
    return false;
  }

  /// Which position path `path` of a reuse solve starts from.
  std::size_t positionOfPath(std::uint64_t path) const
  {
    const std::uint64_t n = this->Frames;
    const std::uint64_t base = this->Options.pathsPerFrame / n;
    const std::uint64_t extra = this->Options.pathsPerFrame % n;
    const std::uint64_t firstBlock = extra * (base + 1);
    if (path < firstBlock)
    {
      return static_cast<std::size_t>(path / (base + 1));
    }
    return static_cast<std::size_t>(extra + (path - firstBlock) / base);
  }

private:
  bool emit(RandomStream& random, std::size_t position, int worker, Vec3& x, Vec3& lightNormal,
    RayHit& hit);
  void scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
    std::size_t firstFrame, std::size_t frameCount, int worker);
  // Always inlined, like the prefetch it calls: GCC would delete the call otherwise.
  [[gnu::always_inline]] inline void prefetchFirstHit(
    const RayHit& hit, std::size_t firstFrame, std::size_t frameCount, int worker);

  const Scene& SceneRef;
  const MovingLight& Light;
  const SolverOptions& Options;
  const RayTracer& Tracer;
  std::size_t Frames;
  int Workers;
  // Direct light needs one scalar per element side and frame: the share of the light's
  // power whose first hit lands there. Its colour rho_e Phi is the same for every hit, and
  // a scalar is a third of the memory traffic of RGB in the hottest loop.
  FixedPointAccumulator<1> ElementShare;
  // The patch solution's reflected power (W), RGB, from the second hit of a walk on; the
  // first hits come from ElementShare.
  FixedPointAccumulator<3> PatchPower;
  std::vector<WorkerCounters> Counters;
  std::vector<WorkerScratch> Scratch;
  std::vector<double> PathsFromPosition;
  // The light's translations as a structure of arrays, for the vectorised weights.
  std::vector<double> TranslationX, TranslationY, TranslationZ;
};

/**
 * Scores a walk's first hit on the element (direct) and patch, then follows it: continue
 * with probability lambda, and at every later hit score the patch and play Russian
 * roulette with the maximum reflectance channel. shares[f] is the fraction of the light's
 * power the walk carries to its first hit in frame firstFrame + f: 1/N for a classic path,
 * G(x_j,y) / sum_k M_k G(x_k,y) for a reused one. A walk's power in frame f is then
 * colour * shares[f], with one RGB colour for all frames: the frames differ only by scalar
 * weights.
 *
 * METHOD.md writes step 3 as P <- P / lambda; the power that leaves the first hit is the
 * reflected power, so we carry rho * P / lambda (the energy balance test checks this).
 */
void SolveRun::scoreAndWalk(RandomStream& random, const RayHit& firstHit, const double* shares,
  std::size_t firstFrame, std::size_t frameCount, int worker)
{
  // The first hit scores only the element's share: the patch's first-hit power is
  // rho_p Phi times the shares of its four elements, added when shooting ends. That keeps
  // the RGB patch slots (3n values) out of the one write every path makes.
  const int firstSide = static_cast<int>(firstHit.side);
  const Rgb& firstRho = this->SceneRef.elementReflectance(firstHit.element);
  Rgb colour = firstRho * this->Light.power();
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
inline void SolveRun::prefetchFirstHit(
  const RayHit& hit, std::size_t firstFrame, std::size_t frameCount, int worker)
{
  this->ElementShare.prefetch(
    this->ElementShare.slots(worker, hit.element, static_cast<int>(hit.side)), firstFrame, frameCount);
}

/// Starts a walk from the light at `position`: a uniform point x of the light (own frame)
/// with its normal, a cosine direction and the first ray. False when the walk ends there: a
/// miss (the power leaves the scene) or, with one-sided surfaces, a back face.
bool SolveRun::emit(RandomStream& random, std::size_t position, int worker, Vec3& x,
  Vec3& lightNormal, RayHit& hit)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  const double u0 = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
  this->Light.samplePoint(u0, u1, u2, x, lightNormal);
  const Vec3 direction = sampleCosineDirection(lightNormal, random);
  const Vec3 start = x + this->Light.translation(position);
  ++counters.shootingRays;
  if (!this->Tracer.intersect(this->Tracer.liftOff(start, lightNormal), direction, hit))
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

void SolveRun::shootReused(std::uint64_t path, int worker)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  WorkerScratch& scratch = this->Scratch[static_cast<std::size_t>(worker)];
  const std::size_t origin = this->positionOfPath(path);
  RandomStream random(this->Options.seed, StreamPurpose::Shooting, path, 0);

  Vec3 x, lightNormal;
  RayHit hit;
  if (!this->emit(random, origin, worker, x, lightNormal, hit))
  {
    return;
  }
  this->prefetchFirstHit(hit, 0, this->Frames, worker);

  // Mixture weights w_j = G(x_j, y) / sum_k M_k G(x_k, y), with real visibility. The pi of
  // G cancels; with d = y - x_j unnormalised, cos_x cos_y / r^2 = (n_x.d)(-n_y.d) / |d|^4.
  // The loop is branch-free over the positions (structure of arrays) so that it vectorises.
  const Vec3 ny = this->SceneRef.elementSideNormal(hit.element, hit.side);
  const Vec3 toHit = hit.point - x;
  double* kernel = scratch.kernel.data();
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    const double dx = toHit.x - this->TranslationX[j];
    const double dy = toHit.y - this->TranslationY[j];
    const double dz = toHit.z - this->TranslationZ[j];
    const double cosX = lightNormal.x * dx + lightNormal.y * dy + lightNormal.z * dz;
    const double cosY = -(ny.x * dx + ny.y * dy + ny.z * dz);
    const double r2 = dx * dx + dy * dy + dz * dz;
    const double g = cosX * cosY / std::max(r2 * r2, std::numeric_limits<double>::min());
    kernel[j] = cosX > 0 && cosY > 0 ? g : 0.0;
  }
  std::size_t shadowCount = 0;
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    if (kernel[j] > 0 && j != origin)
    {
      scratch.targets[shadowCount] = x + this->Light.translation(j);
      scratch.targetFrames[shadowCount] = static_cast<std::uint32_t>(j);
      ++shadowCount;
    }
  }
  if (shadowCount > 0)
  {
    this->Tracer.visibleFrom(
      this->Tracer.liftOff(hit.point, ny), scratch.targets.data(), shadowCount, scratch.visible.data());
    counters.shadowRays += shadowCount;
    for (std::size_t s = 0; s < shadowCount; ++s)
    {
      if (!scratch.visible[s])
      {
        kernel[scratch.targetFrames[s]] = 0;
      }
    }
  }
  double mixture = 0;
  for (std::size_t j = 0; j < this->Frames; ++j)
  {
    mixture += this->PathsFromPosition[j] * scratch.kernel[j];
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
  this->scoreAndWalk(random, hit, scratch.kernel.data(), 0, this->Frames, worker);
}

void SolveRun::shootClassic(std::uint64_t frame, std::uint64_t path, int worker)
{
  RandomStream random(this->Options.seed, StreamPurpose::Shooting, path, frame + 1);
  Vec3 x, lightNormal;
  RayHit hit;
  if (!this->emit(random, static_cast<std::size_t>(frame), worker, x, lightNormal, hit))
  {
    return;
  }
  const double share = 1.0 / static_cast<double>(this->Options.pathsPerFrame);
  this->scoreAndWalk(random, hit, &share, static_cast<std::size_t>(frame), 1, worker);
}

/// Turns the accumulated power into radiosity (W/m^2) in the solution.
void SolveRun::finishShooting(Solution& solution) const
{
  const std::size_t elements = this->SceneRef.elementCount();
  const std::size_t patches = this->SceneRef.patchCount();
  std::vector<Rgb>& direct = solution.directData();
  std::vector<Rgb>& patch = solution.patchData();
  for (std::size_t e = 0; e < elements; ++e)
  {
    const Rgb exitance =
      this->SceneRef.elementReflectance(e) * this->Light.power() / this->SceneRef.elementArea(e);
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < this->Frames; ++f)
      {
        double share = 0;
        this->ElementShare.total(e, s, f, &share);
        direct[solution.elementIndex(f, e, static_cast<Side>(s))] = exitance * share;
      }
    }
  }
  for (std::size_t p = 0; p < patches; ++p)
  {
    const double inverseArea = 1.0 / this->SceneRef.patchArea(p);
    const Rgb firstHitColour = this->SceneRef.patchReflectance(p) * this->Light.power();
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < this->Frames; ++f)
      {
        double power[3];
        this->PatchPower.total(p, s, f, power);
        double share = 0;
        for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch; ++e)
        {
          double elementShare = 0;
          this->ElementShare.total(e, s, f, &elementShare);
          share += elementShare;
        }
        patch[solution.patchIndex(f, p, static_cast<Side>(s))] =
          (Rgb(power[0], power[1], power[2]) + firstHitColour * share) * inverseArea;
      }
    }
  }
}

/**
 * The element sides that gather: those whose patch side received shooting power (the
 * inside of a closed block never does). Returns them as element * 2 + side, in element
 * order, and sets `rays` to the rays each casts so that together they cast about `total`
 * (at least one each: equal counts keep every side's estimate equally accurate).
 */
std::vector<std::uint32_t> SolveRun::gatheringSides(std::uint64_t& rays, std::uint64_t total) const
{
  std::vector<std::uint32_t> sides;
  const std::size_t patches = this->SceneRef.patchCount();
  for (std::size_t p = 0; p < patches; ++p)
  {
    for (int s = 0; s < 2; ++s)
    {
      if (this->patchReceived(p, s))
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
void SolveRun::gather(std::uint32_t elementSide, std::uint64_t rays, bool reuse,
  const Solution& shooting, Solution& out, int worker)
{
  WorkerCounters& counters = this->Counters[static_cast<std::size_t>(worker)];
  std::vector<Rgb>& sum = this->Scratch[static_cast<std::size_t>(worker)].gathered;
  const std::size_t element = elementSide / 2;
  const Side side = static_cast<Side>(elementSide % 2);
  const Triangle& t = this->SceneRef.elementTriangles()[element];
  const auto& points = this->SceneRef.points();
  const Vec3 normal = this->SceneRef.elementSideNormal(element, side);
  std::fill(sum.begin(), sum.end(), Rgb());

  // A hit's row of patch radiosity is added after the next ray is traced: the row was
  // prefetched when the hit was found, so the trace hides its cache miss.
  const std::size_t passes = reuse ? 1 : this->Frames;
  const std::size_t rowLength = reuse ? this->Frames : 1;
  for (std::size_t pass = 0; pass < passes; ++pass)
  {
    Rgb* into = reuse ? sum.data() : &sum[pass];
    const Rgb* pending = nullptr;
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
    RandomStream random(this->Options.seed, StreamPurpose::Gathering, elementSide, reuse ? 0 : pass + 1);
    for (std::uint64_t r = 0; r < rays; ++r)
    {
      const double u1 = random.uniform(), u2 = random.uniform();
      const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
      const Vec3 direction = sampleCosineDirection(normal, random);
      ++counters.gatheringRays;
      RayHit hit;
      const bool found = this->Tracer.intersect(this->Tracer.liftOff(origin, normal), direction, hit);
      addPending();
      if (!found)
      {
        ++counters.missedRays;
        continue;
      }
      if (!this->Options.twoSided && hit.side == Side::Back)
      {
        continue;
      }
      pending = &shooting.patchRadiosity(reuse ? 0 : pass, Scene::patchOfElement(hit.element), hit.side);
      const char* row = reinterpret_cast<const char*>(pending);
      for (std::size_t byte = 0; byte < rowLength * sizeof(Rgb); byte += 64)
      {
        __builtin_prefetch(row + byte);
      }
    }
    addPending();
  }
  const Rgb scale = this->SceneRef.elementReflectance(element) / static_cast<double>(rays);
  for (std::size_t f = 0; f < this->Frames; ++f)
  {
    out.indirectData()[out.elementIndex(f, element, side)] = scale * sum[f];
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
        const Rgb& b = solution.patchRadiosity(f, p, static_cast<Side>(s));
        const Rgb rest(std::max(0.0, b.r - patchDirect.r), std::max(0.0, b.g - patchDirect.g),
          std::max(0.0, b.b - patchDirect.b));
        for (std::size_t e = p * 4; e < p * 4 + 4; ++e)
        {
          solution.indirectData()[solution.elementIndex(f, e, static_cast<Side>(s))] = rest;
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
  , Indirect(frames * elements * 2)
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
  if (!(options.firstBounceSurvival > 0.0 && options.firstBounceSurvival <= 1.0))
  {
    throw Error("the first-bounce survival probability lambda is " +
      std::to_string(options.firstBounceSurvival) + ": it must be in (0, 1] (0.25 is typical)");
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
}

std::uint64_t estimateSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
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
  // Results: direct and indirect per element side, shooting radiosity per patch side.
  const std::uint64_t results = times({ frames,
    saturatingSum(times({ elements, 2, 2 }), times({ patches, 2 })), sizeof(Rgb) });
  // The fixed-point accumulators (FixedPointAccumulator::bytes), one copy per worker.
  const std::uint64_t accumulators =
    saturatingSum(times({ workers, elements, 2, frames, 1, sizeof(std::int64_t) }),
      times({ workers, patches, 2, frames, 3, sizeof(std::int64_t) }));
  const std::uint64_t scratch = times({ workers, frames, 2 * sizeof(Rgb) + sizeof(Vec3) + 16 });
  // Embree's BVH and buffers, generously.
  const std::uint64_t tracing = saturatingSum(times({ elements, 256 }), times({ points, 16 }));
  return saturatingSum(saturatingSum(results, accumulators), saturatingSum(scratch, tracing));
}

std::uint64_t estimateSolveMemory(
  const Scene& scene, std::size_t frames, const SolverOptions& options)
{
  return estimateSolveMemory(
    scene.patchCount(), scene.elementCount(), scene.points().size(), frames, options);
}

std::uint64_t defaultMemoryLimitBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0)
  {
    return 4ULL << 30;
  }
  return static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(pageSize) / 2;
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
    << ": use fewer frames, a larger patch size or fewer threads, or raise the limit";
  throw Error(s.str());
}

Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress)
{
  const auto start = Clock::now();
  validateOptions(options);
  const std::size_t frames = light.frameCount();
  const int workers = resolveThreadCount(options.threads);
  const std::uint64_t memory = estimateSolveMemory(scene, frames, options);
  checkSolveMemory(memory, frames, scene.patchCount(), scene.elementCount(), options);

  // Progress: phases weighted by their expected ray counts.
  const double n = static_cast<double>(frames);
  const double N = static_cast<double>(options.pathsPerFrame);
  const double lambda = options.firstBounceSurvival;
  const double shootingCost = options.reuseShooting ? N * (1 + 1.5 * lambda + 0.2 * (n - 1))
                                                    : n * N * (1 + 1.5 * lambda);
  const double gatheringCost =
    options.gatheringRatio * N * (options.reuseGathering ? 1.0 : n);
  const double shootingShare = shootingCost / (shootingCost + gatheringCost);
  auto phaseTick = [&](double base, double share, std::size_t total) {
    return [&progress, base, share, total](std::size_t done) {
      return !progress ||
        progress(base + share * static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(total, 1)));
    };
  };
  if (progress && !progress(0.0))
  {
    throw Cancelled();
  }

  RayTracer tracer(scene);
  SolveRun run(scene, light, options, tracer, workers);
  Solution solution(frames, scene.elementCount(), scene.patchCount());
  SolverStatistics& stats = solution.statistics;
  stats.secondsSetup = secondsSince(start);

  // Shooting.
  const auto shootingStart = Clock::now();
  if (options.reuseShooting)
  {
    const std::uint64_t paths = options.pathsPerFrame;
    const std::uint64_t tasks = (paths + ReusedPathsPerTask - 1) / ReusedPathsPerTask;
    parallelFor(tasks, workers,
      [&](std::size_t task, int worker) {
        const std::uint64_t end = std::min<std::uint64_t>(paths, (task + 1) * ReusedPathsPerTask);
        for (std::uint64_t p = task * ReusedPathsPerTask; p < end; ++p)
        {
          run.shootReused(p, worker);
        }
      },
      phaseTick(0.0, shootingShare, tasks));
    stats.pathsCast = paths;
  }
  else
  {
    const std::uint64_t paths = options.pathsPerFrame;
    const std::uint64_t tasksPerFrame = (paths + ClassicPathsPerTask - 1) / ClassicPathsPerTask;
    const std::uint64_t tasks = tasksPerFrame * frames;
    parallelFor(tasks, workers,
      [&](std::size_t task, int worker) {
        const std::uint64_t frame = task / tasksPerFrame;
        const std::uint64_t first = (task % tasksPerFrame) * ClassicPathsPerTask;
        const std::uint64_t end = std::min<std::uint64_t>(paths, first + ClassicPathsPerTask);
        for (std::uint64_t p = first; p < end; ++p)
        {
          run.shootClassic(frame, p, worker);
        }
      },
      phaseTick(0.0, shootingShare, tasks));
    stats.pathsCast = paths * frames;
  }
  run.finishShooting(solution);
  stats.secondsShooting = secondsSince(shootingStart);

  // Final gathering.
  const auto gatheringStart = Clock::now();
  if (options.gatheringRatio > 0)
  {
    std::uint64_t raysPerSide = 0;
    const auto total = static_cast<std::uint64_t>(std::llround(options.gatheringRatio * N));
    const std::vector<std::uint32_t> sides = run.gatheringSides(raysPerSide, total);
    stats.gatheringSides = sides.size();
    const std::size_t tasks = (sides.size() + GatheringSidesPerTask - 1) / GatheringSidesPerTask;
    parallelFor(tasks, workers,
      [&](std::size_t task, int worker) {
        const std::size_t end = std::min(sides.size(), (task + 1) * GatheringSidesPerTask);
        for (std::size_t i = task * GatheringSidesPerTask; i < end; ++i)
        {
          run.gather(sides[i], raysPerSide, options.reuseGathering, solution, solution, worker);
        }
      },
      phaseTick(shootingShare, 1.0 - shootingShare, tasks));
  }
  else
  {
    indirectFromPatches(scene, solution);
  }
  stats.secondsGathering = secondsSince(gatheringStart);
  chooseLitSides(scene, solution);

  std::uint64_t firstHits = 0, backAbsorbed = 0;
  for (const WorkerCounters& c : run.counters())
  {
    stats.shootingRays += c.shootingRays;
    stats.shadowRays += c.shadowRays;
    stats.gatheringRays += c.gatheringRays;
    stats.missedRays += c.missedRays;
    firstHits += c.firstHits;
    backAbsorbed += c.firstHitsOnBack;
  }
  stats.frames = frames;
  stats.patches = scene.patchCount();
  stats.elements = scene.elementCount();
  stats.effectivePathsPerFrame = options.pathsPerFrame;
  stats.meanPathLength = stats.pathsCast > 0
    ? 1.0 + (static_cast<double>(stats.shootingRays) / static_cast<double>(stats.pathsCast) - 1.0) / lambda
    : 0.0;
  stats.memoryEstimateBytes = memory;
  stats.threads = workers;
  stats.reuseShooting = options.reuseShooting;
  stats.reuseGathering = options.reuseGathering;
  stats.twoSided = options.twoSided;
  stats.secondsTotal = secondsSince(start);

  if (firstHits == 0)
  {
    solution.warnings.push_back(
      "no light reached the scene: the light may face away from it (it emits along its "
      "normal) or lie outside it; the result is all zero");
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
