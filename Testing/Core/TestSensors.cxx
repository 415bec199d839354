// Sensors: the sky, the sun, point and area lights and the scene's light on measuring points
// against exact values, their standard errors against their errors over seeds, their
// independence from the thread count, the surfaces' radiosity untouched by them, the daylight
// metrics and bad input.
#include "Animation.h"
#include "CoreChecks.h"
#include "FormFactor.h"
#include "Gathering.h"
#include "GeneratedScenes.h"
#include "Sensors.h"
#include "Sky.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

using namespace mlr;
using mlr::checks::expectError;
using mlr::checks::sameBits;

namespace
{
constexpr double Degree = M_PI / 180.0;

Vec3 sunDirection(double elevation, double azimuth)
{
  const double e = elevation * Degree, a = azimuth * Degree;
  return { std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e) };
}

Scene ground(double half = 1, const Rgb& rho = Rgb(0.5))
{
  PatchMesh mesh;
  scenes::addGriddedQuad(
    mesh, { -half, -half, 0 }, { 2 * half, 0, 0 }, { 0, 2 * half, 0 }, 4, 4, rho);
  return Scene::fromPatchMesh(mesh);
}

SolverOptions quick(std::uint64_t paths = 20000, int threads = 0)
{
  SolverOptions options;
  options.pathsPerFrame = paths;
  options.gatheringRatio = 0.5;
  options.seed = 7;
  options.threads = threads;
  return options;
}

SensorSet oneSensor(const Vec3& point, const Vec3& normal)
{
  SensorSet s;
  s.points.push_back(point);
  s.normals.push_back(normal);
  return s;
}

/// The standard deviation of pi L(w) for cosine-distributed w (z up) over the tabulated sky,
/// by midpoint quadrature in cos^2(theta) (uniform for that density) and phi.
double skyEstimatorSigma(const Sky& sky, std::size_t position)
{
  const int n = 400;
  double m1 = 0, m2 = 0;
  for (int i = 0; i < n; ++i)
  {
    const double c2 = (i + 0.5) / n, cz = std::sqrt(c2), sz = std::sqrt(1 - c2);
    for (int j = 0; j < n; ++j)
    {
      const double phi = 2 * M_PI * (j + 0.5) / n;
      const double v =
        M_PI * sky.radiance(position, { sz * std::cos(phi), sz * std::sin(phi), cz });
      m1 += v;
      m2 += v * v;
    }
  }
  m1 /= double(n) * n;
  m2 /= double(n) * n;
  return std::sqrt(std::max(0.0, m2 - m1 * m1));
}
}

TEST(Sensors, OpenGroundReadsTheDiffuseHorizontalOfEverySky)
{
  const Scene scene = ground();
  const SensorSet sensors = oneSensor({ 0.1, -0.2, 0.8 }, { 0, 0, 2 });
  SensorOptions counts;
  counts.hemisphereRays = 4000;
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const std::vector<SkyFrame> frames = { { sunDirection(20, 10), 80, 300 },
      { sunDirection(60, 140), 150, 700 } };
    LightRig rig;
    rig.skies.emplace_back(model, Vec3(0, 0, 1), frames);
    const Solution solution = solve(scene, rig, quick());
    const SensorSolution result = solveSensors(scene, rig, solution, sensors, quick(), counts);
    ASSERT_EQ(result.frameCount(), 2u);
    for (std::size_t f = 0; f < 2; ++f)
    {
      const double sigma = skyEstimatorSigma(rig.skies[0], f) / std::sqrt(4000.0);
      const double e = result.irradiance(f, 0).g;
      EXPECT_NEAR(e, frames[f].diffuseHorizontal, 4 * sigma + 1e-5 * frames[f].diffuseHorizontal)
        << skyModelName(model) << " frame " << f;
      EXPECT_EQ(result.sunIrradiance(f, 0).g, 0.0);
    }
    if (model == SkyModel::Uniform)
    {
      EXPECT_NEAR(skyEstimatorSigma(rig.skies[0], 0), 0.0, 1e-9) << "pi L is constant";
    }
  }
}

TEST(Sensors, LookingDownAtLitGroundGathersItsRadiosity)
{
  // A sensor just above a wide ground, facing it, sees (nearly) only the ground, whose
  // radiosity under a uniform sky is rho E_dh.
  const Scene scene = ground(20, Rgb(0.5));
  LightRig rig;
  rig.skies.emplace_back(SkyModel::Uniform, Vec3(0, 0, 1), std::vector<SkyFrame>{ { {}, 100, 0 } });
  // It reads the ground element below it (gatheredRadiosity in Gathering.h), whose direct light has
  // that element's first hits: within 4 of its standard errors (from 16 batches) of rho E_dh.
  SolverOptions options = quick(400000);
  options.errorBatches = 16;
  const Solution solution = solve(scene, rig, options);
  const Vec3 at(0.3, 0.2, 0.05);
  std::size_t below = scene.elementCount();
  for (std::size_t e = 0; e < scene.elementCount() && below == scene.elementCount(); ++e)
  {
    const Triangle& t = scene.elementTriangles()[e];
    const Vec3 a = scene.points()[t[0]], b = scene.points()[t[1]], c = scene.points()[t[2]];
    const auto edge = [&](const Vec3& p, const Vec3& q)
    { return (q.x - p.x) * (at.y - p.y) - (q.y - p.y) * (at.x - p.x); };
    const double ab = edge(a, b), bc = edge(b, c), ca = edge(c, a);
    if ((ab >= 0 && bc >= 0 && ca >= 0) || (ab <= 0 && bc <= 0 && ca <= 0))
    {
      below = e;
    }
  }
  ASSERT_LT(below, scene.elementCount());
  SensorOptions counts;
  counts.hemisphereRays = 2000;
  // Over the element's centroid, 1 cm up: 1.4 m from its edges, all but 1e-4 of the cosine
  // rays land on it.
  const Triangle& t = scene.elementTriangles()[below];
  const Vec3 over =
    (scene.points()[t[0]] + scene.points()[t[1]] + scene.points()[t[2]]) / 3.0 + Vec3(0, 0, 0.01);
  const SensorSolution result =
    solveSensors(scene, rig, solution, oneSensor(over, { 0, 0, -1 }), quick(), counts);
  const double read = gatheredRadiosity(scene, solution, 0, below, Side::Front).r;
  const double standardError = solution.radiosityStdError(0, below, Side::Front).r;
  std::printf("sensor over the ground: %.3f, the element below %.3f (standard error %.3f)\n",
    result.irradiance(0, 0).r, read, standardError);
  EXPECT_NEAR(result.irradiance(0, 0).r, read, 1e-3 * read);
  EXPECT_NEAR(read, 50.0, 4 * standardError);
  EXPECT_LT(standardError, 2.5);
}

TEST(Sensors, TheSunGivesDniTimesTheSineOfItsElevationAndNothingInAShadow)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -2, -2, 0 }, { 4, 0, 0 }, { 0, 4, 0 }, 4, 4, Rgb(0.5));
  // A black roof over (1, 0): it shades that point from a sun high in the south-west.
  scenes::addGriddedQuad(mesh, { 0.6, -0.4, 1.0 }, { 0.8, 0, 0 }, { 0, 0.8, 0 }, 2, 2, Rgb(0.0));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::vector<Vec3> sun = { sunDirection(30, 180), sunDirection(80, 180),
    sunDirection(45, 90) };
  const double dni = 800;
  LightRig withSun, skyOnly;
  withSun.directionalLights.emplace_back(sun, Rgb(dni));
  const std::vector<SkyFrame> frames(3, SkyFrame{ { 0, 0, 1 }, 100, 0 });
  withSun.skies.emplace_back(SkyModel::Uniform, Vec3(0, 0, 1), frames);
  skyOnly.skies = withSun.skies;
  SensorSet sensors = oneSensor({ -1, 0, 0.01 }, { 0, 0, 1 }); // open ground
  sensors.points.push_back({ 1, 0, 0.01 });                    // under the roof
  sensors.normals.push_back({ 0, 0, 1 });
  const Solution lit = solve(scene, withSun, quick());
  const SensorSolution a = solveSensors(scene, withSun, lit, sensors, quick());
  const Solution dark = solve(scene, skyOnly, quick());
  const SensorSolution b = solveSensors(scene, skyOnly, dark, sensors, quick());
  for (std::size_t f = 0; f < 3; ++f)
  {
    const double expected = dni * sun[f].z;
    EXPECT_NEAR(a.sunIrradiance(f, 0).r, expected, 1e-4 * expected) << "frame " << f;
    // The roof shades (1, 0) from a sun at 80 degrees (the ray meets z = 1 at x = 0.82).
    if (f == 1)
    {
      EXPECT_EQ(a.sunIrradiance(f, 1).r, 0.0);
      // Only the sky, and the black roof reflects nothing: as without the sun, bit for bit.
      EXPECT_EQ(a.irradiance(f, 1).r, b.irradiance(f, 1).r);
      EXPECT_LT(a.irradiance(f, 1).r, 100.0);
    }
    // The open sensor sees all the sky but the roof's sliver, near the horizon.
    const double sky = a.irradiance(f, 0).r - a.sunIrradiance(f, 0).r;
    EXPECT_GT(sky, 98.0);
    EXPECT_LE(sky, 100.0 + 1e-3);
  }
  EXPECT_NEAR(a.sunIrradiance(0, 1).r, dni * sun[0].z, 1e-4 * dni) << "a low sun reaches under";
}

TEST(Sensors, APointLightFollowsTheInverseSquareLaw)
{
  const Scene scene = ground(3);
  const Rgb power(100, 50, 20);
  std::vector<LightPose> poses(3);
  poses[0].position = { 0, 0, 2 };
  poses[1].position = { 0.5, 0.3, 1.5 };
  poses[2].position = { -1, 0, 3 };
  poses[2].power = Rgb(0.5);
  LightRig rig;
  rig.pointLights.emplace_back(power, poses);
  const Solution solution = solve(scene, rig, quick());
  const Vec3 point(0.2, -0.1, 0.5), normal = normalize(Vec3(0.3, 0.1, 1));
  const SensorSolution result =
    solveSensors(scene, rig, solution, oneSensor(point, normal), quick());
  for (std::size_t f = 0; f < 3; ++f)
  {
    const Vec3 d = poses[f].position - point;
    const double r2 = dot(d, d), r = std::sqrt(r2);
    // Lambertian about the nadir (-z): I = Phi cos(gamma) / pi.
    const double cosGamma = d.z / r, cosSensor = dot(normal, d) / r;
    const double scale = poses[f].power.r * cosGamma / M_PI * cosSensor / r2;
    // The ground below faces away from the sensor's hemisphere but for a sliver: its light
    // is the only noise, bounded loosely.
    const Rgb e = result.irradiance(f, 0);
    EXPECT_NEAR(e.r, power.r * scale, 0.02 * power.r * scale) << "frame " << f;
    EXPECT_NEAR(e.b / e.r, power.b / power.r, 0.02);
  }
}

TEST(Sensors, AnAreaLightGivesLambertsFormFactor)
{
  // No surface reflects (a black floor): the sensor reads the light's direct irradiance,
  // Phi / A times the point-to-polygon form factor.
  const Scene scene = ground(1, Rgb(0.0));
  const std::vector<std::vector<Vec3>> light = scenes::squareLightFacingDown({ 0, 0, 0.5 }, 0.3);
  const Rgb power(10);
  const std::vector<Vec3> moves = { { 0, 0, 0 }, { 0.2, 0.1, -0.1 } };
  LightRig rig;
  rig.areaLights.emplace_back(light, power, moves);
  const Solution solution = solve(scene, rig, quick());
  const Vec3 point(0.05, 0.02, 0.1), normal = normalize(Vec3(0.2, 0, 1));
  SensorOptions counts;
  counts.areaLightSamples = 4096;
  const SensorSolution result =
    solveSensors(scene, rig, solution, oneSensor(point, normal), quick(), counts);
  const double area = 0.09;
  for (std::size_t f = 0; f < 2; ++f)
  {
    std::vector<Vec3> polygon = light[0];
    for (Vec3& v : polygon)
    {
      v += moves[f];
    }
    const double exact = power.r / area * pointToPolygonFormFactor(point, normal, polygon);
    // The noise of S uniform samples of Phi cos cos / (pi r^2): its deviation by quadrature.
    double m1 = 0, m2 = 0;
    const int n = 64;
    for (int i = 0; i < n; ++i)
    {
      for (int j = 0; j < n; ++j)
      {
        const Vec3 x =
          Vec3(-0.15 + 0.3 * (i + 0.5) / n, -0.15 + 0.3 * (j + 0.5) / n, 0.5) + moves[f];
        const Vec3 d = x - point;
        const double r2 = dot(d, d);
        const double v =
          power.r * (d.z / std::sqrt(r2)) * dot(normal, d) / std::sqrt(r2) / (M_PI * r2);
        m1 += v;
        m2 += v * v;
      }
    }
    m1 /= n * n;
    m2 /= n * n;
    const double sigma = std::sqrt(m2 - m1 * m1) / std::sqrt(4096.0);
    EXPECT_NEAR(m1, exact, 1e-3 * exact) << "the quadrature agrees with Lambert";
    EXPECT_NEAR(result.irradiance(f, 0).r, exact, 4 * sigma) << "frame " << f;
    EXPECT_GT(sigma, 0);
  }
}

TEST(Sensors, AreaLightPointsAreStratified)
{
  // 64 points on a 0.3 m panel 0.3 m above sensors 0.2 to 0.8 m off its axis, over 8 seeds:
  // independent points would leave each reading off by about the deviation of one point
  // over 8 (sigma); the jittered grid leaves a small part of it.
  const Scene scene = ground(2, Rgb(0.0));
  const std::vector<std::vector<Vec3>> light = scenes::squareLightFacingDown({ 0, 0, 0.3 }, 0.3);
  const Rgb power(10);
  LightRig rig;
  rig.areaLights.emplace_back(light, power, std::vector<Vec3>{ { 0, 0, 0 } });
  const Solution solution = solve(scene, rig, quick());
  SensorOptions counts;
  counts.areaLightSamples = 64;
  const Vec3 up(0, 0, 1);
  for (const double x : { 0.2, 0.4, 0.8 })
  {
    const Vec3 point(x, 0.05, 0);
    const double exact = power.r / 0.09 * pointToPolygonFormFactor(point, up, light[0]);
    double m1 = 0, m2 = 0;
    const int n = 64;
    for (int i = 0; i < n; ++i)
    {
      for (int j = 0; j < n; ++j)
      {
        const Vec3 d = Vec3(-0.15 + 0.3 * (i + 0.5) / n, -0.15 + 0.3 * (j + 0.5) / n, 0.3) - point;
        const double r2 = dot(d, d);
        const double v = power.r * (d.z / std::sqrt(r2)) * (d.z / std::sqrt(r2)) / (M_PI * r2);
        m1 += v / (n * n);
        m2 += v * v / (n * n);
      }
    }
    const double sigma = std::sqrt(m2 - m1 * m1) / std::sqrt(64.0);
    double squares = 0;
    for (std::uint64_t seed = 1; seed <= 8; ++seed)
    {
      SolverOptions options = quick();
      options.seed = seed;
      const SensorSolution result =
        solveSensors(scene, rig, solution, oneSensor(point, up), options, counts);
      const double error = result.irradiance(0, 0).r - exact;
      squares += error * error / 8;
    }
    EXPECT_LT(std::sqrt(squares), 0.3 * sigma)
      << "x = " << x << ", sigma " << sigma / exact << ", rms " << std::sqrt(squares) / exact;
    EXPECT_GT(sigma, 0.02 * exact) << "independent points would be visibly noisy";
  }
}

TEST(Sensors, TheStatisticsCountEveryRayCast)
{
  // One sensor faces up under every kind of light, one faces down and sees none of them: the
  // shadow rays are the lights' frames (and samples) that reach the upward sensor's side.
  const Scene scene = ground(3);
  LightRig rig;
  const std::vector<Vec3> sun = { sunDirection(30, 0), sunDirection(50, 90), sunDirection(70, 0) };
  // Off in the middle frame: no ray there.
  rig.directionalLights.emplace_back(sun, Rgb(500), std::vector<Rgb>{ Rgb(1), Rgb(0), Rgb(1) });
  rig.skies.emplace_back(
    SkyModel::Uniform, Vec3(0, 0, 1), std::vector<SkyFrame>(3, SkyFrame{ { 0, 0, 1 }, 100, 0 }));
  std::vector<LightPose> poses(3);
  for (LightPose& pose : poses)
  {
    pose.position = { 0.5, 0, 2 };
  }
  rig.pointLights.emplace_back(Rgb(50), poses);
  rig.areaLights.emplace_back(
    scenes::squareLightFacingDown({ 0, 0, 2 }, 0.5), Rgb(20), std::vector<Vec3>(3, Vec3(0, 0, 0)));
  const Solution solution = solve(scene, rig, quick());
  SensorSet sensors = oneSensor({ 0.1, 0.2, 0.5 }, { 0, 0, 1 });
  sensors.points.push_back({ -0.3, 0.1, 0.5 });
  sensors.normals.push_back({ 0, 0, -1 });
  SensorOptions counts;
  counts.hemisphereRays = 37;
  counts.areaLightSamples = 5;
  const SensorSolution result = solveSensors(scene, rig, solution, sensors, quick(), counts);
  const std::uint64_t frames = 3;
  EXPECT_EQ(result.statistics().gatheringRays, 2u * counts.hemisphereRays);
  EXPECT_EQ(result.statistics().shadowRays,
    (frames - 1) /* sun */ + frames /* point light */ + frames * counts.areaLightSamples);
  EXPECT_GE(result.statistics().seconds, 0.0);
  // Nothing to cast without sensors.
  EXPECT_EQ(solveSensors(scene, rig, solution, {}, quick(), counts).statistics().shadowRays, 0u);
}

namespace
{
/// A closed room with a light below its ceiling, and a grid of work-plane sensors.
struct RoomCase
{
  PolygonSoup soup;
  LightRig rig;
  SensorSet sensors;
};

RoomCase room(std::size_t frames = 3)
{
  RoomCase c;
  c.soup =
    scenes::boxOfQuads({ 0, 0, 0 }, { 3, 2, 2.5 }, std::vector<Rgb>(6, Rgb(0.6, 0.5, 0.4)), true);
  c.rig.areaLights.emplace_back(scenes::squareLightFacingDown({ 1.5, 1, 2.4 }, 0.4), Rgb(200),
    scenes::translationsAlong({ 1.5, 1, 2.4 }, { 0.8, 0.6, 2.4 }, { 2.2, 1.4, 2.3 }, frames));
  for (int i = 0; i < 4; ++i)
  {
    for (int j = 0; j < 3; ++j)
    {
      c.sensors.points.push_back({ 0.4 + 0.7 * i, 0.4 + 0.6 * j, 0.8 });
      c.sensors.normals.push_back({ 0, 0, 1 });
    }
  }
  return c;
}

AnimationOptions roomOptions(int threads, const SensorSet& sensors)
{
  AnimationOptions options;
  options.remeshing.targetEdgeLength = 0.5;
  options.solver = quick(20000, threads);
  options.sensors = sensors;
  options.sensorOptions.hemisphereRays = 64;
  options.sensorOptions.areaLightSamples = 8;
  return options;
}
}

TEST(Sensors, SensorsDoNotChangeTheSurfacesRadiosityBitForBit)
{
  RoomCase c = room();
  Animation without = solveAnimation(c.soup, c.rig, roomOptions(2, {}));
  Animation with = solveAnimation(c.soup, c.rig, roomOptions(2, c.sensors));
  EXPECT_EQ(without.sensors.sensorCount(), 0u);
  ASSERT_EQ(with.sensors.sensorCount(), c.sensors.size());
  EXPECT_TRUE(sameBits(without.solution.patchData(), with.solution.patchData()));
  EXPECT_TRUE(sameBits(without.solution.directData(), with.solution.directData()));
  EXPECT_TRUE(sameBits(without.solution.indirectData(), with.solution.indirectData()));
  // And the sensors read light: the direct part of the lamp at least.
  for (std::size_t s = 0; s < c.sensors.size(); ++s)
  {
    for (std::size_t f = 0; f < 3; ++f)
    {
      EXPECT_GT(with.sensors.irradiance(f, s).r, 0.0);
    }
  }
}

TEST(Sensors, TheThreadCountDoesNotChangeTheResultBitForBit)
{
  RoomCase c = room();
  // A sun and a sky over the room's open top too: every estimator runs.
  c.soup = scenes::boxOfQuads({ 0, 0, 0 }, { 3, 2, 2.5 }, std::vector<Rgb>(6, Rgb(0.6)), true);
  c.soup.polygons.pop_back(); // no ceiling
  c.soup.materials.pop_back();
  c.rig.directionalLights.emplace_back(
    std::vector<Vec3>{ sunDirection(70, 0), sunDirection(60, 30), sunDirection(50, 60) }, Rgb(500));
  c.rig.skies.emplace_back(SkyModel::CieOvercast, Vec3(0, 0, 1),
    std::vector<SkyFrame>{ { {}, 100, 0 }, { {}, 120, 0 }, { {}, 90, 0 } });
  LightPose lamp;
  lamp.position = { 1, 1, 2 };
  c.rig.pointLights.emplace_back(Rgb(50), std::vector<LightPose>{ lamp });
  const Animation one = solveAnimation(c.soup, c.rig, roomOptions(1, c.sensors));
  const Animation three = solveAnimation(c.soup, c.rig, roomOptions(3, c.sensors));
  SensorSolution a = one.sensors, b = three.sensors;
  EXPECT_TRUE(sameBits(a.irradianceData(), b.irradianceData()));
  EXPECT_TRUE(sameBits(a.sunData(), b.sunData()));
  double sun = 0;
  for (std::size_t s = 0; s < c.sensors.size(); ++s)
  {
    sun += a.sunIrradiance(0, s).r;
  }
  EXPECT_GT(sun, 0.0) << "some sensors see the sun";
}

TEST(Sensors, AnyBudgetGivesTheSameBits)
{
  // Seven frames of a moving sun, a changing and a fixed sky, a lamp and a moving area light over
  // 42 sensors facing every way: read a frame at a time, in groups of 16 sensors, every frame
  // of every sensor still sums its rays in the same order.
  RoomCase c = room(7);
  c.soup = scenes::boxOfQuads({ 0, 0, 0 }, { 3, 2, 2.5 }, std::vector<Rgb>(6, Rgb(0.6)), true);
  c.soup.polygons.pop_back(); // no ceiling
  c.soup.materials.pop_back();
  std::vector<Vec3> suns;
  std::vector<SkyFrame> skies;
  for (int f = 0; f < 7; ++f)
  {
    suns.push_back(sunDirection(70 - 5 * f, 10 * f));
    skies.push_back({ suns.back(), 100.0 + 7 * f, 0 });
  }
  c.rig.directionalLights.emplace_back(suns, Rgb(500));
  // A clear sky brightest about its moving sun: its shape changes from frame to frame.
  c.rig.skies.emplace_back(SkyModel::CieClear, Vec3(0, 0, 1), skies);
  c.rig.skies.emplace_back(
    SkyModel::CieOvercast, Vec3(0, 0, 1), std::vector<SkyFrame>{ { {}, 30, 0 } });
  LightPose lamp;
  lamp.position = { 1, 1, 2 };
  c.rig.pointLights.emplace_back(Rgb(50), std::vector<LightPose>{ lamp });
  for (int i = 0; i < 30; ++i)
  {
    c.sensors.points.push_back({ 0.1 + 0.09 * i, 0.2 + 0.05 * i, 0.3 + 0.05 * (i % 5) });
    c.sensors.normals.push_back({ std::sin(i * 0.3), std::cos(i * 0.2), 0.5 });
  }
  const Animation a = solveAnimation(c.soup, c.rig, roomOptions(2, {}));
  const AnimationOptions options = roomOptions(2, c.sensors);
  SensorSolution whole =
    solveSensors(a.scene, c.rig, a.solution, c.sensors, options.solver, options.sensorOptions);
  // A frame at a time (the table's one frame) in groups of 16 sensors, and blocks of 3, 3
  // and 1 frames.
  SensorBudget tight, threes;
  tight.tableBytes = 1;
  tight.hemisphereBytes = 1;
  threes.framesPerBlock = 3;
  for (const SensorBudget& budget : { tight, threes })
  {
    std::vector<double> shares;
    SensorSolution pieces = solveSensors(
      a.scene, c.rig, a.solution, c.sensors, options.solver, options.sensorOptions,
      [&](double share)
      {
        shares.push_back(share);
        return true;
      },
      nullptr, budget);
    EXPECT_TRUE(sameBits(whole.irradianceData(), pieces.irradianceData()));
    EXPECT_TRUE(sameBits(whole.sunData(), pieces.sunData()));
    EXPECT_TRUE(sameBits(whole.stdErrorData(), pieces.stdErrorData()));
    EXPECT_EQ(whole.statistics().shadowRays, pieces.statistics().shadowRays);
    EXPECT_EQ(whole.statistics().gatheringRays, pieces.statistics().gatheringRays);
    ASSERT_FALSE(shares.empty());
    EXPECT_TRUE(std::is_sorted(shares.begin(), shares.end()));
    EXPECT_GE(shares.front(), 0.0);
    EXPECT_EQ(shares.back(), 1.0);
  }
  double gathered = 0;
  for (std::size_t s = 0; s < c.sensors.size(); ++s)
  {
    gathered += whole.irradiance(6, s).g;
  }
  EXPECT_GT(gathered, 0.0);
}

namespace
{
/**
 * The root mean square of errors over that of the standard errors reported with them, which
 * is 1 when the standard errors are right. Over n independent draws the RMS of normal errors
 * over their deviation has a relative deviation of about 1/sqrt(2n): the ratio must be within
 * 3/sqrt(2n) of 1, with n the seeds (values of one seed may share their errors, so the seeds
 * are the independent draws that can be counted on).
 */
struct ErrorRatio
{
  double squares = 0, stdErrorSquares = 0;

  void add(double error, double stdError)
  {
    EXPECT_TRUE(std::isfinite(stdError) && stdError >= 0) << stdError;
    squares += error * error;
    stdErrorSquares += stdError * stdError;
  }
  double ratio() const { return std::sqrt(squares / stdErrorSquares); }
  static double tolerance(int seeds) { return 3 / std::sqrt(2.0 * seeds); }
};
}

TEST(Sensors, TheStandardErrorMatchesTheErrorInAGlowingBox)
{
  // A closed box whose walls all emit M and reflect rho: the radiosity is M / (1 - rho)
  // everywhere, and so is the irradiance at any point inside, facing any way. A sensor gets M
  // from its points on the walls (emitters sampled as area lights: stratified, half of them
  // behind it) and rho M / (1 - rho) from the walls' solution through its hemisphere rays.
  // This test is about the solution's part (the sensors' own sampling alone is tested under
  // the sky and the lamp below): at 5,000 paths in 16 batches, with 4,096 rays and 16,384
  // points making the sensors' own noise small, the solution's noise is about 90% of the
  // error's variance. Left out, the standard error would be about 3 times too small (2.7 to
  // 3.7 over seed sets), far outside the tolerance; with 512 rays and 4,096 points it was
  // 1.3 to 1.9, often within it.
  const Rgb rho(0.3, 0.5, 0.7), emission(10);
  PolygonSoup soup = scenes::boxOfQuads({ 0, 0, 0 }, { 2, 2, 2 }, std::vector<Rgb>(6, rho), true);
  for (Material& m : soup.materials)
  {
    m.emission = emission;
  }
  SensorSet sensors;
  const std::vector<std::pair<Vec3, Vec3>> placed = { { { 1, 1, 1 }, { 0, 0, 1 } },
    { { 0.3, 0.4, 0.2 }, { 1, 1, 1 } }, { { 1.7, 0.5, 1.5 }, { -1, 0, 0 } },
    { { 0.5, 1.6, 0.9 }, { 0, -1, 0.3 } }, { { 1.2, 1.8, 0.3 }, { 0, 0, -1 } },
    { { 0.2, 0.2, 1.8 }, { 1, 0, 0 } } };
  for (const auto& [point, normal] : placed)
  {
    sensors.points.push_back(point);
    sensors.normals.push_back(normal);
  }
  const int seeds = 20;
  ErrorRatio all, ownOnly;
  for (int seed = 1; seed <= seeds; ++seed)
  {
    AnimationOptions options;
    options.remeshing.targetEdgeLength = 0.25;
    options.solver.pathsPerFrame = 5000;
    options.solver.errorBatches = 16;
    options.solver.seed = static_cast<std::uint64_t>(seed);
    options.sensors = sensors;
    options.sensorOptions.hemisphereRays = 4096;
    options.sensorOptions.areaLightSamples = 16384;
    const Animation a = solveAnimation(soup, LightRig(), options);
    ASSERT_EQ(a.sensors.frameCount(), 1u);
    EXPECT_EQ(a.sensors.solutionBatches(), 16u);
    // The same sensors without the solution's part, for comparison.
    const SensorSolution own =
      solveSensors(a.scene, LightRig(), a.solution, sensors, options.solver, options.sensorOptions);
    EXPECT_EQ(own.solutionBatches(), 0u);
    for (std::size_t i = 0; i < sensors.size(); ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        const double error = a.sensors.irradiance(0, i)[c] - emission[c] / (1 - rho[c]);
        all.add(error, a.sensors.irradianceStdError(0, i)[c]);
        ownOnly.add(error, own.irradianceStdError(0, i)[c]);
        EXPECT_LE(own.irradianceStdError(0, i)[c], a.sensors.irradianceStdError(0, i)[c]);
      }
    }
  }
  std::printf("glowing box: RMS error / RMS standard error %.3f (without the solution's part "
              "%.3f), tolerance %.3f\n",
    all.ratio(), ownOnly.ratio(), ErrorRatio::tolerance(seeds));
  EXPECT_NEAR(all.ratio(), 1.0, ErrorRatio::tolerance(seeds));
  // The test's power: the sensors' own part alone must be wrong by more than twice the
  // tolerance, or a standard error without the solution's part could pass the check above.
  EXPECT_GT(ownOnly.ratio(), 1.0 + 2 * ErrorRatio::tolerance(seeds));
}

TEST(Sensors, TheOwnSamplingErrorMatchesTheErrorUnderASkyAndALamp)
{
  // Without batches the standard error is the sensor's own sampling alone, and nothing here
  // reflects into the sensors: on open ground under a CIE clear sky an upward sensor reads
  // E_dh through its hemisphere rays (the sky's radiance varies, so they have noise), and
  // over a black floor the 64 stratified points on a lamp give Lambert's form factor (noise
  // that independent points would overstate several times).
  const int seeds = 20;
  {
    const Scene scene = ground(3);
    const std::vector<SkyFrame> frames = { { sunDirection(25, 10), 80, 300 },
      { sunDirection(60, 140), 150, 700 } };
    LightRig rig;
    rig.skies.emplace_back(SkyModel::CieClear, Vec3(0, 0, 1), frames);
    const Solution solution = solve(scene, rig, quick());
    SensorSet sensors = oneSensor({ 0.1, -0.2, 0.8 }, { 0, 0, 1 });
    sensors.points.push_back({ -0.5, 0.4, 1.5 });
    sensors.normals.push_back({ 0, 0, 1 });
    SensorOptions counts;
    counts.hemisphereRays = 256;
    ErrorRatio sky;
    for (int seed = 1; seed <= seeds; ++seed)
    {
      SolverOptions options = quick();
      options.seed = static_cast<std::uint64_t>(seed);
      const SensorSolution result = solveSensors(scene, rig, solution, sensors, options, counts);
      for (std::size_t i = 0; i < sensors.size(); ++i)
      {
        for (std::size_t f = 0; f < frames.size(); ++f)
        {
          sky.add(result.irradiance(f, i).g - frames[f].diffuseHorizontal,
            result.irradianceStdError(f, i).g);
        }
      }
    }
    std::printf("sky: RMS error / RMS standard error %.3f\n", sky.ratio());
    EXPECT_NEAR(sky.ratio(), 1.0, ErrorRatio::tolerance(seeds));
  }
  {
    const Scene scene = ground(2, Rgb(0.0));
    const std::vector<std::vector<Vec3>> lamp = scenes::squareLightFacingDown({ 0, 0, 0.3 }, 0.3);
    const std::vector<Vec3> moves = { { 0, 0, 0 }, { 0.1, 0.05, 0 }, { 0.3, 0.1, 0.1 } };
    LightRig rig;
    rig.areaLights.emplace_back(lamp, Rgb(10), moves);
    const Solution solution = solve(scene, rig, quick());
    SensorSet sensors;
    for (const double x : { 0.0, 0.2, 0.4, 0.8, 1.5 })
    {
      sensors.points.push_back({ x, 0.05, 0 });
      sensors.normals.push_back({ 0, 0, 1 });
    }
    SensorOptions counts;
    counts.areaLightSamples = 64;
    ErrorRatio lit;
    for (int seed = 1; seed <= seeds; ++seed)
    {
      SolverOptions options = quick();
      options.seed = static_cast<std::uint64_t>(seed);
      const SensorSolution result = solveSensors(scene, rig, solution, sensors, options, counts);
      for (std::size_t i = 0; i < sensors.size(); ++i)
      {
        for (std::size_t f = 0; f < moves.size(); ++f)
        {
          std::vector<Vec3> polygon = lamp[0];
          for (Vec3& v : polygon)
          {
            v += moves[f];
          }
          const double exact =
            10 / 0.09 * pointToPolygonFormFactor(sensors.points[i], sensors.normals[i], polygon);
          lit.add(result.irradiance(f, i).r - exact, result.irradianceStdError(f, i).r);
        }
      }
    }
    std::printf("lamp: RMS error / RMS standard error %.3f\n", lit.ratio());
    EXPECT_NEAR(lit.ratio(), 1.0, ErrorRatio::tolerance(seeds));
  }
}

TEST(Sensors, TheStandardErrorIsTheSameForAnyThreadCountWholeOrInChunks)
{
  // The room of the tests above with its lamp moving over 3 frames, in 4 batches: the
  // sensors read every batch, which changes no bit of the surfaces', and their standard
  // errors do not depend on the threads, whole or in chunks of 2 frames.
  RoomCase c = room();
  for (const std::uint64_t framesPerChunk : { 0, 2 })
  {
    AnimationOptions one = roomOptions(1, c.sensors), three = roomOptions(3, c.sensors);
    AnimationOptions none = roomOptions(2, {});
    for (AnimationOptions* options : { &one, &three, &none })
    {
      options->solver.errorBatches = 4;
      options->solver.framesPerChunk = framesPerChunk;
    }
    const Animation a = solveAnimation(c.soup, c.rig, one);
    const Animation b = solveAnimation(c.soup, c.rig, three);
    const Animation without = solveAnimation(c.soup, c.rig, none);
    EXPECT_EQ(a.solution.statistics.chunks, framesPerChunk == 0 ? 1u : 2u);
    SensorSolution sa = a.sensors, sb = b.sensors;
    EXPECT_TRUE(sameBits(sa.irradianceData(), sb.irradianceData()));
    EXPECT_TRUE(sameBits(sa.stdErrorData(), sb.stdErrorData()));
    EXPECT_EQ(sa.solutionBatches(), 4u);
    Solution with = a.solution, alone = without.solution;
    EXPECT_TRUE(sameBits(with.directData(), alone.directData()));
    EXPECT_TRUE(sameBits(with.indirectData(), alone.indirectData()));
    EXPECT_TRUE(sameBits(with.stdErrorData(), alone.stdErrorData()));
    for (std::size_t s = 0; s < c.sensors.size(); ++s)
    {
      for (std::size_t f = 0; f < 3; ++f)
      {
        const Rgb e = sa.irradianceStdError(f, s);
        EXPECT_TRUE(std::isfinite(e.sum()) && e.r > 0 && e.g > 0 && e.b > 0)
          << "sensor " << s << ", frame " << f << ", chunks of " << framesPerChunk;
        EXPECT_LT(e.g, 0.5 * sa.irradiance(f, s).g);
      }
      const FrameError figures = sensorFrameError(sa, 1);
      EXPECT_EQ(figures.litElements, c.sensors.size());
      EXPECT_GT(figures.median, 0.0);
      EXPECT_LE(figures.median, figures.p95);
    }
  }
}

TEST(Sensors, TheStandardErrorFollowsTheChunksOverlap)
{
  // 8 frames in chunks of 4 overlapping by 2 (the default would be 1): the sensors' reads of
  // the batches are blended over the same seams as the surfaces, the same bits for 1 and 3
  // threads, and every frame, the blended ones too, has an error of its own.
  RoomCase c = room(8);
  AnimationOptions one = roomOptions(1, c.sensors), three = roomOptions(3, c.sensors);
  for (AnimationOptions* options : { &one, &three })
  {
    options->solver.errorBatches = 4;
    options->solver.framesPerChunk = 4;
    options->solver.chunkOverlap = 2;
  }
  const Animation a = solveAnimation(c.soup, c.rig, one);
  const Animation b = solveAnimation(c.soup, c.rig, three);
  EXPECT_EQ(a.solution.statistics.chunks, 2u);
  EXPECT_EQ(a.solution.statistics.chunkOverlap, 2u);
  SensorSolution sa = a.sensors, sb = b.sensors;
  EXPECT_TRUE(sameBits(sa.irradianceData(), sb.irradianceData()));
  EXPECT_TRUE(sameBits(sa.stdErrorData(), sb.stdErrorData()));
  for (std::size_t s = 0; s < c.sensors.size(); ++s)
  {
    for (std::size_t f = 0; f < 8; ++f)
    {
      const Rgb e = sa.irradianceStdError(f, s);
      EXPECT_TRUE(std::isfinite(e.sum()) && e.g > 0) << "sensor " << s << ", frame " << f;
      EXPECT_LT(e.g, 0.5 * sa.irradiance(f, s).g) << "sensor " << s << ", frame " << f;
    }
  }
}

TEST(Sensors, DaylightMetricsOfHandCheckedSeries)
{
  const double constant[4] = { 500, 500, 500, 500 }, none[4] = { 0, 0, 0, 0 };
  DaylightMetrics m = daylightMetrics(constant, none, 4, 300, 1);
  EXPECT_EQ(m.autonomy, 1.0);
  EXPECT_EQ(m.udiUseful, 1.0);
  EXPECT_EQ(m.udiLow, 0.0);
  EXPECT_EQ(m.udiHigh, 0.0);
  EXPECT_EQ(m.directSunHours, 0.0);

  const double series[5] = { 50, 150, 300, 2500, 10000 };
  const double sun[5] = { 0, 0, 0, 1500, 9000 };
  m = daylightMetrics(series, sun, 5, 300, 0.5);
  EXPECT_DOUBLE_EQ(m.autonomy, 3.0 / 5);
  EXPECT_DOUBLE_EQ(m.udiLow, 1.0 / 5);
  EXPECT_DOUBLE_EQ(m.udiUseful, 2.0 / 5);
  EXPECT_DOUBLE_EQ(m.udiHigh, 2.0 / 5);
  EXPECT_DOUBLE_EQ(m.directSunHours, 1.0);
  EXPECT_DOUBLE_EQ(m.udiLow + m.udiUseful + m.udiHigh, 1.0);
  m = daylightMetrics(series, sun, 5, 3000, 1);
  EXPECT_DOUBLE_EQ(m.autonomy, 1.0 / 5);

  EXPECT_EQ(hoursPerTimeStep({ 7.5 }), 1.0);
  EXPECT_EQ(hoursPerTimeStep({ 8, 9, 10, 32, 33, 34 }), 1.0) << "a night skipped";
  EXPECT_EQ(hoursPerTimeStep({ 12, 12.25, 12.5, 12.75 }), 0.25);
  expectError([&] { daylightMetrics(series, sun, 5, -1, 1); }, "threshold");
  expectError([&] { daylightMetrics(series, sun, 5, std::numeric_limits<double>::quiet_NaN(), 1); },
    "threshold");
}

TEST(Sensors, BadSensorsAreRefusedByName)
{
  const double nan = std::numeric_limits<double>::quiet_NaN();
  SensorSet noNormals;
  noNormals.points = { { 0, 0, 1 } };
  expectError([&] { checkSensors(noNormals); }, "Normals");
  expectError([&] { checkSensors(oneSensor({ nan, 0, 1 }, { 0, 0, 1 })); }, "sensor 0");
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1e20 }, { 0, 0, 1 })); }, "finite");
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 0 })); }, "zero");
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1 }, { 0, nan, 1 })); }, "normal");
  SensorSet two = oneSensor({ 0, 0, 1 }, { 0, 0, 1 });
  two.points.push_back({ 1, 0, 1 });
  two.normals.push_back({ 0, 0, 0 });
  expectError([&] { checkSensors(two); }, "sensor 1");
  SensorOptions none;
  none.hemisphereRays = 0;
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 1 }), none); }, "hemisphere rays");
  SensorOptions few;
  few.hemisphereRays = MinimumHemisphereRays - 1;
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 1 }), few); }, "give 16 to");
  few.hemisphereRays = MinimumHemisphereRays;
  EXPECT_NO_THROW(checkSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 1 }), few));
  SensorOptions many;
  many.areaLightSamples = MaximumSensorRays + 1;
  expectError([&] { checkSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 1 }), many); }, "area light");
  // A unit normal of any length.
  EXPECT_NEAR(normalizedSensors(oneSensor({ 0, 0, 1 }, { 0, 0, 1e300 })).normals[0].z, 1.0, 1e-15);
  // Refused before remeshing, through the animation's entry point.
  RoomCase c = room();
  c.sensors.normals[5] = { 0, 0, 0 };
  expectError([&] { solveAnimation(c.soup, c.rig, roomOptions(1, c.sensors)); }, "sensor 5");
  // A sensor set too large for the memory limit is refused by the one memory check.
  RoomCase big = room();
  AnimationOptions options = roomOptions(1, big.sensors);
  options.outputBytesPerSensorFrame = std::uint64_t(1) << 40;
  expectError([&] { solveAnimation(big.soup, big.rig, options); }, "memory");
}

TEST(Sensors, ReadingABatchAsksWhetherToGoOn)
{
  // The sensors read every batch between the batches' progress calls (a year over a thousand
  // sensors reads for seconds): they ask again with the last fraction reported, and stop
  // there when told to.
  RoomCase c = room();
  AnimationOptions options = roomOptions(2, c.sensors);
  options.solver.errorBatches = 4;
  bool stop = false;
  std::vector<double> before, after;
  options.solver.batchSolved = [&](std::uint64_t, std::size_t, const Solution&) { stop = true; };
  EXPECT_THROW(solveAnimation(c.soup, c.rig, options,
                 [&](double f)
                 {
                   (stop ? after : before).push_back(f);
                   return !stop;
                 }),
    Cancelled);
  ASSERT_FALSE(before.empty());
  ASSERT_EQ(after.size(), 1u);
  EXPECT_EQ(after.front(), before.back());
}
