// Limits (issue 7): memory estimates refuse work before allocating it, and a solve can be
// cancelled at any phase, remeshing a 200,000-triangle input included, within 0.5 s.
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
/// runs them; `keepGoing` is polled through both progress callbacks. Returns the phase it
/// was in when it stopped ("done" when it did not).
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
      const RemeshResult remeshed = remesh(soup, RemeshOptions{}, [&](double) { return keepGoing(); });
      phase = "building the scene";
      const Scene scene = Scene::fromPatchMesh(remeshed.mesh);
      const MovingLight moving(light, Rgb(100), translations);
      SolverOptions options;
      options.pathsPerFrame = 300000;
      phase = "solving";
      solve(scene, moving, options, [&](double) { return keepGoing(); });
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
  ASSERT_EQ(pipeline.run([] { return true; }), "done");
  const double total = secondsSince(start);

  // Cancel at evenly spread times over the whole run; the request comes from another thread,
  // so the latency includes the wait for the next poll of the callback.
  const int runs = UnderAddressSanitizer ? 3 : 8;
  double worst = 0;
  for (int k = 0; k < runs; ++k)
  {
    const double delay = total * (k + 0.5) / runs;
    DelayedCancel cancel(delay);
    const std::string phase = pipeline.run([&] { return cancel.keepGoing(); });
    cancel.finished();
    if (!cancel.refused())
    {
      EXPECT_EQ(phase, "done");
      continue; // finished before any poll saw the request: nothing to measure
    }
    EXPECT_NE(phase, "done") << "cancelled at " << delay << " s but not stopped";
    const double latency = cancel.latency();
    std::printf("cancel at %.2f s of %.2f s: stopped %s after %.3f s\n", delay, total, phase.c_str(),
      latency);
    EXPECT_LT(latency, CancelLatencyBound) << "cancelled at " << delay << " s, while " << phase;
    worst = std::max(worst, latency);
  }
  std::printf("worst cancellation latency: %.3f s (bound %.1f s)\n", worst, CancelLatencyBound);
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

TEST(MemoryLimit, SolveEstimateFromCountsMatchesTheSceneAndSaturates)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(6, true, { Rgb(0.5) }));
  SolverOptions options;
  options.threads = 2;
  EXPECT_EQ(estimateSolveMemory(scene, 7, options),
    estimateSolveMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), 7, options));
  // Counts no machine can hold saturate instead of wrapping around to small numbers.
  const std::uint64_t huge = estimateSolveMemory(std::size_t(1) << 40, std::size_t(1) << 42,
    std::size_t(1) << 41, std::size_t(1) << 30, options);
  EXPECT_EQ(huge, UINT64_MAX);
  const std::string message =
    errorOf([&] { checkSolveMemory(huge, 1u << 30, std::size_t(1) << 40, std::size_t(1) << 42, options, true); });
  EXPECT_NE(message.find("about 1099511627776 patches"), std::string::npos) << message;
}
