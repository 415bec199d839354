// Final gathering: what a gathering ray reads where it lands, against form factors. A patch
// whose four elements have very different direct light must not be read as its mean, or a
// surface that sees one lit corner of it (a face beside a shadow edge) is biased by the
// patch size.
#include "CoreChecks.h"
#include "Gathering.h"
#include "GeneratedScenes.h"
#include "RayTracer.h"
#include "Sensors.h"
#include "Solution.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlr;
using mlr::checks::elementFormFactor;

namespace
{
constexpr double Rho = 0.5;
constexpr double LitIrradiance = 4.0; ///< the direct irradiance of the lit floor element
constexpr double Bounced = 0.3;       ///< the floor patch's radiosity from later bounces
constexpr double Height = 0.01;       ///< of the receiver over the lit element's centroid
constexpr double Half = 0.005;        ///< half the receiver's side

/// A floor that is one patch (a triangle of legs 2), and a small square receiver facing down
/// just above the centroid of the floor's element `lit`.
struct FloorScene
{
  Scene scene;
  std::size_t lit = 0;
  Vec3 above;
};

FloorScene floorScene()
{
  PatchMesh mesh;
  mesh.points = { { 0, 0, 0 }, { 2, 0, 0 }, { 0, 2, 0 } };
  mesh.triangles = { { 0, 1, 2 } };
  mesh.reflectance = { Rgb(Rho) };
  const Scene floor = Scene::fromPatchMesh(mesh);
  // A corner element: the receiver sees the two edges that part it from its patch's others.
  FloorScene result;
  result.lit = 0;
  const Triangle& t = floor.elementTriangles()[result.lit];
  const auto& p = floor.points();
  result.above = (p[t[0]] + p[t[1]] + p[t[2]]) / 3.0 + Vec3(0, 0, Height);
  scenes::addGriddedQuad(mesh, result.above + Vec3(-Half, Half, 0), { 2 * Half, 0, 0 },
    { 0, -2 * Half, 0 }, 1, 1, Rgb(Rho));
  result.scene = Scene::fromPatchMesh(mesh);
  return result;
}

/// The floor's element `lit` has direct irradiance LitIrradiance, its other three none, and the
/// floor patch's bounced light is Bounced.
Solution floorSolution(const FloorScene& f)
{
  const Scene& scene = f.scene;
  Solution solution(1, scene.elementCount(), scene.patchCount());
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    solution.reflectanceData()[e] = scene.elementReflectance(e);
  }
  solution.directData()[solution.elementIndex(0, f.lit, Side::Front)] =
    PackedRgb(Rgb(LitIrradiance));
  solution.patchData()[solution.patchIndex(0, 0, Side::Front)] = PackedRgb(Rgb(Bounced));
  return solution;
}

/// What a cosine-weighted ray from `triangle` (normal `normal`) reads, as mean and standard
/// deviation: rho E + Bounced on the lit element, Bounced on the rest of the floor.
struct Expected
{
  double mean = 0, sigma = 0;
};

Expected expectedReading(
  const FloorScene& f, const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& normal)
{
  const auto& p = f.scene.points();
  const Triangle& t = f.scene.elementTriangles()[f.lit];
  const double toLit = elementFormFactor(a, b, c, normal, { p[t[0]], p[t[1]], p[t[2]] });
  const double toFloor = elementFormFactor(a, b, c, normal, { p[0], p[1], p[2] });
  const double lit = Rho * LitIrradiance + Bounced;
  Expected e;
  e.mean = toLit * lit + (toFloor - toLit) * Bounced;
  const double square = toLit * lit * lit + (toFloor - toLit) * Bounced * Bounced;
  e.sigma = std::sqrt(std::max(0.0, square - e.mean * e.mean));
  return e;
}
}

TEST(Gathering, ReadsTheDirectLightOfTheElementItReaches)
{
  // Over the lit corner element, almost every ray lands on it: it reads rho E + Bounced
  // (about 2.3), where the patch's mean would read rho E / 4 + Bounced (0.8).
  const FloorScene f = floorScene();
  const RayTracer tracer(f.scene);
  Solution solution = floorSolution(f);
  solution.allocateIndirect();
  SolverOptions options;
  options.threads = 1;
  options.seed = 11;
  const std::uint64_t raysPerSide = 20000;
  options.pathsPerFrame = raysPerSide * 2 * f.scene.elementCount();
  options.gatheringRatio = 1;
  const std::vector<std::uint8_t> reachable(2 * f.scene.patchCount(), 1);
  double secondsReducing = 0;
  gatherIndirect(
    f.scene, tracer, options, reachable, 1, [](double) { return true; }, secondsReducing, solution);

  const auto& p = f.scene.points();
  for (std::size_t e = Scene::ElementsPerPatch; e < f.scene.elementCount(); ++e)
  {
    const Triangle& t = f.scene.elementTriangles()[e];
    const Expected x = expectedReading(f, p[t[0]], p[t[1]], p[t[2]], f.scene.elementNormal(e));
    const double read = solution.indirectIrradiance(0, e, Side::Front).r;
    // What a ray reads is stored once more before it is summed (PackedRgb rounding).
    EXPECT_NEAR(read, x.mean,
      5 * x.sigma / std::sqrt(double(raysPerSide)) + 2 * PackedRgb::RelativeRounding * x.mean)
      << "receiver element " << e;
    EXPECT_GT(read, 2.0) << "read as the lit element, not as the patch's mean";
  }
  // What the sensors read with, and the patch's radiosity: its direct part the mean of its
  // elements' (equal areas), rho E / 4.
  // Each is a sum of stored values, each rounded to within PackedRgb::RelativeRounding.
  const auto stored = [](double x) { return PackedRgb::RelativeRounding * x; };
  EXPECT_NEAR(gatheredRadiosity(f.scene, solution, 0, f.lit, Side::Front).r,
    Rho * LitIrradiance + Bounced, stored(Rho * LitIrradiance + Bounced));
  EXPECT_NEAR(
    gatheredRadiosity(f.scene, solution, 0, f.lit + 1, Side::Front).r, Bounced, stored(Bounced));
  EXPECT_NEAR(solution.patchRadiosity(0, 0, Side::Front).r, Rho * LitIrradiance / 4 + Bounced,
    stored(Rho * LitIrradiance / 4 + Bounced));
  EXPECT_NEAR(f.scene.elementArea(f.lit), f.scene.patchArea(0) / 4, 1e-12);
}

TEST(Gathering, SensorsReadTheDirectLightOfTheElementTheyReach)
{
  // A sensor where the receiver was, facing down, with no light of its own to see: what it
  // reads is what a gathering ray reads.
  FloorScene f = floorScene();
  const Solution solution = floorSolution(f);
  SensorSet sensors;
  sensors.points = { f.above };
  sensors.normals = { { 0, 0, -1 } };
  SensorOptions counts;
  counts.hemisphereRays = 20000;
  SolverOptions options;
  options.threads = 1;
  options.seed = 5;
  const SensorSolution result =
    solveSensors(f.scene, LightRig(), solution, sensors, options, counts);
  // A point over the lit element: the form factor of a vanishing receiver there.
  const Vec3 d(1e-6, 0, 0), e(0, 1e-6, 0);
  const Expected x =
    expectedReading(f, f.above - d - e, f.above + d - e, f.above + e, { 0, 0, -1 });
  EXPECT_NEAR(result.irradiance(0, 0).r, x.mean,
    5 * x.sigma / std::sqrt(double(counts.hemisphereRays)) + 1e-4 * x.mean);
  EXPECT_GT(result.irradiance(0, 0).r, 2.0);
}

TEST(Gathering, AnyBudgetGivesTheSameBits)
{
  // Under a tight memory limit gathering holds its rows a frame at a time and keeps the hits
  // of a few sides at a time: every frame still sums its rays in the same order.
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(
    3, true, { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.6), Rgb(0.6), Rgb(0.5), Rgb(0.7) }));
  const MovingLight light(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.2, 0.5, 0.9 }, { 0.8, 0.5, 0.9 }, 5));
  SolverOptions options = checks::modeOptions(true, 20000, 3);
  Solution solution = solve(scene, light, options);
  const RayTracer tracer(scene);
  const std::vector<std::uint8_t> reachable(2 * scene.patchCount(), 1);
  auto gathered = [&](const GatheringBudget& budget)
  {
    solution.allocateIndirect();
    double secondsReducing = 0;
    gatherIndirect(
      scene, tracer, options, reachable, 2, [](double) { return true; }, secondsReducing, solution,
      budget);
    return solution.indirectData();
  };
  const StoredArray whole = gathered({});
  // A frame of rows (a stored value per element side) and the hits of one task at a time.
  const std::uint64_t frameOfRows = 2 * sizeof(PackedRgb) * scene.elementCount();
  const StoredArray tight = gathered({ frameOfRows, 1 });
  EXPECT_EQ(gatheringBlockFrames(scene.elementCount(), 5, frameOfRows), 1u);
  EXPECT_EQ(gatheringBlockFrames(scene.elementCount(), 5, 2 * frameOfRows), 2u);
  EXPECT_TRUE(checks::sameBits(whole, tight));
  double sum = 0;
  for (const PackedRgb& v : whole)
  {
    sum += Rgb(v).sum();
  }
  EXPECT_GT(sum, 0) << "gathering read nothing";
}

TEST(Gathering, SidesCastTheRaysAskedForOnAverage)
{
  // A mean of 1.415 rays a side (what rounding made 1, 71% of the rays asked for): each side
  // casts 1 or 2, 2 with probability 0.415, so 20,000 sides cast 28,300 rays give or take
  // sqrt(20,000 x 0.415 x 0.585) = 70.
  constexpr std::uint32_t Sides = 20000;
  for (const std::uint64_t seed : { 1u, 2u })
  {
    std::uint64_t total = 0, twos = 0;
    for (std::uint32_t side = 0; side < Sides; ++side)
    {
      const std::uint64_t rays = raysOfSide(1.415, seed, side);
      ASSERT_TRUE(rays == 1 || rays == 2) << rays;
      ASSERT_EQ(rays, raysOfSide(1.415, seed, side)) << "keyed by the seed and the side alone";
      total += rays;
      twos += rays == 2 && raysOfSide(1.415, seed + 10, side) == 2;
    }
    EXPECT_NEAR(double(total), 1.415 * Sides, 5 * 70.0);
    // Another seed gives other sides the extra ray: both have it about 0.415^2 of the time.
    EXPECT_NEAR(double(twos), 0.415 * 0.415 * Sides, 5 * std::sqrt(0.172 * 0.828 * Sides));
  }
  // A whole mean is cast exactly.
  for (std::uint32_t side = 0; side < 100; ++side)
  {
    EXPECT_EQ(raysOfSide(3.0, 7, side), 3u);
    EXPECT_EQ(raysOfSide(1.0, 7, side), 1u);
  }
}

TEST(Gathering, ASolveCastsKTimesNRays)
{
  // k N = 1,000 rays a frame over the closed box's 432 element sides, 2.31 a side: 1,000
  // give or take sqrt(432 x 0.31 x 0.69) = 9.6, where rounding the mean to 2 cast 864.
  // Reuse casts one set, classic one per frame.
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(
    3, true, { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.6), Rgb(0.6), Rgb(0.5), Rgb(0.7) }));
  const MovingLight light(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1),
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.2, 0.5, 0.9 }, { 0.8, 0.5, 0.9 }, 5));
  for (const bool reuse : { true, false })
  {
    SolverOptions options = checks::modeOptions(reuse, 1000, 2);
    const Solution solution = solve(scene, light, options);
    ASSERT_EQ(solution.statistics.gatheringSides, 432u);
    const double perFrame =
      double(solution.statistics.gatheringRays) / (reuse ? 1.0 : double(solution.frameCount()));
    EXPECT_NEAR(perFrame, 1000.0, 5 * 9.6) << (reuse ? "reuse" : "classic");
  }
}
