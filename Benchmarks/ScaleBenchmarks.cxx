#include "ScaleBenchmarks.h"
#include "ProcessMeasures.h"

#include "BareEmbree.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>

namespace mlr::bench
{
namespace
{
constexpr double GiB = 1024.0 * 1024.0 * 1024.0;

SolverOptions optionsFor(const ScaleCaseOptions& scale, std::uint64_t paths, bool reuse)
{
  SolverOptions o;
  o.pathsPerFrame = paths;
  o.gatheringRatio = 1;
  o.firstBounceSurvival = 0.25;
  o.threads = scale.threads;
  o.memoryLimitBytes = scale.memoryLimitBytes;
  o.reuseShooting = reuse;
  o.reuseGathering = reuse;
  return o;
}
}

std::string runLongAnimation(const ScaleCaseOptions& scale)
{
  constexpr std::size_t frames = 300;
  constexpr std::uint64_t paths = 600000;
  const scenes::PaperRoom room = scenes::paperScaleRoom(frames);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  const MovingLight light(room.light, Rgb(100, 100, 100), room.translations);
  std::printf("Long animation: the paper-scale room, %zu patches, %zu elements, %zu frames, "
              "N = %llu, k = 1, lambda = 0.25\n",
    scene.patchCount(), scene.elementCount(), frames, static_cast<unsigned long long>(paths));
  std::fflush(stdout);
  const SolverStatistics full = solve(scene, light, optionsFor(scale, paths, true)).statistics;
  const SolverStatistics classic = solve(scene, light, optionsFor(scale, paths, false)).statistics;
  const bench::BareRates bare = bench::measureBareEmbree(scene, light, full.threads, 4000000);

  std::printf("Threads: %d\n%-12s %9s %9s %9s %9s %13s %13s %13s\n", full.threads, "mode",
    "total s", "ms/frame", "shoot s", "gather s", "nearest-hit", "shadow", "gathering");
  for (const auto& [name, s] :
    { std::make_pair("classic", classic), std::make_pair("full reuse", full) })
  {
    std::printf("%-12s %9.2f %9.2f %9.2f %9.2f %13llu %13llu %13llu\n", name, s.secondsTotal,
      1000 * s.secondsTotal / frames, s.secondsShooting, s.secondsGathering,
      static_cast<unsigned long long>(s.shootingRays),
      static_cast<unsigned long long>(s.shadowRays),
      static_cast<unsigned long long>(s.gatheringRays + s.reachabilityRays));
  }
  const double speedup = classic.secondsTotal / full.secondsTotal;
  std::printf("\n");
  const double solverShadowRate = printShadowRays(full, frames, bare);
  std::printf("Full reuse is %.2fx faster than classic over %zu frames (%.1f ms per frame "
              "against %.1f ms). Target: at least 6x: %s\n",
    speedup, frames, 1000 * full.secondsTotal / frames, 1000 * classic.secondsTotal / frames,
    speedup >= 6 ? "met" : "MISSED");

  std::ostringstream out;
  out << "{\"frames\": " << frames << ", \"patches\": " << scene.patchCount()
      << ", \"paths_per_frame\": " << paths << ", \"threads\": " << full.threads
      << ", \"classic_seconds\": " << classic.secondsTotal
      << ", \"full_reuse_seconds\": " << full.secondsTotal << ", \"speedup\": " << speedup
      << ", \"shadow_rays\": " << full.shadowRays
      << ", \"shadow_rays_possible\": " << double(full.firstHits) * double(frames - 1)
      << ", \"shadow_rays_blocked\": " << full.shadowRaysBlocked
      << ", \"solver_shadow_rays_per_second\": " << solverShadowRate
      << ", \"bare_shadow_rays_per_second\": " << bare.shadowRays << "}";
  return out.str();
}

std::string runLargeScene(const ScaleCaseOptions& scale)
{
  constexpr std::size_t frames = 120;
  constexpr std::uint64_t paths = 4000000;
  // The paper room's cell of 0.385 m gives 2,832 patches; 0.0645 m gives about 100,000.
  const scenes::PaperRoom room = scenes::paperScaleRoom(frames, 0.0645);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  const MovingLight light(room.light, Rgb(100, 100, 100), room.translations);
  const SolverOptions options = optionsFor(scale, paths, true);
  const MemoryPlan plan = planSolveMemory(
    scene.patchCount(), scene.elementCount(), scene.points().size(), frames, options);
  const double elementFrames = double(scene.elementCount()) * double(frames);
  std::printf("Large scene: the paper room in %zu patches, %zu elements, %zu frames, N = %llu, "
              "full reuse\n",
    scene.patchCount(), scene.elementCount(), frames, static_cast<unsigned long long>(paths));
  std::printf("Memory bound before reachability (every side): %.2f GiB (%.1f bytes per "
              "element-frame): results %.2f GiB "
              "(16 bits per channel), shooting accumulators %.2f GiB (%s), other %.2f GiB\n",
    double(plan.peak) / GiB, double(plan.peak) / elementFrames, double(plan.results) / GiB,
    double(plan.accumulators) / GiB,
    plan.accumulatorCopyPerWorker ? "a copy per worker" : "one copy shared by the workers",
    double(plan.other) / GiB);
  std::fflush(stdout);

  const std::uint64_t before = statusBytes("VmRSS");
  const bool reset = resetPeakResidentMemory();
  const SolverStatistics s = solve(scene, light, options).statistics;
  const std::uint64_t peak = statusBytes("VmHWM");
  const std::uint64_t solvePeak = peak > before ? peak - before : 0;
  const double ratio = double(solvePeak) / double(s.memoryEstimateBytes);
  std::printf("Reachable patch sides: %llu of %zu (%.1f%%); sides without slots that paths hit "
              "(overflow): %llu. Memory estimate with them: %.2f GiB (%.1f bytes per "
              "element-frame): results written %.2f GiB, shooting accumulators %.2f GiB (%s)\n",
    static_cast<unsigned long long>(s.reachableSides), 2 * scene.patchCount(),
    100.0 * double(s.reachableSides) / double(2 * scene.patchCount()),
    static_cast<unsigned long long>(s.overflowSides), double(s.memoryEstimateBytes) / GiB,
    double(s.memoryEstimateBytes) / elementFrames, double(s.memoryResultBytes) / GiB,
    double(s.memoryAccumulatorBytes) / GiB,
    s.accumulatorCopyPerWorker ? "a copy per worker" : "one copy shared by the workers");
  std::printf("Threads: %d. Solve %.1f s (%.0f ms per frame): shooting %.1f s, gathering %.1f s; "
              "%llu shadow rays, %llu nearest-hit rays, %llu gathering rays\n",
    s.threads, s.secondsTotal, 1000 * s.secondsTotal / frames, s.secondsShooting,
    s.secondsGathering, static_cast<unsigned long long>(s.shadowRays),
    static_cast<unsigned long long>(s.shootingRays),
    static_cast<unsigned long long>(s.gatheringRays));
  std::printf("Resident memory: %.2f GiB before the solve, peak %.2f GiB%s; the solve's own peak "
              "%.2f GiB = %.1f bytes per element-frame, %.2fx its estimate\n",
    double(before) / GiB, double(peak) / GiB, reset ? "" : " (peak of the whole process)",
    double(solvePeak) / GiB, double(solvePeak) / elementFrames, ratio);
  const bench::BareRates bare = bench::measureBareEmbree(scene, light, s.threads, 4000000);
  const double solverShadowRate = printShadowRays(s, frames, bare);
  // Without the reset, VmHWM is the whole process's peak: the solve's own is not measured.
  std::printf("Targets: the process under 16 GiB: %s; the solve's peak within 15%% of the "
              "estimate: %s\n",
    double(peak) < 16 * GiB ? "met" : "MISSED",
    !reset                           ? "not measured (the peak could not be reset)"
      : ratio > 0.85 && ratio < 1.15 ? "met"
                                     : "MISSED");

  std::ostringstream out;
  out << "{\"frames\": " << frames << ", \"patches\": " << scene.patchCount()
      << ", \"elements\": " << scene.elementCount() << ", \"paths_per_frame\": " << paths
      << ", \"threads\": " << s.threads << ", \"seconds\": " << s.secondsTotal
      << ", \"accumulator_copy_per_worker\": " << (s.accumulatorCopyPerWorker ? "true" : "false")
      << ", \"estimate_bytes\": " << s.memoryEstimateBytes
      << ", \"reachable_sides\": " << s.reachableSides
      << ", \"overflow_sides\": " << s.overflowSides << ", \"resident_before_bytes\": " << before
      << ", \"peak_resident_bytes\": " << peak
      << ", \"solve_peak_bytes\": " << (reset ? std::to_string(solvePeak) : std::string("null"))
      << ", \"bytes_per_element_frame\": "
      << (reset ? std::to_string(double(solvePeak) / elementFrames) : std::string("null"))
      << ", \"solver_shadow_rays_per_second\": " << solverShadowRate
      << ", \"bare_shadow_rays_per_second\": " << bare.shadowRays << "}";
  return out.str();
}

} // namespace mlr::bench
