// Limits: memory estimates refuse work before allocating it, and a solve can be cancelled at
// any phase, remeshing a 200,000-triangle input included, within 0.5 s.
#include "CoreChecks.h"
#include "ReliabilitySupport.h"

#include "Error.h"
#include "GeneratedScenes.h"
#include "MovingLight.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

using namespace mlr;
using mlr::checks::errorOf;
using namespace mlr::reliability;

namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

/// Remeshing, scene and solve of the 200,000-triangle sphere lit from inside, as the filter
/// runs them; `keepGoing(lastPoll)` is polled through both progress callbacks, `lastPoll`
/// true at the solve's final poll (fraction 1), the last chance to cancel. Returns the phase
/// it was in when it stopped ("done" when it did not).
struct Pipeline
{
  PolygonSoup soup = sphereSoup(100);
  std::vector<std::vector<Vec3>> light = scenes::squareLightFacingDown({ 0, 0, 0 }, 0.2);
  std::vector<Vec3> translations =
    scenes::translationsAlong({ 0, 0, 0 }, { -0.3, 0, 0 }, { 0.3, 0, 0 }, 30);

  template <typename KeepGoing>
  std::string run(const KeepGoing& keepGoing) const
  {
    std::string phase = "remeshing";
    try
    {
      const RemeshResult remeshed =
        remesh(soup, RemeshOptions{}, [&](double) { return keepGoing(false); });
      phase = "building the scene";
      const Scene scene = Scene::fromPatchMesh(remeshed.mesh);
      const MovingLight moving(light, Rgb(100), translations);
      SolverOptions options;
      options.pathsPerFrame = 300000;
      phase = "solving";
      solve(
        scene, moving, options, [&](double fraction) { return keepGoing(fraction >= 1 - 1e-9); });
      return "done";
    }
    catch (const Cancelled&)
    {
      return phase;
    }
  }
};
}

TEST(CancelLatency, AnyPhaseOfRemeshingAndSolvingA200kTriangleSphere)
{
  const Pipeline pipeline;
  ASSERT_EQ(pipeline.soup.polygons.size(), 200000u);
  const auto start = Clock::now();
  ASSERT_EQ(pipeline.run([](bool) { return true; }), "done");
  const double total = secondsSince(start);

  // Cancel at evenly spread times over the whole run; the request comes from another thread,
  // so the latency includes the wait for the next poll of the callback. A run faster than
  // the first could end before its request: its final poll waits for the request and then
  // refuses, so that every run is cancelled and measured, whatever the machine's load.
  const int runs = UnderAddressSanitizer ? 3 : 8;
  double worst = 0;
  int cancelledBeforeTheEnd = 0;
  for (int k = 0; k < runs; ++k)
  {
    const double delay = total * (k + 0.5) / runs;
    DelayedCancel cancel(delay);
    bool waited = false;
    const std::string phase = pipeline.run(
      [&](bool lastPoll)
      {
        waited = waited || (lastPoll && !cancel.requested());
        while (lastPoll && !cancel.requested())
        {
          std::this_thread::sleep_for(std::chrono::milliseconds(1));
        }
        return cancel.keepGoing();
      });
    cancel.finished();
    ASSERT_TRUE(cancel.requested()) << "cancel " << k;
    ASSERT_TRUE(cancel.refused()) << "cancelled at " << delay << " s but no poll saw it";
    ASSERT_NE(phase, "done") << "cancelled at " << delay << " s but not stopped";
    const double latency = cancel.latency();
    ASSERT_GE(latency, 0.0);
    std::printf("cancel at %.2f s of %.2f s: stopped %s after %.3f s\n", delay, total,
      phase.c_str(), latency);
    EXPECT_LT(latency, CancelLatencyBound) << "cancelled at " << delay << " s, while " << phase;
    worst = std::max(worst, latency);
    cancelledBeforeTheEnd += waited ? 0 : 1;
  }
  std::printf("worst cancellation latency: %.3f s (bound %.1f s); %d of %d runs stopped before "
              "their final poll\n",
    worst, CancelLatencyBound, cancelledBeforeTheEnd, runs);
}

TEST(MemoryLimit, RemeshingIsRefusedBeforeAllocating)
{
  const PolygonSoup sphere = sphereSoup(20); // 8,000 triangles, area ~12.5
  for (bool cgal : { true, false })
  {
    RemeshOptions options;
    options.useCgal = cgal;
    options.targetEdgeLength = 0.01; // ~340,000 patches
    options.memoryLimitBytes = 64ULL << 20;
    const auto start = Clock::now();
    const std::string message = errorOf([&] { remesh(sphere, options); });
    EXPECT_NE(message.find("remeshing at patch size 0.01 needs an estimated"), std::string::npos)
      << message;
    EXPECT_NE(message.find("over the memory limit of 0.0625 GiB"), std::string::npos) << message;
    EXPECT_LT(secondsSince(start), 1.0) << "refused after the work, not before";
  }
  // The default limit (half the physical memory) refuses what no machine here holds.
  RemeshOptions huge;
  huge.targetEdgeLength = 0.0005; // ~130 million patches
  const std::string message = errorOf([&] { remesh(sphere, huge); });
  EXPECT_TRUE(message.find("over the memory limit") != std::string::npos ||
    message.find("give a larger patch size") != std::string::npos)
    << message;
  // Within the limit it runs.
  RemeshOptions fine;
  fine.targetEdgeLength = 0.2;
  fine.memoryLimitBytes = 64ULL << 20;
  EXPECT_GT(remesh(sphere, fine).statistics.patches, 100u);
}

// The estimate against the bytes a solve allocates is TestSolveMemory (an executable that
// counts the heap).
TEST(MemoryLimit, SolveEstimateSaturates)
{
  SolverOptions options;
  options.threads = 2;
  // Counts no machine can hold saturate instead of wrapping around to small numbers.
  const std::uint64_t huge = estimateSolveMemory(std::size_t(1) << 40, std::size_t(1) << 42,
    std::size_t(1) << 41, std::size_t(1) << 30, options);
  EXPECT_EQ(huge, UINT64_MAX);
  const std::string message = errorOf(
    [&] {
      checkSolveMemory(huge, 1u << 30, std::size_t(1) << 40, std::size_t(1) << 42, options, true);
    });
  EXPECT_NE(message.find("about 1099511627776 patches"), std::string::npos) << message;
}
