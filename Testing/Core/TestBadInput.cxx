// Every bad input is refused with a message that names what to fix; cancellation stops a
// solve quickly and never returns a partial result.
#include "CoreChecks.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <chrono>
#include <limits>

using namespace mlr;
using mlr::checks::expectError;

namespace
{
PatchMesh floorMesh()
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  return mesh;
}

MovingLight someLight(std::size_t frames = 2)
{
  return MovingLight(
    scenes::squareLightFacingDown({ 0.5, 0.5, 1 }, 0.2), Rgb(1), std::vector<Vec3>(frames));
}

const double notANumber = std::numeric_limits<double>::quiet_NaN();
const double infinity = std::numeric_limits<double>::infinity();
}

TEST(BadInput, EmptyScene)
{
  expectError([] { Scene::fromPatchMesh(PatchMesh{}); }, "scene is empty");
}

TEST(BadInput, ReflectanceOutsideUnitInterval)
{
  for (double rho : { 1.0, 1.5, -0.1, notANumber })
  {
    PatchMesh mesh = floorMesh();
    mesh.reflectance[3] = Rgb(0.5, rho, 0.5);
    expectError([&] { Scene::fromPatchMesh(mesh); }, "patch 3 has reflectance");
  }
}

TEST(BadInput, NonFiniteCoordinates)
{
  PatchMesh mesh = floorMesh();
  mesh.points[0].x = notANumber;
  mesh.points[4].z = infinity;
  expectError([&] { Scene::fromPatchMesh(mesh); }, "2 points with NaN or infinite coordinates");
}

TEST(BadInput, DegeneratePatchAndBadIndex)
{
  PatchMesh mesh = floorMesh();
  mesh.triangles[2] = { 0, 1, 1 };
  expectError([&] { Scene::fromPatchMesh(mesh); }, "patch 2 is degenerate");
  mesh = floorMesh();
  mesh.triangles[1][2] = 999;
  expectError([&] { Scene::fromPatchMesh(mesh); }, "patch 1 uses point 999");
  mesh = floorMesh();
  mesh.reflectance.pop_back();
  expectError([&] { Scene::fromPatchMesh(mesh); }, "one reflectance per patch");
}

TEST(BadInput, DegenerateLight)
{
  const std::vector<Vec3> frames(1);
  expectError([&] { MovingLight({}, Rgb(1), frames); }, "no polygon");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 1, 0, 0 } } }, Rgb(1), frames);
    },
    "needs at least 3");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 1, 0, 0 }, { 2, 0, 0 } } }, Rgb(1), frames);
    },
    "zero area");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 0, 0, 0 }, { 0, 0, 0 } } }, Rgb(1), frames);
    },
    "zero area");
  // Edges that cross, enclosing a net area of 2.
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 3, 0, 0 }, { 0, 2, 0 }, { 1, 2, 0 } } }, Rgb(1), frames);
    },
    "not a simple polygon");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 1, 0, 0 }, { 1, 1, 0.5 }, { 0, 1, 0 } } }, Rgb(1), frames);
    },
    "not planar");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 0 }, { 1, 0, notANumber }, { 0, 1, 0 } } }, Rgb(1), frames);
    },
    "NaN");
  const auto square = scenes::squareLightFacingDown({ 0, 0, 0 }, 1);
  expectError([&] { MovingLight(square, Rgb(1, -1, 1), frames); }, "light power");
  expectError([&] { MovingLight(square, Rgb(1, notANumber, 1), frames); }, "light power");
  expectError([&] { MovingLight(square, Rgb(1), std::vector<Vec3>{}); }, "zero frames");
  expectError([&] { MovingLight(square, Rgb(1), { Vec3(0, infinity, 0) }); }, "light position 0");
}

TEST(BadInput, SolverOptionsOutOfRange)
{
  const Scene scene = Scene::fromPatchMesh(floorMesh());
  const MovingLight light = someLight();
  auto with = [&](auto change)
  {
    return [&scene, &light, change]
    {
      SolverOptions o;
      o.pathsPerFrame = 100;
      change(o);
      solve(scene, light, o);
    };
  };
  expectError(with([](SolverOptions& o) { o.pathsPerFrame = 0; }), "paths per frame is 0");
  expectError(with([](SolverOptions& o) { o.pathsPerFrame = 1ULL << 62; }), "over the maximum");
  expectError(with([](SolverOptions& o) { o.firstBounceSurvival = 0; }), "lambda");
  expectError(with([](SolverOptions& o) { o.firstBounceSurvival = 1.5; }), "lambda");
  expectError(with([](SolverOptions& o) { o.firstBounceSurvival = notANumber; }), "lambda");
  expectError(with([](SolverOptions& o) { o.gatheringRatio = -1; }), "gathering ratio k");
  expectError(with([](SolverOptions& o) { o.gatheringRatio = notANumber; }), "gathering ratio k");
  expectError(with([](SolverOptions& o) { o.threads = -2; }), "thread count");
}

TEST(BadInput, MemoryEstimateOverLimitIsRefusedBeforeAllocating)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(10, true, { Rgb(0.5) }));
  const MovingLight light = someLight(10000);
  SolverOptions o;
  o.pathsPerFrame = 1000;
  o.memoryLimitBytes = 256ULL << 20;
  const std::uint64_t estimate = estimateSolveMemory(scene, 10000, o);
  EXPECT_GT(estimate, o.memoryLimitBytes);
  const auto start = std::chrono::steady_clock::now();
  expectError([&] { solve(scene, light, o); }, "over the memory limit");
  // Refused up front: no time spent allocating or tracing (gigabytes would take far longer;
  // the bound is loose so that the machine's load cannot change the verdict).
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  // The estimate counts the results at least: frames x 2 sides x (patch radiosity + direct
  // and indirect per element), RGB floats.
  const std::uint64_t floor =
    10000ULL * 2 * (scene.patchCount() + 2 * scene.elementCount()) * sizeof(PackedRgb);
  EXPECT_GT(estimate, floor);
}

TEST(Cancel, StopsPromptlyAndReportsIt)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(8, true, { Rgb(0.7) }));
  const MovingLight light(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.3, 0.9 }, { 0.7, 0.7, 0.9 }, 30));
  for (bool reuse : { true, false })
  {
    SolverOptions o;
    o.pathsPerFrame = 50000000; // minutes of work
    o.reuseShooting = reuse;
    o.reuseGathering = reuse;
    std::chrono::steady_clock::time_point cancelledAt;
    double lastFraction = -1;
    bool monotonic = true;
    auto progress = [&](double fraction)
    {
      monotonic = monotonic && fraction >= lastFraction;
      lastFraction = fraction;
      if (fraction > 0.0005)
      {
        cancelledAt = std::chrono::steady_clock::now();
        return false;
      }
      return true;
    };
    EXPECT_THROW(solve(scene, light, o, progress), Cancelled);
    const double latency =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - cancelledAt).count();
    // Tasks are milliseconds long; the bound is 25 times the 0.2 s expected on a quiet
    // machine, so that the gate's load cannot change the verdict (a lost check still fails).
    EXPECT_LT(latency, 5.0) << (reuse ? "reuse" : "classic");
    EXPECT_TRUE(monotonic);
  }
  // Cancelling before anything starts also reports it.
  SolverOptions o;
  o.pathsPerFrame = 1000;
  EXPECT_THROW(solve(scene, light, o, [](double) { return false; }), Cancelled);
}

TEST(Cancel, ProgressReachesOne)
{
  const Scene scene = Scene::fromPatchMesh(floorMesh());
  SolverOptions o;
  o.pathsPerFrame = 20000;
  double last = 0;
  solve(scene, someLight(), o,
    [&](double f)
    {
      last = f;
      return true;
    });
  EXPECT_DOUBLE_EQ(last, 1.0);
}
