#include "ChunkBenchmarks.h"

#include "Chunks.h"
#include "GeneratedScenes.h"
#include "MemoryPlan.h"
#include "ProcessMeasures.h"
#include "Solver.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <malloc.h>
#include <sstream>
#include <string>
#include <vector>

namespace mlr::bench
{
namespace
{
constexpr double MiB = 1024.0 * 1024.0;
constexpr std::uint64_t Paths = 600000;

SolverOptions optionsFor(const ScaleCaseOptions& scale, bool reuse, std::uint64_t seed = 0)
{
  SolverOptions o;
  o.pathsPerFrame = Paths;
  o.threads = scale.threads;
  o.memoryLimitBytes = scale.memoryLimitBytes;
  o.reuseShooting = reuse;
  o.reuseGathering = reuse;
  o.seed = seed;
  return o;
}

struct Room
{
  Scene scene;
  LightRig rig;
};

Room room(std::size_t frames)
{
  const scenes::PaperRoom r = scenes::paperScaleRoom(frames);
  Room out{ Scene::fromPatchMesh(r.mesh), {} };
  out.rig.areaLights.emplace_back(r.light, Rgb(100, 100, 100), r.translations);
  return out;
}

/// Every frame's total radiosity (lit side, sum over channels) of every element, streamed.
std::vector<std::vector<float>> framesOf(
  const Room& r, const SolverOptions& o, std::size_t framesPerChunk)
{
  std::vector<std::vector<float>> frames;
  solveInChunks(r.scene, r.rig, o, framesPerChunk, {},
    [&](std::size_t, Solution& s)
    {
      for (std::size_t f = 0; f < s.frameCount(); ++f)
      {
        std::vector<float> b(s.elementCount());
        for (std::size_t e = 0; e < s.elementCount(); ++e)
        {
          b[e] = static_cast<float>(s.total(f, e, s.litSide(e)).sum());
        }
        frames.push_back(std::move(b));
      }
    });
  return frames;
}

/// The RMS error of the change from frame f to f + 1, from two independent estimates a, b.
double flicker(
  const std::vector<std::vector<float>>& a, const std::vector<std::vector<float>>& b, std::size_t f)
{
  double sum = 0;
  for (std::size_t e = 0; e < a[f].size(); ++e)
  {
    const double d = (double(a[f + 1][e]) - a[f][e]) - (double(b[f + 1][e]) - b[f][e]);
    sum += d * d;
  }
  return std::sqrt(sum / (2.0 * double(a[f].size())));
}
}

std::string runChunkedAnimation(const ScaleCaseOptions& scale)
{
  constexpr std::size_t framesPerChunk = 100;
  std::printf("\nLong animations in chunks of %zu frames (overlap %zu), streamed, N = %llu, "
              "full reuse\n%8s %7s %9s %9s %9s %9s %12s %12s %14s\n",
    framesPerChunk, chunkOverlap(framesPerChunk), static_cast<unsigned long long>(Paths), "frames",
    "chunks", "total s", "ms/frame", "shoot s", "gather s", "solve MiB", "process MiB",
    "estimate MiB");
  std::fflush(stdout);
  std::ostringstream json;
  json << "{\"frames_per_chunk\": " << framesPerChunk << ", \"runs\": [";
  double seconds3000 = 0;
  int threads = 0;
  for (const std::size_t frames : { 300, 1000, 3000 })
  {
    const Room r = room(frames);
    const SolverOptions o = optionsFor(scale, true);
    // The memory freed by the run before goes back to the system first, so that the peak of
    // the process is this run's.
    malloc_trim(0);
    const std::uint64_t before = statusBytes("VmRSS");
    resetPeakResidentMemory();
    const SolverStatistics s = solveInChunks(r.scene, r.rig, o, framesPerChunk, {},
      [](std::size_t, Solution&) {
      }).statistics;
    const std::uint64_t peak = statusBytes("VmHWM");
    const std::uint64_t solvePeak = peak > before ? peak - before : 0;
    const std::uint64_t estimate = estimateChunkedMemory(r.scene.patchCount(),
      r.scene.elementCount(), r.scene.points().size(), frames, framesPerChunk, o, 1, 0, true);
    std::printf("%8zu %7llu %9.2f %9.2f %9.2f %9.2f %12.1f %12.1f %14.1f\n", frames,
      static_cast<unsigned long long>(s.chunks), s.secondsTotal, 1000 * s.secondsTotal / frames,
      s.secondsShooting, s.secondsGathering, double(solvePeak) / MiB, double(peak) / MiB,
      double(estimate) / MiB);
    std::fflush(stdout);
    json << (frames == 300 ? "" : ", ") << "{\"frames\": " << frames << ", \"chunks\": " << s.chunks
         << ", \"seconds\": " << s.secondsTotal << ", \"peak_bytes\": " << solvePeak
         << ", \"estimate_bytes\": " << estimate << "}";
    if (frames == 3000)
    {
      seconds3000 = s.secondsTotal;
    }
    threads = s.threads;
  }

  // Classic solves every frame alone: timed over 100 frames, per frame.
  constexpr std::size_t classicFrames = 100;
  const Room c = room(classicFrames);
  const double classicSeconds =
    solve(c.scene, c.rig, optionsFor(scale, false)).statistics.secondsTotal;
  const double classicPerFrame = classicSeconds / classicFrames;
  const double ratio = classicPerFrame * 3000 / seconds3000;
  std::printf("Classic: %.1f ms per frame (%zu frames in %.2f s), %.0f s for 3,000 frames. "
              "Chunked full reuse over 3,000 frames: %.2f s, %.1fx faster. Target: at least "
              "15x: %s. Threads: %d\n",
    1000 * classicPerFrame, classicFrames, classicSeconds, classicPerFrame * 3000, seconds3000,
    ratio, ratio >= 15 ? "met" : "MISSED", threads);
  std::fflush(stdout);

  // Flicker: 300 frames in chunks of 30, two seeds, and one chunk beside it; the default
  // overlap (C/8 = 3) and longer ones, which blend each seam over more frames.
  constexpr std::size_t seamFrames = 300, seamChunk = 30;
  const Room f = room(seamFrames);
  auto timedFrames = [&](
                       std::uint64_t seed, std::size_t perChunk, std::uint64_t overlap, double& cpu)
  {
    SolverOptions o = optionsFor(scale, true, seed);
    o.chunkOverlap = overlap;
    const double before = processCpuSeconds();
    auto frames = framesOf(f, o, perChunk);
    cpu += processCpuSeconds() - before;
    return frames;
  };
  double wholeCpu = 0;
  const auto wa = timedFrames(1, 0, 0, wholeCpu);
  const auto wb = timedFrames(2, 0, 0, wholeCpu);
  // Away from the animation's ends, as the seams are.
  auto away = [&](std::size_t t) { return t >= seamChunk && t + 1 + seamChunk < seamFrames; };
  double whole = 0, wholeAway = 0, wholeVariance = 0;
  std::size_t changesAway = 0;
  for (std::size_t t = 0; t + 1 < seamFrames; ++t)
  {
    const double ew = flicker(wa, wb, t);
    whole += ew * ew;
    if (away(t))
    {
      wholeAway += ew * ew;
      ++changesAway;
    }
  }
  whole = std::sqrt(whole / double(seamFrames - 1));
  wholeAway = std::sqrt(wholeAway / double(changesAway));
  /// A frame's variance, from the two seeds: the mean over elements of (a - b)^2 / 2.
  auto variance =
    [&](const std::vector<std::vector<float>>& a, const std::vector<std::vector<float>>& b)
  {
    double sum = 0;
    std::size_t count = 0;
    for (std::size_t t = seamChunk; t + seamChunk < seamFrames; ++t)
    {
      for (std::size_t e = 0; e < a[t].size(); ++e)
      {
        const double d = double(a[t][e]) - b[t][e];
        sum += d * d / 2;
        ++count;
      }
    }
    return sum / double(count);
  };
  wholeVariance = variance(wa, wb);
  std::printf("Flicker (RMS error of the frame-to-frame change, W/m^2, two seeds), %zu frames in "
              "chunks of %zu; one solve of the %zu frames: %.4f (%.4f away from the ends), "
              "%.1f CPU s for the two seeds\n"
              "%8s %9s %9s %9s %10s %14s %12s %10s\n",
    seamFrames, seamChunk, seamFrames, whole, wholeAway, wholeCpu, "overlap", "at seams", "inside",
    "ratio", "all/one", "variance/one", "CPU s", "target");
  double seam = 0, inside = 0;
  json << "], \"flicker_one_chunk\": " << whole << ", \"overlaps\": [";
  for (const std::uint64_t asked : { 0, 7, 15 })
  {
    const ChunkPlan plan = planChunks(seamFrames, seamChunk, asked);
    double cpu = 0;
    const auto a = timedFrames(1, seamChunk, asked, cpu);
    const auto b = timedFrames(2, seamChunk, asked, cpu);
    // A change is at a seam when either of its frames is a blend of two chunks.
    auto blended = [&](std::size_t frame)
    {
      for (std::size_t k = 0; k < plan.chunks.size(); ++k)
      {
        const double w = plan.weight(k, frame);
        if (w > 0 && w < 1)
        {
          return true;
        }
      }
      return false;
    };
    double atSeams = 0, within = 0, all = 0;
    std::size_t seams = 0, insides = 0;
    for (std::size_t t = 0; t + 1 < seamFrames; ++t)
    {
      if (!away(t))
      {
        continue;
      }
      const double e = flicker(a, b, t);
      all += e * e;
      if (blended(t) || blended(t + 1))
      {
        atSeams += e * e;
        ++seams;
      }
      else
      {
        within += e * e;
        ++insides;
      }
    }
    atSeams = std::sqrt(atSeams / double(seams));
    within = insides > 0 ? std::sqrt(within / double(insides)) : 0.0;
    all = std::sqrt(all / double(changesAway));
    const double ratio = within > 0 ? atSeams / within : 0.0;
    char withinText[32] = "none", ratioText[32] = "-";
    if (insides > 0)
    {
      std::snprintf(withinText, sizeof withinText, "%.4f", within);
      std::snprintf(ratioText, sizeof ratioText, "%.2f", ratio);
    }
    std::printf("%8zu %9.4f %9s %9s %10.2f %14.3f %12.1f %10s\n", plan.overlap, atSeams, withinText,
      ratioText, all / wholeAway, variance(a, b) / wholeVariance, cpu,
      insides == 0 ? "no inside" : (ratio <= 1.1 ? "met" : "MISSED"));
    std::fflush(stdout);
    if (asked == 0)
    {
      seam = atSeams;
      inside = within;
    }
    json << (asked == 0 ? "" : ", ") << "{\"overlap\": " << plan.overlap
         << ", \"flicker_seam\": " << atSeams << ", \"flicker_inside\": " << within
         << ", \"flicker_over_one_solve\": " << all / wholeAway << ", \"cpu_seconds\": " << cpu
         << "}";
  }
  std::printf("Target: flicker at the seams within 1.1x of inside the chunks; all/one: the "
              "flicker of every change away from the ends over one solve's; variance/one: a "
              "frame's variance over one solve's (the MSE's Monte Carlo part).\n");

  json << "], \"classic_seconds_per_frame\": " << classicPerFrame << ", \"speedup_3000\": " << ratio
       << ", \"flicker_seam\": " << seam << ", \"flicker_inside\": " << inside << "}";
  return json.str();
}

std::string runLargeChunked(const ScaleCaseOptions& scale)
{
  constexpr std::size_t frames = 3000;
  constexpr std::uint64_t paths = 4000000;
  const scenes::PaperRoom r = scenes::paperScaleRoom(frames, 0.0645);
  Room large{ Scene::fromPatchMesh(r.mesh), {} };
  large.rig.areaLights.emplace_back(r.light, Rgb(100, 100, 100), r.translations);
  SolverOptions o = optionsFor(scale, true);
  o.pathsPerFrame = paths;
  if (o.memoryLimitBytes == 0)
  {
    // 7 GiB for the solve, so that the process, the scene beside it, stays within 8 GB
    // (7.45 GiB).
    o.memoryLimitBytes = std::uint64_t(7) << 30;
  }
  const Scene& scene = large.scene;
  // As solveAnimation does: the chunks' length from the sides light reaches, probed once.
  const SolveSetup setup(scene, large.rig, o);
  const std::size_t bound = chooseFramesPerChunk(
    scene.patchCount(), scene.elementCount(), scene.points().size(), frames, o, 1, 0, true);
  const std::size_t c = chooseFramesPerChunk(scene.patchCount(), scene.elementCount(),
    scene.points().size(), frames, o, 1, 0, true, 0, &setup.reachable(), &setup.firstHits());
  const std::uint64_t estimate = estimateChunkedMemory(scene.patchCount(), scene.elementCount(),
    scene.points().size(), frames, c, o, 1, 0, true, 0, &setup.reachable(), &setup.firstHits());
  std::printf("\nThe large scene over %zu frames: %zu patches, %zu elements, N = %llu, full "
              "reuse, streamed in chunks of %zu (overlap %zu) that a %.1f GiB limit chooses "
              "for the sides light reaches (%zu for every side); estimate %.2f GiB\n",
    frames, scene.patchCount(), scene.elementCount(), static_cast<unsigned long long>(paths), c,
    chunkOverlap(c), double(o.memoryLimitBytes) / (1024 * MiB), bound,
    double(estimate) / (1024 * MiB));
  std::fflush(stdout);
  malloc_trim(0);
  const std::uint64_t before = statusBytes("VmRSS");
  resetPeakResidentMemory();
  std::size_t streamed = 0;
  const SolverStatistics s = solveInChunks(
    scene, large.rig, o, c, {}, [&](std::size_t, Solution& f) { streamed += f.frameCount(); }, {},
    &setup)
                               .statistics;
  const std::uint64_t peak = statusBytes("VmHWM");
  const std::uint64_t solvePeak = peak > before ? peak - before : 0;
  std::printf("%llu chunks, %zu frames streamed in %.1f s (%.0f ms per frame, %d threads); peak "
              "of the solve %.2f GiB (%.2fx the estimate), of the process %.2f GiB. Target: "
              "within 8 GB: %s\n",
    static_cast<unsigned long long>(s.chunks), streamed, s.secondsTotal,
    1000 * s.secondsTotal / frames, s.threads, double(solvePeak) / (1024 * MiB),
    double(solvePeak) / double(estimate), double(peak) / (1024 * MiB),
    double(peak) <= 8e9 ? "met" : "MISSED");
  std::fflush(stdout);
  std::ostringstream json;
  json << "{\"frames\": " << frames << ", \"patches\": " << scene.patchCount()
       << ", \"elements\": " << scene.elementCount() << ", \"frames_per_chunk\": " << c
       << ", \"chunks\": " << s.chunks << ", \"seconds\": " << s.secondsTotal
       << ", \"peak_bytes\": " << peak << ", \"solve_peak_bytes\": " << solvePeak
       << ", \"estimate_bytes\": " << estimate << "}";
  return json.str();
}

} // namespace mlr::bench
