// Regression tests for what fuzzing found in Core. The inputs that crashed are also
// replayed as files: Testing/Fuzz/regressions/<target>/ (ctest Fuzz.*.Replay).
#include "CoreChecks.h"
#include "Error.h"
#include "GeneratedScenes.h"
#include "MovingLight.h"
#include "Remeshing.h"
#include "Scene.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <string>

using namespace mlr;
using mlr::checks::errorOf;

namespace
{

constexpr const char* OutOfRange = "coordinates must stay within +-1e+15";
}

// mlr-fuzz-readers, stl_coordinates_beyond_embree_range: an STL file with coordinates near
// 1e34 made every ray origin (lifted off surfaces by 1e-5 of the scene's size) invalid for
// Embree, which asserts (and aborts the program) or, built without assertions, misbehaves.
TEST(FuzzRegression, CoordinatesBeyondWhatEmbreeTracesAreRefused)
{
  PolygonSoup soup = scenes::boxOfQuads({ 0, 0, 0 }, { 1, 1, 1 }, { Rgb(0.5) });
  soup.points[3].y = -1.2328603979926733e17;
  EXPECT_NE(errorOf([&] { remesh(soup, RemeshOptions{}); }).find(OutOfRange), std::string::npos);

  PatchMesh mesh = scenes::closedBox(2, true, { Rgb(0.5) });
  mesh.points[1].z = 1.8615590189516027e34;
  EXPECT_NE(errorOf([&] { Scene::fromPatchMesh(mesh); }).find(OutOfRange), std::string::npos);

  const auto square = scenes::squareLightFacingDown({ 0, 0, 0 }, 1);
  EXPECT_NE(errorOf([&] { MovingLight(square, Rgb(1), { Vec3(0, 0, -3e15) }); }).find(OutOfRange),
    std::string::npos);
  const auto far = scenes::squareLightFacingDown({ 2e15, 0, 0 }, 1);
  EXPECT_NE(
    errorOf([&] { MovingLight(far, Rgb(1), { Vec3() }); }).find(OutOfRange), std::string::npos);
}

// The bound itself is safe: a scene, a light and positions at its scale solve.
TEST(FuzzRegression, ScenesAtTheCoordinateBoundSolve)
{
  const double size = 1e14, at = 8e14;
  PatchMesh mesh;
  scenes::addBox(
    mesh, { at, at, at }, { at + size, at + size, at + size }, size / 4, true, { Rgb(0.5) });
  const Scene scene = Scene::fromPatchMesh(mesh);
  const Vec3 centre(at + size / 2, at + size / 2, at + 0.9 * size);
  const MovingLight light(scenes::squareLightFacingDown(centre, 0.2 * size), Rgb(100),
    scenes::translationsAlong(centre, centre, centre + Vec3(0.1 * size, 0, 0), 2));
  SolverOptions options;
  options.pathsPerFrame = 2000;
  const Solution solution = solve(scene, light, options);
  double total = 0;
  for (std::size_t e = 0; e < solution.elementCount(); ++e)
  {
    const Rgb b = solution.total(0, e, solution.litSide(e));
    ASSERT_TRUE(b.isFinite());
    total += b.sum();
  }
  EXPECT_GT(total, 0);
}
