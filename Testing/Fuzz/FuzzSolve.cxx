// libFuzzer target: arbitrary bytes -> a polygon soup (points, polygons, materials), a light,
// a trajectory, remeshing and solver options (and sometimes a cancellation) -> remesh(),
// Scene::fromPatchMesh(), MovingLight and a tiny solve() through Core.
//
// mlr::Error (bad input, limits, cancellation) is a normal outcome. Findings are crashes,
// sanitizer reports, any other exception escaping Core, hangs (-timeout), memory over
// -rss_limit_mb, and broken promises checked below: remeshing that succeeds must give a
// valid scene, and a solve that succeeds must give finite, non-negative radiosity.
#include "ByteReader.h"

#include "Error.h"
#include "MovingLight.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Solver.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

namespace
{
using mlr::fuzz::ByteReader;

/// MLR_FUZZ_VERBOSE=1 prints how each input ended, to check that seeds get where meant.
void outcome(const std::string& what)
{
  static const bool verbose = std::getenv("MLR_FUZZ_VERBOSE") != nullptr;
  if (verbose)
  {
    std::fprintf(stderr, "  -> %s\n", what.c_str());
  }
}

[[noreturn]] void finding(const std::string& what)
{
  std::fprintf(stderr, "FUZZ FINDING: %s\n", what.c_str());
  std::abort();
}

mlr::Rgb reflectance(ByteReader& in)
{
  const std::uint8_t kind = in.byte();
  if (kind < 200)
  {
    return mlr::Rgb((kind % 20) / 20.0);
  }
  if (kind < 240)
  {
    return mlr::Rgb(in.unit() * 0.99, in.unit() * 0.99, in.unit() * 0.99);
  }
  static const double special[] = { 1.0, -0.1, std::nan(""), 0.9999999999, 0.0, 1e-300, 1e300,
    -0.0 };
  return mlr::Rgb(0.5, special[kind % 8], 0.5);
}

double edgeLength(ByteReader& in)
{
  static const double lengths[] = { 1e-9, 1e-4, 1e-3, 0.01, 0.05, 0.1, 0.25, 0.5, 1, 3, 100,
    std::nan(""), -1, HUGE_VAL, 1e-300, 0.02 };
  return lengths[in.below(16)];
}
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  ByteReader in(data, size);
  const std::uint8_t flags = in.byte();

  // The scene: few points on a coarse grid, so that polygons share points, edges and planes.
  mlr::PolygonSoup soup;
  const std::size_t pointCount = 3 + in.below(40);
  for (std::size_t i = 0; i < pointCount; ++i)
  {
    const double x = in.coordinate(), y = in.coordinate(), z = in.coordinate();
    soup.points.emplace_back(x, y, z);
  }
  const std::size_t polygonCount = 1 + in.below(24);
  for (std::size_t p = 0; p < polygonCount; ++p)
  {
    std::vector<std::uint32_t> polygon(in.below(7));
    for (std::uint32_t& v : polygon)
    {
      // Now and then an index past the last point.
      const std::uint8_t kind = in.byte();
      v = kind < 250 ? static_cast<std::uint32_t>(in.below(pointCount))
                     : static_cast<std::uint32_t>(pointCount + kind % 3);
    }
    soup.polygons.push_back(std::move(polygon));
    soup.materials.push_back(mlr::Material{ reflectance(in) });
  }
  if (flags & 0x10)
  {
    soup.materials.pop_back(); // one material short
  }

  // The light: one or two small polygons, usually planar (z fixed).
  std::vector<std::vector<mlr::Vec3>> light(1 + in.below(2));
  for (auto& polygon : light)
  {
    const double z = in.coordinate();
    const std::size_t corners = 2 + in.below(4);
    for (std::size_t i = 0; i < corners; ++i)
    {
      const double x = in.coordinate(), y = in.coordinate();
      polygon.emplace_back(x, y, (flags & 0x20) ? in.coordinate() : z);
    }
  }
  // Mostly a valid power and 1 or 2 frames, so that most inputs reach the solve.
  static const double powers[] = { 100, 1, 0, 1e30, -1, std::nan(""), 1e-300, 3 };
  auto powerOf = [&in](std::uint8_t b) { return b < 192 ? 100.0 : powers[b % 8]; };
  const double red = powerOf(in.byte()), blue = powerOf(in.byte());
  const mlr::Rgb power(red, 100, blue);
  const std::uint8_t frames = in.byte();
  std::vector<mlr::Vec3> translations(frames < 8 ? 0 : frames < 16 ? 3 : 1 + frames % 2);
  for (mlr::Vec3& t : translations)
  {
    const double x = in.coordinate(), y = in.coordinate(), z = in.coordinate();
    t = mlr::Vec3(x, y, z);
  }

  mlr::RemeshOptions remeshOptions;
  remeshOptions.useCgal = (flags & 0x01) == 0;
  if (in.byte() < 128)
  {
    remeshOptions.targetEdgeLength = 0;
    remeshOptions.targetPatchCount = in.below(300);
  }
  else
  {
    remeshOptions.targetEdgeLength = edgeLength(in);
  }
  remeshOptions.sharpEdgeAngle = in.byte() < 240 ? 30.0 : in.byte() - 20.0;
  // Small limits: a fuzz input must be refused, not allowed to take seconds or gigabytes.
  remeshOptions.memoryLimitBytes = 8ULL << 20;

  mlr::SolverOptions solverOptions;
  solverOptions.pathsPerFrame = in.u16() % 2000;
  solverOptions.gatheringRatio = in.byte() / 64.0;
  solverOptions.firstBounceSurvival = in.unit();
  solverOptions.reuseShooting = (flags & 0x02) == 0;
  solverOptions.reuseGathering = (flags & 0x04) == 0;
  solverOptions.twoSided = (flags & 0x08) == 0;
  solverOptions.seed = in.byte();
  solverOptions.threads = 1 + static_cast<int>(in.below(2));
  solverOptions.memoryLimitBytes = (1 + in.below(32)) << 20;

  // Sometimes the caller cancels after a few progress reports, in remeshing or in the solve.
  const bool cancels = (flags & 0x40) != 0;
  const std::size_t cancelAfter = in.below(40);
  std::size_t reports = 0;
  auto progress = [&](double fraction)
  {
    if (!(fraction >= 0.0 && fraction <= 1.0))
    {
      finding("progress fraction out of [0, 1]: " + std::to_string(fraction));
    }
    return !cancels || ++reports <= cancelAfter;
  };

  mlr::RemeshResult remeshed;
  try
  {
    remeshed = mlr::remesh(soup, remeshOptions, progress);
  }
  catch (const mlr::Error& e)
  {
    outcome(std::string("remesh: ") + e.what());
    return 0;
  }
  const mlr::PatchMesh& mesh = remeshed.mesh;
  if (mesh.triangles.empty() || mesh.reflectance.size() != mesh.triangles.size())
  {
    finding("remesh() returned an empty or inconsistent mesh without an error");
  }
  for (const mlr::Triangle& t : mesh.triangles)
  {
    for (std::uint32_t v : t)
    {
      if (v >= mesh.points.size())
      {
        finding("remesh() returned a triangle on a point that does not exist");
      }
    }
  }

  mlr::Scene scene;
  try
  {
    scene = mlr::Scene::fromPatchMesh(mesh);
  }
  catch (const mlr::Error& e)
  {
    // remesh() promises patches a Scene accepts.
    finding(std::string("Scene::fromPatchMesh refused remesh()'s output: ") + e.what());
  }

  try
  {
    const mlr::MovingLight movingLight(light, power, translations);
    const mlr::Solution solution = mlr::solve(scene, movingLight, solverOptions, progress);
    for (std::size_t f = 0; f < solution.frameCount(); ++f)
    {
      for (std::size_t e = 0; e < solution.elementCount(); ++e)
      {
        const mlr::Rgb b = solution.total(f, e, solution.litSide(e));
        if (!b.isFinite() || b.minComponent() < 0)
        {
          finding("the solve gave radiosity that is negative, NaN or infinite");
        }
      }
    }
    outcome("solved " + std::to_string(solution.frameCount()) + " frames of " +
      std::to_string(scene.patchCount()) + " patches");
  }
  catch (const mlr::Error& e)
  {
    outcome(std::string("solve: ") + e.what());
  }
  return 0;
}
