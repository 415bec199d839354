#include "Solver.h"

#include "Chunks.h"
#include "Error.h"
#include "ErrorEstimate.h"
#include "Gathering.h"
#include "Parallel.h"
#include "RayTracer.h"
#include "Reachability.h"
#include "Shooting.h"

#include <algorithm>
#include <chrono>
#include <optional>
#include <sstream>

namespace mlr
{

namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// The progress's cost model, in units of one shooting path's rays (shootingCost), measured
/// in the Cornell box from 12,116 to 194,896 elements, 20,000 to 2 million paths and 30 to 300
/// frames (Documentation/Performance.md, "Progress"). Past a few thousand elements per
/// hundred thousand paths, the work per element side and frame outweighs the rays.
/// A probe ray of the setup, the tracer's build included.
constexpr double ProbeRayCost = 4;
/// A gathering ray, whose light is read in every frame.
constexpr double GatheringRayCost = 3.5;
/// Per element side and frame of one pass (a batch, or a solve without batches): shooting's
/// sums zeroed and reduced, gathering's light of each side scored, and a batch merged into
/// the running mean and spread.
constexpr double ShootingSideFrameCost = 0.085;
constexpr double GatheringSideFrameCost = 0.2;
constexpr double BatchSideFrameCost = 0.09;

/// The batches a solve runs (its first round's): 1 without an error estimate.
double batchCount(const SolverOptions& options)
{
  return estimatesError(options) ? static_cast<double>(options.errorBatches) : 1.0;
}

/// The options of one pass: a batch's N.
SolverOptions passOptions(const SolverOptions& options)
{
  SolverOptions pass = options;
  pass.pathsPerFrame = std::max<std::uint64_t>(
    1, options.pathsPerFrame / static_cast<std::uint64_t>(batchCount(options)));
  return pass;
}

/// The expected cost of one pass's gathering: its k N rays, at least one per element side
/// (per frame without reuse), and its work per side and frame; none without gathering (k = 0:
/// the patches' light is copied, and the pass reports no gathering progress).
double gatheringCost(const Scene& scene, std::size_t frames, const SolverOptions& pass)
{
  if (!(pass.gatheringRatio > 0))
  {
    return 0;
  }
  const double rays = std::max(
    pass.gatheringRatio * static_cast<double>(pass.pathsPerFrame), elementSides(scene, pass));
  return GatheringRayCost * rays * (pass.reuseGathering ? 1.0 : static_cast<double>(frames)) +
    GatheringSideFrameCost * elementSides(scene, pass) * static_cast<double>(frames);
}

/// The work per side and frame of one pass besides gathering's: shooting's, and a batch's
/// merge.
double passSideFrameCost(const Scene& scene, std::size_t frames, const SolverOptions& options)
{
  return (ShootingSideFrameCost + (estimatesError(options) ? BatchSideFrameCost : 0.0)) *
    elementSides(scene, options) * static_cast<double>(frames);
}

/// The fractions of the progress its phases take, weighted by their expected cost: the
/// reachability probes (none when a SolveSetup brings them), then the passes (one per batch),
/// each shooting every source, then gathering.
struct ProgressPlan
{
  double probing = 0;
  /// Of a pass's progress.
  std::vector<double> shooting;

  ProgressPlan(const Scene& scene, const std::vector<LightSource>& sources, std::size_t frames,
    const SolverOptions& options, double setupCost)
  {
    const SolverOptions pass = passOptions(options);
    const double perSource = ShootingSideFrameCost * elementSides(scene, options) *
      static_cast<double>(frames) / static_cast<double>(std::max<std::size_t>(1, sources.size()));
    double total = 0;
    for (const LightSource& source : sources)
    {
      this->shooting.push_back(shootingCost(source, pass) + perSource);
      total += this->shooting.back();
    }
    total += gatheringCost(scene, frames, pass);
    for (double& share : this->shooting)
    {
      share /= total;
    }
    const double merges = estimatesError(options)
      ? BatchSideFrameCost * elementSides(scene, options) * static_cast<double>(frames)
      : 0.0;
    this->probing = setupCost / (setupCost + batchCount(options) * (total + merges));
  }
};

/// The statistics that do not count rays, and the warnings about where the light went.
void finish(const Scene& scene, const SolverOptions& options, std::size_t frames,
  const MemoryPlan& plan, int workers, std::uint64_t firstHits, std::uint64_t backAbsorbed,
  Solution& solution)
{
  SolverStatistics& stats = solution.statistics;
  stats.frames = frames;
  stats.patches = scene.patchCount();
  stats.elements = scene.elementCount();
  stats.effectivePathsPerFrame =
    solution.hasErrorEstimate() ? solution.errorEstimate.pathsPerFrame : options.pathsPerFrame;
  stats.meanPathLength = stats.pathsCast > 0 ? 1.0 +
      (static_cast<double>(stats.shootingRays) / static_cast<double>(stats.pathsCast) - 1.0) /
        options.firstBounceSurvival
                                             : 0.0;
  stats.memoryEstimateBytes = plan.peak;
  stats.memoryResultBytes = plan.results;
  stats.memoryAccumulatorBytes = plan.accumulators;
  stats.accumulatorCopyPerWorker = plan.accumulatorCopyPerWorker;
  stats.firstHits = firstHits - backAbsorbed;
  stats.threads = workers;
  stats.reuseShooting = options.reuseShooting;
  stats.reuseGathering = options.reuseGathering;
  stats.twoSided = options.twoSided;
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
}
}

double predictedSpeedup(
  std::size_t frames, double gatheringRatio, double lambda, double meanPathLength)
{
  const double n = static_cast<double>(frames);
  const double walk = lambda * (meanPathLength - 1.0);
  return (n * (1.0 + walk) + gatheringRatio * n) / (n + walk + gatheringRatio);
}

namespace
{
double storageScaleOf(const Scene& scene, const std::vector<LightSource>& sources)
{
  double power = 0;
  for (const LightSource& source : sources)
  {
    double brightest = 0;
    for (std::size_t k = 0; k < source.positions(); ++k)
    {
      brightest = std::max(brightest, (source.power() * source.factor(k)).maxComponent());
    }
    power += brightest;
  }
  return Solution::storageScaleFor(scene.totalArea(), power);
}
} // namespace

double storageScaleFor(const Scene& scene, const LightRig& rig)
{
  return storageScaleOf(scene, lightSources(scene, rig, sceneEmitters(scene)));
}

void validateOptions(const SolverOptions& options)
{
  if (options.pathsPerFrame == 0)
  {
    throw Error("the number of paths per frame is 0: give at least 1 (600000 is typical)");
  }
  validateErrorOptions(options);
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
    throw Error("the gathering ratio k is " + formatNumber(options.gatheringRatio) +
      ": it must be 0 (no final gathering) or positive (1 is typical)");
  }
  if (options.gatheringRatio * static_cast<double>(options.pathsPerFrame) >
    static_cast<double>(MaximumPathsPerFrame))
  {
    throw Error("the gathering ratio k times the paths per frame is over the maximum of " +
      std::to_string(MaximumPathsPerFrame) + " rays per frame");
  }
  if (!(options.storageScale >= 0) || !std::isfinite(options.storageScale))
  {
    throw Error("the storage scale must be 0 (from the scene and its lights) or positive");
  }
  if (const std::string problem = chunkSettingsProblem(
        options.framesPerChunk, options.chunkOverlap, "framesPerChunk", "chunkOverlap");
      !problem.empty())
  {
    throw Error("the option " + problem);
  }
  if (options.chunkOverlap > MaximumChunkOverlap)
  {
    throw Error("the chunk overlap is " + std::to_string(options.chunkOverlap) +
      " frames: give at most " + std::to_string(MaximumChunkOverlap));
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

Solution solve(const Scene& scene, const MovingLight& light, const SolverOptions& options,
  const ProgressCallback& progress)
{
  LightRig rig;
  rig.areaLights.push_back(light);
  return solve(scene, rig, options, progress);
}

namespace
{
Solution solveWith(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress, const SolveSetup* setup)
{
  const auto start = Clock::now();
  // Setup, up to the allocations, is one phase the ranks agree on: a rank over its memory
  // limit (checked per rank) or cancelled stops every rank here.
  std::size_t frames = 0;
  int workers = 1;
  MemoryPlan plan;
  std::vector<MovingLight> emitters;
  std::vector<LightSource> sources;
  std::optional<ProgressPlan> shares;
  std::optional<RayTracer> tracerStorage;
  Solution solution;
  double secondsReducing = 0;
  const bool batched = estimatesError(options);
  agreeAcrossRanks(
    options,
    [&]
    {
      validateOptions(options);
      frames = frameCount(rig, scene.hasEmission());
      workers = resolveThreadCount(options.threads);
      emitters = sceneEmitters(scene);
      sources = lightSources(scene, rig, emitters);
      // With a setup, the sides it found bound this solve's (the bound of every side else).
      plan = planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(),
        frames, options, sources.size(), setup ? &setup->reachable() : nullptr,
        setup ? &setup->firstHits() : nullptr);
      checkSolveMemory(plan.peak, frames, scene.patchCount(), scene.elementCount(), options);
      for (const LightSource& source : sources)
      {
        checkBatchPathsPerPosition(source, options);
      }
      shares.emplace(
        scene, sources, frames, options, setup ? 0.0 : SolveSetup::cost(scene, options));
      if (progress && !progress(0.0))
      {
        throw Cancelled();
      }
      if (!setup)
      {
        tracerStorage.emplace(scene);
      }
      solution = Solution(frames, scene.elementCount(), scene.patchCount());
      solution.setStorageScale(
        options.storageScale > 0 ? options.storageScale : storageScaleOf(scene, sources));
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        solution.reflectanceData()[e] = scene.elementReflectance(e);
      }
      if (scene.hasEmission())
      {
        solution.emissionData().resize(scene.elementCount());
        for (std::size_t e = 0; e < scene.elementCount(); ++e)
        {
          solution.emissionData()[e] = scene.elementEmission(e);
        }
      }
    },
    &secondsReducing);
  const RayTracer& tracer = setup ? setup->tracer() : *tracerStorage;
  SolverStatistics& stats = solution.statistics;
  // What follows the probes: the passes, a batched solve's too.
  ProgressCallback passesProgress;
  if (progress)
  {
    passesProgress = [&progress, probing = shares->probing](double f)
    { return progress(probing + (1.0 - probing) * f); };
  }

  // How each moving light's reused paths are shared over its positions: chosen once, from
  // the whole solve's N and seed, for every batch and round.
  std::vector<std::vector<double>> positionShare(sources.size());
  agreeAcrossRanks(
    options,
    [&]
    {
      for (std::size_t i = 0; i < sources.size(); ++i)
      {
        positionShare[i] = positionShares(
          scene, sources[i], options, tracer, workers,
          [&](double) { return !progress || progress(0.0); }, stats.pilotRays);
      }
    },
    &secondsReducing);

  // The patch sides light can reach, from geometry alone (deterministic and cheap: every rank
  // probes every side): only they get shooting accumulators and gather. With them known, the
  // plan counts the accumulators they take, and may give each worker a copy after all.
  // A chunk takes those of the whole animation's setup instead.
  std::vector<std::uint8_t> reachable, firstHits;
  if (setup)
  {
    reachable = setup->reachable();
    firstHits = setup->firstHits();
  }
  else
  {
    agreeAcrossRanks(
      options,
      [&]
      {
        reachable = reachableSides(
          scene, tracer, sources, options, workers,
          [&](double f) { return !progress || progress(shares->probing * f); },
          stats.reachabilityRays, &firstHits);
      },
      &secondsReducing);
  }
  stats.secondsSetup = secondsSince(start);
  stats.reachableSides =
    static_cast<std::uint64_t>(std::count(reachable.begin(), reachable.end(), 1));
  plan = planSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), frames,
    options, sources.size(), reachable.empty() ? nullptr : &reachable,
    reachable.empty() ? nullptr : &firstHits);

  // One pass: shooting every source, then gathering, into `into`. A batched solve runs one per
  // batch, sharing the scene, the tracer and the reachable sides (which do not depend on the
  // seed).
  WorkerCounters rays;
  auto pass = [&](const SolverOptions& passOptions, Solution& into,
                const std::function<bool(double)>& fraction)
  {
    double progressBase = 0;
    auto phaseTick = [&](double share)
    {
      const double base = progressBase;
      progressBase += share;
      return [&fraction, base, share](double f) { return !fraction || fraction(base + share * f); };
    };
    // Shooting, one source at a time: each has its own accumulators, added to the solution.
    const auto shootingStart = Clock::now();
    for (std::size_t i = 0; i < sources.size(); ++i)
    {
      const ShootingResult shot =
        shoot(scene, sources[i], passOptions, tracer, workers, plan.accumulatorCopyPerWorker,
          positionShare[i], reachable, phaseTick(shares->shooting[i]), secondsReducing, into);
      stats.pathsCast += shot.pathsCast;
      stats.staticPathsCast += sources[i].isStatic() ? shot.pathsCast : 0;
      if (!sources[i].isStatic())
      {
        stats.smallestPositionShare = std::min(stats.smallestPositionShare, shot.smallestShare);
        stats.largestPositionShare = std::max(stats.largestPositionShare, shot.largestShare);
      }
      rays += shot.counters;
      stats.overflowSides += shot.overflowSides;
    }
    stats.secondsShooting += secondsSince(shootingStart);

    // Final gathering, once, on the sum of every source's patch solution. The accumulators
    // are gone: the indirect light takes their memory.
    const auto gatheringStart = Clock::now();
    into.allocateIndirect();
    if (passOptions.gatheringRatio > 0)
    {
      const GatheringResult gathered = gatherIndirect(scene, tracer, passOptions, reachable,
        workers, phaseTick(1.0 - progressBase), secondsReducing, into, plan.gathering);
      stats.gatheringSides = gathered.sides;
      rays += gathered.counters;
    }
    else
    {
      indirectFromPatches(scene, into);
    }
    stats.secondsGathering += secondsSince(gatheringStart);
  };

  if (batched)
  {
    // The batches solve into one more Solution, with the same reflectance and emission,
    // whose light is merged into `solution` after each.
    Solution batch(frames, scene.elementCount(), scene.patchCount());
    batch.setStorageScale(solution.storageScale());
    batch.reflectanceData() = solution.reflectanceData();
    batch.emissionData() = solution.emissionData();
    std::uint64_t batchIndex = 0;
    solveInBatches(
      scene, options,
      [&](
        const SolverOptions& batchOptions, const std::function<bool(double)>& fraction) -> Solution&
      {
        batch.clearRadiosity();
        pass(batchOptions, batch, fraction);
        if (options.batchSolved)
        {
          options.batchSolved(batchIndex, rig.firstFrame, batch);
        }
        ++batchIndex;
        return batch;
      },
      passesProgress, plan.peak, secondsReducing, solution);
  }
  else
  {
    pass(options, solution, passesProgress);
  }
  stats.sources = sources.size();
  // The counters of the rays each rank traced (reachability's are every rank's own).
  std::uint64_t counts[7] = { rays.shootingRays, rays.shadowRays, rays.gatheringRays,
    rays.missedRays, rays.firstHits, rays.firstHitsOnBack, rays.shadowRaysBlocked };
  sumAcrossRanks(options, counts, 7, secondsReducing);
  stats.shootingRays = counts[0];
  stats.shadowRays = counts[1];
  stats.gatheringRays = counts[2];
  stats.missedRays = counts[3];
  stats.shadowRaysBlocked = counts[6];
  stats.secondsReducing = secondsReducing;
  if (!batched)
  {
    solution.chooseLitSides(scene, workers);
  }
  finish(scene, options, frames, plan, workers, counts[4], counts[5], solution);
  stats.secondsTotal = secondsSince(start);
  return solution;
}
} // namespace

Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress)
{
  return solveWith(scene, rig, options, progress, nullptr);
}

Solution solve(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress, const SolveSetup& setup)
{
  return solveWith(scene, rig, options, progress, &setup);
}

SolveSetup::SolveSetup(const Scene& scene, const LightRig& rig, const SolverOptions& options,
  const ProgressCallback& progress)
{
  const auto start = Clock::now();
  validateOptions(options);
  frameCount(rig, scene.hasEmission());
  const int workers = resolveThreadCount(options.threads);
  const std::vector<MovingLight> emitters = sceneEmitters(scene);
  const std::vector<LightSource> sources = lightSources(scene, rig, emitters);
  if (progress && !progress(0.0))
  {
    throw Cancelled();
  }
  this->Tracer = std::make_unique<RayTracer>(scene);
  this->Reachable = reachableSides(
    scene, *this->Tracer, sources, options, workers,
    [&](double f) { return !progress || progress(f); }, this->ReachabilityRays, &this->FirstHits);
  this->Seconds = secondsSince(start);
}

SolveSetup::~SolveSetup() = default;

double SolveSetup::cost(const Scene& scene, const SolverOptions& options)
{
  return ProbeRayCost * static_cast<double>(scene.patchCount()) * (options.twoSided ? 2.0 : 1.0) *
    ReachabilityProbesPerSide;
}

double elementSides(const Scene& scene, const SolverOptions& options)
{
  return static_cast<double>(scene.elementCount()) * (options.twoSided ? 2.0 : 1.0);
}

double solveCost(
  const Scene& scene, const LightRig& rig, const SolverOptions& options, std::size_t positions)
{
  const std::size_t frames = positions > 0 ? positions : frameCount(rig, scene.hasEmission());
  double shooting = 0;
  auto add = [&](std::size_t lightFrames)
  { shooting += shootingCost(lightFrames > 1 ? frames : 1, options); };
  for (const MovingLight& light : rig.areaLights)
  {
    add(light.frameCount());
  }
  for (const PointLight& light : rig.pointLights)
  {
    add(light.frameCount());
  }
  for (const DirectionalLight& light : rig.directionalLights)
  {
    add(light.frameCount());
  }
  for (const Sky& sky : rig.skies)
  {
    add(sky.frameCount());
  }
  if (scene.hasEmission())
  {
    add(1);
  }
  // Shooting's rays are the whole N's however it is batched; the rest is every pass's.
  return shooting +
    batchCount(options) *
    (gatheringCost(scene, frames, passOptions(options)) +
      passSideFrameCost(scene, frames, options));
}

} // namespace mlr
