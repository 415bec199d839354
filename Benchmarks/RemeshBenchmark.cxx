#include "RemeshBenchmark.h"

#include "Error.h"
#include "GeneratedScenes.h"
#include "Remeshing.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <sstream>
#include <thread>
#include <vector>

namespace mlr::bench
{
namespace
{
using Clock = std::chrono::steady_clock;

/// Cancellation must reach the caller within this many seconds.
constexpr double LatencyTarget = 0.5;

double secondsBetween(Clock::time_point a, Clock::time_point b)
{
  return std::chrono::duration<double>(b - a).count();
}

/// FNV-1a over the patches' bits: equal before and after a change means the same patches.
std::uint64_t patchHash(const PatchMesh& mesh)
{
  std::uint64_t hash = 14695981039346656037ULL;
  auto bytes = [&hash](const void* data, std::size_t size)
  {
    const auto* p = static_cast<const unsigned char*>(data);
    for (std::size_t i = 0; i < size; ++i)
    {
      hash = (hash ^ p[i]) * 1099511628211ULL;
    }
  };
  bytes(mesh.points.data(), mesh.points.size() * sizeof(Vec3));
  bytes(mesh.triangles.data(), mesh.triangles.size() * sizeof(Triangle));
  bytes(mesh.reflectance.data(), mesh.reflectance.size() * sizeof(Rgb));
  return hash;
}

/// A gap between two calls of the progress callback, with the fractions reported at its ends
/// (they tell the phase: 0 while triangulating and repairing, 0.0475 while splitting at
/// contacts, then rising with the faces remeshed).
struct Gap
{
  double seconds = 0;
  double at = 0; ///< seconds into the run where it starts
  double fromFraction = 0, toFraction = 0;
};

struct PlainRun
{
  RemeshStatistics statistics;
  std::uint64_t hash = 0;
  std::size_t calls = 0;
  std::vector<Gap> longestGaps; ///< longest first
};

PlainRun runWithoutCancelling(const PolygonSoup& soup, const RemeshOptions& options)
{
  std::vector<std::pair<Clock::time_point, double>> calls;
  calls.reserve(1 << 16);
  const Clock::time_point start = Clock::now();
  calls.emplace_back(start, 0.0);
  const RemeshResult result = remesh(soup, options,
    [&calls](double f)
    {
      calls.emplace_back(Clock::now(), f);
      return true;
    });
  calls.emplace_back(Clock::now(), 1.0);
  PlainRun run;
  run.statistics = result.statistics;
  run.hash = patchHash(result.mesh);
  run.calls = calls.size() - 2;
  for (std::size_t i = 1; i < calls.size(); ++i)
  {
    run.longestGaps.push_back({ secondsBetween(calls[i - 1].first, calls[i].first),
      secondsBetween(start, calls[i - 1].first), calls[i - 1].second, calls[i].second });
  }
  std::sort(run.longestGaps.begin(), run.longestGaps.end(),
    [](const Gap& a, const Gap& b) { return a.seconds > b.seconds; });
  run.longestGaps.resize(std::min<std::size_t>(run.longestGaps.size(), 5));
  return run;
}

struct CancelRun
{
  double requestedAt = 0; ///< seconds into the run
  double latency = 0;     ///< from the request to mlr::Cancelled caught by the caller
  double unwinding = 0;   ///< of which from the callback saying stop to the catch
  double fraction = 0;    ///< the progress reported when the callback said stop
  bool cancelled = false; ///< false: the run ended before the request was seen
};

/// Remeshes in a thread of its own and asks it to stop `after` seconds in.
CancelRun cancelAfter(const PolygonSoup& soup, const RemeshOptions& options, double after)
{
  std::atomic<bool> stop{ false };
  CancelRun run;
  Clock::time_point seen, ended;
  const Clock::time_point start = Clock::now();
  std::thread worker(
    [&]
    {
      try
      {
        remesh(soup, options,
          [&stop, &seen, &run](double f)
          {
            if (!stop.load(std::memory_order_relaxed))
            {
              return true;
            }
            seen = Clock::now();
            run.fraction = f;
            return false;
          });
      }
      catch (const Cancelled&)
      {
        run.cancelled = true;
      }
      ended = Clock::now();
    });
  std::this_thread::sleep_until(
    start + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(after)));
  const Clock::time_point requested = Clock::now();
  stop = true;
  worker.join();
  run.requestedAt = secondsBetween(start, requested);
  run.latency = secondsBetween(requested, ended);
  run.unwinding = run.cancelled ? secondsBetween(seen, ended) : 0;
  return run;
}

double median(std::vector<double> values)
{
  if (values.empty())
  {
    return 0;
  }
  std::sort(values.begin(), values.end());
  return values[values.size() / 2];
}
} // namespace

std::string runRemeshing(const RemeshCaseOptions& options)
{
  const Clock::time_point generating = Clock::now();
  const PolygonSoup soup =
    scenes::sphereAndBoxOnTiledFloor(options.floorCells, options.sphereFrequency);
  std::printf("Remeshing a large input: a floor of %d x %d squares, a sphere of %d x %d x 20 "
              "triangles through it and a box standing on it: %zu polygons, %zu points "
              "(generated in %.1f s)\n",
    options.floorCells, options.floorCells, options.sphereFrequency, options.sphereFrequency,
    soup.polygons.size(), soup.points.size(), secondsBetween(generating, Clock::now()));

  std::ostringstream json;
  json << "{\"input_triangles\": " << soup.polygons.size() << ", \"cases\": [";
  bool allMet = true;
  for (std::size_t c = 0; c < options.patchCounts.size(); ++c)
  {
    RemeshOptions remeshOptions;
    remeshOptions.targetPatchCount = options.patchCounts[c];
    const PlainRun plain = runWithoutCancelling(soup, remeshOptions);
    const RemeshStatistics& s = plain.statistics;
    std::printf("\nTarget %zu patches: %zu patches in %.2f s (of which contacts %.2f s: %zu "
                "triangles split, %zu covered), %zu regions, %zu refined only; patch hash "
                "%016llx\n",
      options.patchCounts[c], s.patches, s.seconds, s.secondsContacts, s.contactSplitTriangles,
      s.coveredTriangles, s.regions, s.fallbackRegions,
      static_cast<unsigned long long>(plain.hash));
    std::printf("  progress callback: %zu calls; longest gaps between calls:", plain.calls);
    for (const Gap& g : plain.longestGaps)
    {
      std::printf(" %.3f s at %.2f s (fraction %.4f -> %.4f);", g.seconds, g.at, g.fromFraction,
        g.toFraction);
    }
    std::printf("\n");

    std::vector<CancelRun> runs;
    std::vector<double> latencies, unwindings;
    for (int k = 0; k < options.cancelPoints; ++k)
    {
      // Deterministic request times, evenly spread over the uncancelled run.
      const double after = s.seconds * (k + 0.5) / options.cancelPoints;
      runs.push_back(cancelAfter(soup, remeshOptions, after));
      if (runs.back().cancelled)
      {
        latencies.push_back(runs.back().latency);
        unwindings.push_back(runs.back().unwinding);
      }
    }
    const auto worst = std::max_element(runs.begin(), runs.end(),
      [](const CancelRun& a, const CancelRun& b)
      { return (a.cancelled ? a.latency : 0) < (b.cancelled ? b.latency : 0); });
    const double maxLatency =
      latencies.empty() ? 0 : *std::max_element(latencies.begin(), latencies.end());
    const bool met = !latencies.empty() && maxLatency <= LatencyTarget;
    allMet = allMet && met;
    std::printf("  cancelled at %d evenly spaced times (%zu before the end): latency max %.3f s "
                "(requested at %.2f s), median %.3f s; of which unwinding (from the callback "
                "saying stop to the catch) max %.3f s\n",
      options.cancelPoints, latencies.size(), maxLatency,
      worst != runs.end() ? worst->requestedAt : 0.0, median(latencies),
      unwindings.empty() ? 0.0 : *std::max_element(unwindings.begin(), unwindings.end()));
    std::printf("  latencies (requested at s: latency s, unwinding s, fraction):");
    for (const CancelRun& r : runs)
    {
      if (r.cancelled)
      {
        std::printf(" %.2f: %.3f, %.3f, %.3f;", r.requestedAt, r.latency, r.unwinding, r.fraction);
      }
      else
      {
        std::printf(" %.2f: finished;", r.requestedAt);
      }
    }
    std::printf(
      "\n  Target: cancellable within %.1f s: %s\n", LatencyTarget, met ? "met" : "MISSED");

    json << (c > 0 ? ", " : "") << "{\"target_patches\": " << options.patchCounts[c]
         << ", \"patches\": " << s.patches << ", \"seconds\": " << s.seconds
         << ", \"seconds_contacts\": " << s.secondsContacts << ", \"longest_poll_gap_seconds\": "
         << (plain.longestGaps.empty() ? 0.0 : plain.longestGaps[0].seconds)
         << ", \"cancel_requests\": " << options.cancelPoints
         << ", \"cancelled\": " << latencies.size()
         << ", \"cancel_latency_max_seconds\": " << maxLatency
         << ", \"cancel_latency_median_seconds\": " << median(latencies)
         << ", \"target_met\": " << (met ? "true" : "false") << "}";
  }
  json << "], \"target_met\": " << (allMet ? "true" : "false") << "}";
  return json.str();
}

} // namespace mlr::bench
