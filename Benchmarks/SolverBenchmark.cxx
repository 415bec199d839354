// mlr-benchmark: the paper's configuration at its scale, solved in all four reuse modes,
// with the measured speed-up beside the paper's eq. (4) and our ray rate beside bare
// Embree's for the same ray kinds; then a turning light and the sun over a town block
// (RigBenchmarks.h). Everything printed is measured in this one run.
#include "AccuracyBenchmarks.h"
#include "AnnualBenchmark.h"
#include "BareEmbree.h"
#include "ChunkBenchmarks.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "RemeshBenchmark.h"
#include "Remeshing.h"
#include "RigBenchmarks.h"
#include "ScaleBenchmarks.h"
#include "Solver.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

using namespace mlr;

namespace
{
struct Arguments
{
  std::uint64_t paths = 600000;
  std::size_t frames = 30;
  bool framesGiven = false; ///< --frames was given (else spotlight takes 60)
  int threads = 0;
  std::string json;
  std::string only;          ///< run just this mode (for profiling)
  std::string which = "all"; ///< --case: all, paper, rotating, spotlight, sun, ...
  int referenceFactor = 16;
  double gatheringRatio = 1; ///< --gathering-ratio for rotating, spotlight and sun
  bool gatheringRatioGiven = false;
  std::string cache = "output/benchmark-cache";
  std::uint64_t memoryLimitMiB = 0; ///< --memory-limit-mib for long and large (0: default)
  bool pathsGiven = false, referenceFactorGiven = false;
  int seeds = 0;                   ///< --seeds for ends and error-bars (0: their default)
  double targetError = 0.02;       ///< --target-error for target-error
  bench::AnnualCaseOptions annual; ///< --weather, --dates, --classic-frames
};

/// The cases of AccuracyBenchmarks.h.
bool isAccuracyCase(const std::string& which)
{
  return which == "ends" || which == "error-bars" || which == "target-error";
}

/// Runs an accuracy case: smaller default N than the others, so that each fits in minutes.
std::string runAccuracyCase(const Arguments& args)
{
  bench::AccuracyCaseOptions o;
  o.paths = args.pathsGiven ? args.paths : 100000;
  o.frames = args.framesGiven ? args.frames : 0;
  o.threads = args.threads;
  o.seeds = args.seeds;
  o.referenceFactor = args.referenceFactorGiven ? args.referenceFactor : 0;
  o.target = args.targetError;
  o.cacheDirectory = args.cache;
  if (args.which == "ends")
  {
    return "  \"ends\": " + bench::runEnds(o);
  }
  if (args.which == "error-bars")
  {
    return "  \"error_bars\": " + bench::runErrorBars(o);
  }
  return "  \"target_error\": " + bench::runTargetError(o);
}

void usage()
{
  std::printf(
    "usage: mlr-benchmark [--case all|paper|rotating|spotlight|sun|long|large|remesh] [--paths N]\n"
    "                     [--frames n] [--threads T] [--json FILE] [--reference-factor F]\n"
    "                     [--cache DIR] [--only classic|gathering|shooting|full]\n"
    "                     [--memory-limit-mib M] [--seeds S] [--target-error T]\n"
    "                     [--gathering-ratio k] [--case ends|error-bars|target-error]\n"
    "  paper:    the generated paper-scale room (about 2,800 patches, a small ceiling light on a\n"
    "            diagonal) in the four reuse modes, compared with bare Embree, and remeshing\n"
    "  rotating: a light turning 90 degrees in the same room\n"
    "  spotlight: a point light with an IES spot panning 90 degrees in the same room, and its\n"
    "            shadow-ray rate beside bare Embree's (about 7 minutes the first time, under 1\n"
    "            minute with its reference cached; not in all)\n"
    "  sun:      a town block of about 3,000 patches under 48 sun positions\n"
    "  remesh:   a 1,004,806-polygon input remeshed to 10,000 and 100,000 patches, and\n"
    "            cancelled at 20 times in each (about 5 minutes, not in all)\n"
    "  all:      paper, rotating and sun in turn (the default)\n"
    "rotating, spotlight and sun compare full reuse with classic, errors against a classic "
    "reference of\n"
    "F x N paths (default 16), cached in DIR (default output/benchmark-cache; '' keeps none),\n"
    "all with k N gathering rays per frame (--gathering-ratio k, 0 < k <= 64, default 1).\n"
    "--frames sets the frames of paper and rotating (30) and spotlight (60); --only profiles one\n"
    "paper mode.\n"
    "  long:     the paper room over 300 frames, classic against full reuse, and where the\n"
    "            shadow rays go; then 300, 1,000 and 3,000 frames in chunks: peak memory,\n"
    "            speed against classic, flicker at the seams (about 4 minutes, not in all)\n"
    "  chunks:   only the chunks part of long\n"
    "  large:    the room in about 100,000 patches, 120 frames, N = 4,000,000, full reuse: time\n"
    "            and peak memory against the estimate (about 3 minutes, not in all); then the\n"
    "            same over 3,000 frames in the chunks a 7 GiB limit chooses, streamed\n"
    "  large-chunks: only that second part of large\n"
    "--memory-limit-mib M sets the solver's memory limit of paper, long and large (default: half "
    "the\n"
    "physical memory; under twice the per-worker peak the workers share one accumulator copy).\n"
    "  ends:     every frame's MSE over classic's at equal N (default 100,000) for the paper "
    "room,\n"
    "            the turning light and the sun, in the end-of-animation schemes (--seeds, 2)\n"
    "  error-bars: the paper room with 16 error batches over --seeds (20) seeds (N 100,000)\n"
    "  target-error: the paper room, 10 frames, to --target-error T (0.02), first round N "
    "100,000\n"
    "  annual:   the town block with about 1,000 work-plane sensors under every daylit hour of a\n"
    "            weather file: full reuse end to end, classic on K frames extrapolated, MSE,\n"
    "            memory (2 minutes, 10 more the first time; not in all); --weather FILE.epw "
    "(default Data/paris_synthetic.epw),\n"
    "            --dates MM-DD,MM-DD (default the whole year), --classic-frames K (default 48)\n");
}

bool parse(int argc, char** argv, Arguments& a)
{
  for (int i = 1; i < argc; ++i)
  {
    const std::string flag = argv[i];
    const bool hasValue = i + 1 < argc;
    if (flag == "--paths" && hasValue)
    {
      a.paths = std::strtoull(argv[++i], nullptr, 10);
      a.pathsGiven = true;
    }
    else if (flag == "--frames" && hasValue)
    {
      a.frames = std::strtoull(argv[++i], nullptr, 10);
      a.framesGiven = true;
    }
    else if (flag == "--threads" && hasValue)
    {
      a.threads = std::atoi(argv[++i]);
    }
    else if (flag == "--json" && hasValue)
    {
      a.json = argv[++i];
    }
    else if (flag == "--only" && hasValue)
    {
      a.only = argv[++i];
    }
    else if (flag == "--case" && hasValue)
    {
      a.which = argv[++i];
      if (a.which != "all" && a.which != "paper" && a.which != "rotating" &&
        a.which != "spotlight" && a.which != "sun" && a.which != "remesh" && a.which != "long" &&
        a.which != "large" && a.which != "chunks" && a.which != "large-chunks" &&
        a.which != "annual" && !isAccuracyCase(a.which))
      {
        std::fprintf(stderr,
          "mlr-benchmark: --case must be all, paper, rotating, spotlight, sun, "
          "remesh, long, chunks, large, large-chunks, ends, error-bars, target-error or "
          "annual\n");
        return false;
      }
    }
    else if (flag == "--reference-factor" && hasValue)
    {
      a.referenceFactor = std::atoi(argv[++i]);
      a.referenceFactorGiven = true;
    }
    else if (flag == "--gathering-ratio" && hasValue)
    {
      const char* text = argv[++i];
      char* end = nullptr;
      a.gatheringRatio = std::strtod(text, &end);
      if (end == text || *end != '\0' || !(a.gatheringRatio > 0 && a.gatheringRatio <= 64))
      {
        std::fprintf(stderr, "mlr-benchmark: --gathering-ratio must be above 0 and at most 64\n");
        return false;
      }
      a.gatheringRatioGiven = true;
    }
    else if (flag == "--memory-limit-mib" && hasValue)
    {
      a.memoryLimitMiB = std::strtoull(argv[++i], nullptr, 10);
    }
    else if (flag == "--seeds" && hasValue)
    {
      a.seeds = std::atoi(argv[++i]);
    }
    else if (flag == "--target-error" && hasValue)
    {
      a.targetError = std::atof(argv[++i]);
    }
    else if (flag == "--weather" && hasValue)
    {
      a.annual.weather = argv[++i];
    }
    else if (flag == "--dates" && hasValue)
    {
      a.annual.dates = argv[++i];
    }
    else if (flag == "--classic-frames" && hasValue)
    {
      a.annual.classicFrames = std::strtoull(argv[++i], nullptr, 10);
    }
    else if (flag == "--cache" && hasValue)
    {
      a.cache = argv[++i];
    }
    else
    {
      usage();
      return flag == "--help";
    }
  }
  if (a.gatheringRatioGiven && a.which != "rotating" && a.which != "spotlight" &&
    a.which != "sun" && a.which != "all")
  {
    std::fprintf(stderr,
      "mlr-benchmark: --gathering-ratio applies to --case rotating, spotlight and sun (and to "
      "all, for its rotating and sun parts); --case %s keeps k = 1\n",
      a.which.c_str());
    return false;
  }
  return true;
}

/// Median remeshing seconds of `repeats` runs, with the last run's statistics.
RemeshStatistics timeRemeshing(
  const PolygonSoup& soup, std::size_t patches, int repeats, double& median)
{
  RemeshOptions options;
  options.targetPatchCount = patches;
  std::vector<double> seconds;
  RemeshStatistics last;
  for (int r = 0; r < repeats; ++r)
  {
    last = remesh(soup, options).statistics;
    seconds.push_back(last.seconds);
  }
  std::sort(seconds.begin(), seconds.end());
  median = seconds[seconds.size() / 2];
  return last;
}

struct ModeResult
{
  const char* name;
  bool reuseShooting, reuseGathering;
  SolverStatistics stats;
  double bareSeconds = 0;
  int repeats = 1;
};

/// The paper's configuration in the four modes, bare Embree and remeshing. Returns the
/// JSON keys of the results (empty when profiling one mode with --only).
std::string runPaperCase(const Arguments& args)
{
  const scenes::PaperRoom room = scenes::paperScaleRoom(args.frames);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  const MovingLight light(room.light, Rgb(100, 100, 100), room.translations);
  SolverOptions options;
  options.pathsPerFrame = args.paths;
  options.threads = args.threads;
  options.gatheringRatio = 1;
  options.firstBounceSurvival = 0.25;
  options.memoryLimitBytes = args.memoryLimitMiB << 20;

  std::printf("Paper-scale room: %zu patches, %zu elements, %zu frames, N = %llu effective "
              "paths per frame, k = %g, lambda = %g\n",
    scene.patchCount(), scene.elementCount(), light.frameCount(),
    static_cast<unsigned long long>(options.pathsPerFrame), options.gatheringRatio,
    options.firstBounceSurvival);

  std::vector<ModeResult> modes = { { "classic", false, false, {} },
    { "gathering reuse", false, true, {} }, { "shooting reuse", true, false, {} },
    { "full reuse", true, true, {} } };
  if (!args.only.empty())
  {
    // Profiling: one mode, no comparison.
    SolverOptions o = options;
    o.reuseShooting = args.only == "shooting" || args.only == "full";
    o.reuseGathering = args.only == "gathering" || args.only == "full";
    const SolverStatistics s = solve(scene, light, o).statistics;
    std::printf("%s: %.3f s (shooting %.3f s, gathering %.3f s)\n", args.only.c_str(),
      s.secondsTotal, s.secondsShooting, s.secondsGathering);
    return {};
  }
  for (ModeResult& m : modes)
  {
    SolverOptions o = options;
    o.reuseShooting = m.reuseShooting;
    o.reuseGathering = m.reuseGathering;
    // A solve under a few seconds is at the mercy of the machine's hiccups: take the
    // median of three (the rays, and the result, are the same every time).
    std::vector<SolverStatistics> runs = { solve(scene, light, o).statistics };
    if (runs[0].secondsTotal < 3.0)
    {
      runs.push_back(solve(scene, light, o).statistics);
      runs.push_back(solve(scene, light, o).statistics);
      std::sort(runs.begin(), runs.end(),
        [](const SolverStatistics& a, const SolverStatistics& b)
        { return a.secondsTotal < b.secondsTotal; });
    }
    m.stats = runs[runs.size() / 2];
    m.repeats = static_cast<int>(runs.size());
  }
  const int threads = modes[0].stats.threads;
  const bench::BareRates bare = bench::measureBareEmbree(scene, light, threads, 4000000);

  std::printf("Threads: %d\n\n", threads);
  std::printf("%-16s %9s %9s %9s %12s %12s %12s %10s %9s\n", "mode", "total s", "shoot s",
    "gather s", "nearest-hit", "shadow", "gathering", "Mrays/s", "vs bare");
  for (ModeResult& m : modes)
  {
    const SolverStatistics& s = m.stats;
    // Bare Embree's time for this mode's rays: light rays are one per path, the rest of
    // the nearest-hit rays leave surfaces. The reachability probes run before shooting, in
    // neither phase's seconds, so neither side counts them.
    const double lightRays = double(s.pathsCast);
    const double surfaceRays = double(s.shootingRays) - lightRays + double(s.gatheringRays);
    m.bareSeconds = lightRays / bare.lightRays + surfaceRays / bare.surfaceRays +
      double(s.shadowRays) / bare.shadowRays;
    const double traced = s.secondsShooting + s.secondsGathering;
    const double rays = double(s.shootingRays + s.shadowRays + s.gatheringRays);
    std::printf("%-16s %9.2f %9.2f %9.2f %12llu %12llu %12llu %10.1f %8.2fx\n", m.name,
      s.secondsTotal, s.secondsShooting, s.secondsGathering,
      static_cast<unsigned long long>(s.shootingRays),
      static_cast<unsigned long long>(s.shadowRays),
      static_cast<unsigned long long>(s.gatheringRays), rays / traced / 1e6,
      traced / m.bareSeconds);
  }
  const SolverStatistics& classic = modes[0].stats;
  const SolverStatistics& full = modes[3].stats;
  const double measured = classic.secondsTotal / full.secondsTotal;
  const double predicted = predictedSpeedup(light.frameCount(), options.gatheringRatio,
    options.firstBounceSurvival, classic.meanPathLength);
  std::printf("\nBare Embree on the same scene (%d threads): %.1f M light rays/s, %.1f M "
              "surface rays/s (rtcIntersect1), %.1f M shadow rays/s (rtcOccluded16)\n",
    threads, bare.lightRays / 1e6, bare.surfaceRays / 1e6, bare.shadowRays / 1e6);
  std::printf("'vs bare' = solver seconds (shooting + gathering) / bare Embree seconds for "
              "the same rays of the same kinds.\nModes under 3 s show the median of 3 runs.\n");
  std::printf("Memory estimate of full reuse: %.1f bytes per element-frame (%s); %llu of %zu "
              "patch sides reachable, %llu sides without slots hit (overflow)\n",
    double(full.memoryEstimateBytes) / (double(scene.elementCount()) * double(light.frameCount())),
    full.accumulatorCopyPerWorker ? "a copy of the accumulators per worker" : "one shared copy",
    static_cast<unsigned long long>(full.reachableSides), 2 * scene.patchCount(),
    static_cast<unsigned long long>(full.overflowSides));
  std::printf("Mean path length l = %.3f (from classic: shooting rays per path = 1 + "
              "lambda (l - 1))\n",
    classic.meanPathLength);
  std::printf("Speed-up of full reuse over classic: measured %.2fx; paper eq. (4) predicts "
              "%.2fx in ray casts (it counts a shadow ray as a nearest hit)\n",
    measured, predicted);
  std::printf("Targets: full reuse >= 6x faster than classic: %s; solver within 1.5x of bare "
              "Embree (full reuse): %s; full-reuse solve under 3 s: %s\n",
    measured >= 6 ? "met" : "MISSED",
    modes[3].stats.secondsShooting + modes[3].stats.secondsGathering <= 1.5 * modes[3].bareSeconds
      ? "met"
      : "MISSED",
    full.secondsTotal < 3 ? "met" : "MISSED");

  // Remeshing beside the solve: the paper room given as 16 big quads, and a finely
  // tessellated 200,000-triangle input.
  double roomSeconds = 0, sphereSeconds = 0;
  const RemeshStatistics roomMesh = timeRemeshing(scenes::paperRoomOfQuads(), 2700, 5, roomSeconds);
  const RemeshStatistics sphereMesh = timeRemeshing(scenes::icosphere(100), 3000, 3, sphereSeconds);
  std::printf(
    "\nRemeshing (CGAL, median): paper room %zu quads -> %zu patches in %.3f s (%.1f%% of "
    "the full-reuse solve); 200,000-triangle sphere -> %zu patches in %.2f s\n",
    roomMesh.inputPolygons, roomMesh.patches, roomSeconds, 100 * roomSeconds / full.secondsTotal,
    sphereMesh.patches, sphereSeconds);
  std::printf("Target: remeshing the paper room under 25%% of the full-reuse solve: %s\n",
    roomSeconds < 0.25 * full.secondsTotal ? "met" : "MISSED");

  std::ostringstream out;
  out << "  \"patches\": " << scene.patchCount() << ",\n  \"elements\": " << scene.elementCount()
      << ",\n  \"frames\": " << light.frameCount()
      << ",\n  \"paths_per_frame\": " << options.pathsPerFrame << ",\n  \"threads\": " << threads
      << ",\n  \"mean_path_length\": " << classic.meanPathLength
      << ",\n  \"remesh_room_seconds\": " << roomSeconds
      << ",\n  \"remesh_200k_seconds\": " << sphereSeconds
      << ",\n  \"speedup_measured\": " << measured << ",\n  \"speedup_eq4\": " << predicted
      << ",\n  \"bare_rays_per_second\": {\"light\": " << bare.lightRays
      << ", \"surface\": " << bare.surfaceRays << ", \"shadow\": " << bare.shadowRays
      << "},\n  \"modes\": [\n";
  for (std::size_t i = 0; i < modes.size(); ++i)
  {
    const SolverStatistics& s = modes[i].stats;
    out << "    {\"name\": \"" << modes[i].name << "\", \"seconds\": " << s.secondsTotal
        << ", \"seconds_shooting\": " << s.secondsShooting
        << ", \"seconds_gathering\": " << s.secondsGathering
        << ", \"nearest_hit_rays\": " << s.shootingRays << ", \"shadow_rays\": " << s.shadowRays
        << ", \"gathering_rays\": " << s.gatheringRays
        << ", \"bare_embree_seconds\": " << modes[i].bareSeconds << "}"
        << (i + 1 < modes.size() ? ",\n" : "\n");
  }
  out << "  ]";
  return out.str();
}
} // namespace

int main(int argc, char** argv)
{
  Arguments args;
  if (!parse(argc, argv, args))
  {
    return 2;
  }
  if (argc > 1 && std::strcmp(argv[1], "--help") == 0)
  {
    return 0;
  }
  try
  {
    std::vector<std::string> json;
    if (args.which == "all" || args.which == "paper" || !args.only.empty())
    {
      const std::string paper = runPaperCase(args);
      if (!args.only.empty())
      {
        return 0;
      }
      json.push_back(paper);
    }
    bench::RigCaseOptions rigOptions;
    rigOptions.paths = args.paths;
    rigOptions.frames = args.frames;
    rigOptions.threads = args.threads;
    rigOptions.referenceFactor = args.referenceFactor;
    rigOptions.gatheringRatio = args.gatheringRatio;
    rigOptions.cacheDirectory = args.cache;
    if (args.which == "all" || args.which == "rotating")
    {
      json.push_back("  \"turning_light\": " + bench::runTurningLight(rigOptions));
    }
    if (args.which == "spotlight")
    {
      bench::RigCaseOptions spotOptions = rigOptions;
      spotOptions.frames = args.framesGiven ? args.frames : 60;
      json.push_back("  \"panning_spot\": " + bench::runPanningSpot(spotOptions));
    }
    if (args.which == "all" || args.which == "sun")
    {
      json.push_back("  \"sun_over_town\": " + bench::runSunOverTown(rigOptions));
    }
    if (isAccuracyCase(args.which))
    {
      json.push_back(runAccuracyCase(args));
    }
    if (args.which == "remesh")
    {
      json.push_back("  \"remesh_large\": " + bench::runRemeshing(bench::RemeshCaseOptions{}));
    }
    bench::ScaleCaseOptions scaleOptions;
    scaleOptions.threads = args.threads;
    scaleOptions.memoryLimitBytes = args.memoryLimitMiB << 20;
    if (args.which == "long")
    {
      json.push_back("  \"long_animation\": " + bench::runLongAnimation(scaleOptions));
      json.push_back("  \"chunks\": " + bench::runChunkedAnimation(scaleOptions));
    }
    if (args.which == "chunks")
    {
      json.push_back("  \"chunks\": " + bench::runChunkedAnimation(scaleOptions));
    }
    if (args.which == "large")
    {
      json.push_back("  \"large_scene\": " + bench::runLargeScene(scaleOptions));
      json.push_back("  \"large_chunks\": " + bench::runLargeChunked(scaleOptions));
    }
    if (args.which == "large-chunks")
    {
      json.push_back("  \"large_chunks\": " + bench::runLargeChunked(scaleOptions));
    }
    if (args.which == "annual")
    {
      bench::AnnualCaseOptions annual = args.annual;
      annual.paths = args.paths;
      annual.threads = args.threads;
      annual.referenceFactor = args.referenceFactor;
      annual.cacheDirectory = args.cache;
      json.push_back("  \"annual\": " + bench::runAnnual(annual));
    }
    if (!args.json.empty())
    {
      std::ofstream out(args.json);
      out << "{\n";
      for (std::size_t i = 0; i < json.size(); ++i)
      {
        out << json[i] << (i + 1 < json.size() ? ",\n" : "\n");
      }
      out << "}\n";
      if (!out)
      {
        std::fprintf(stderr, "mlr-benchmark: cannot write %s\n", args.json.c_str());
        return 1;
      }
    }
  }
  catch (const Error& e)
  {
    std::fprintf(stderr, "mlr-benchmark: %s\n", e.what());
    return 1;
  }
  return 0;
}
