// The sun: a directional light whose direction and irradiance change per frame.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

using namespace mlr;
using mlr::checks::expectError;
using mlr::checks::modeOptions;
using mlr::checks::SeedMoments;

namespace
{
constexpr double Degree = M_PI / 180.0;

/// The unit direction towards a sun at `elevation` above the horizon (z up) and `azimuth`
/// from +x towards +y, both in degrees.
Vec3 sunDirection(double elevation, double azimuth)
{
  const double e = elevation * Degree, a = azimuth * Degree;
  return { std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e) };
}

LightRig sunRig(const DirectionalLight& sun)
{
  LightRig rig;
  rig.directionalLights.push_back(sun);
  return rig;
}

/// A square ground [-size/2, size/2]^2 at z = 0, facing up, cells x cells.
void addGround(PatchMesh& mesh, double size, int cells, const Rgb& rho)
{
  scenes::addGriddedQuad(
    mesh, { -size / 2, -size / 2, 0 }, { size, 0, 0 }, { 0, size, 0 }, cells, cells, rho);
}

/// 2D convex hull (Andrew's monotone chain) of the points' x and y, counter-clockwise.
std::vector<Vec3> convexHull(std::vector<Vec3> points)
{
  std::sort(points.begin(), points.end(),
    [](const Vec3& a, const Vec3& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  auto turn = [](const Vec3& o, const Vec3& a, const Vec3& b)
  { return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x); };
  std::vector<Vec3> hull(2 * points.size());
  std::size_t k = 0;
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    while (k >= 2 && turn(hull[k - 2], hull[k - 1], points[i]) <= 0)
    {
      --k;
    }
    hull[k++] = points[i];
  }
  for (std::size_t i = points.size() - 1, lower = k + 1; i-- > 0;)
  {
    while (k >= lower && turn(hull[k - 2], hull[k - 1], points[i]) <= 0)
    {
      --k;
    }
    hull[k++] = points[i];
  }
  hull.resize(k - 1);
  return hull;
}

double polygonArea(const std::vector<Vec3>& polygon)
{
  double twice = 0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const Vec3& a = polygon[i];
    const Vec3& b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return 0.5 * std::abs(twice);
}

/// True when p lies inside the counter-clockwise convex polygon by more than `margin`.
bool insideConvex(const std::vector<Vec3>& polygon, const Vec3& p, double margin)
{
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const Vec3& a = polygon[i];
    const Vec3& b = polygon[(i + 1) % polygon.size()];
    const double cross = (b.x - a.x) * (p.y - a.y) - (b.y - a.y) * (p.x - a.x);
    if (cross / length(b - a) <= margin)
    {
      return false;
    }
  }
  return true;
}

/// The shadow of box [lo, hi] (standing on z = 0) on the ground: its corners projected along
/// the sun direction s onto z = 0, and their convex hull (the projection of a convex body).
std::vector<Vec3> boxShadow(const Vec3& lo, const Vec3& hi, const Vec3& s)
{
  std::vector<Vec3> projected;
  for (int i = 0; i < 8; ++i)
  {
    const Vec3 corner((i & 1) ? hi.x : lo.x, (i & 2) ? hi.y : lo.y, (i & 4) ? hi.z : lo.z);
    projected.push_back(corner - s * (corner.z / s.z));
  }
  return convexHull(projected);
}

/// The number of paths frame j's reuse solve starts from each direction: N split evenly over
/// the directions that shine (as the solver splits them).
std::vector<double> pathsPerDirection(const DirectionalLight& sun, std::uint64_t N)
{
  std::vector<std::size_t> active;
  for (std::size_t k = 0; k < sun.frameCount(); ++k)
  {
    if (sun.powerFactor(k).maxComponent() > 0)
    {
      active.push_back(k);
    }
  }
  std::vector<double> M(sun.frameCount(), 0.0);
  for (std::size_t a = 0; a < active.size(); ++a)
  {
    M[active[a]] = double(N / active.size() + (a < N % active.size() ? 1 : 0));
  }
  return M;
}
}

TEST(Sun, UnoccludedGroundGetsRhoTimesIrradianceTimesSineOfElevation)
{
  PatchMesh mesh;
  addGround(mesh, 1.0, 8, Rgb(0.5, 0.3, 0.7));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const double elevations[] = { 10, 30, 55, 80 };
  const double azimuths[] = { 200, 10, 120, 300 };
  std::vector<Vec3> directions;
  for (int k = 0; k < 4; ++k)
  {
    // Any length: the light normalises.
    directions.push_back(sunDirection(elevations[k], azimuths[k]) * (0.5 + k));
  }
  const Rgb irradiance(1000, 800, 600);
  const DirectionalLight sun(directions, irradiance);
  // Paths start on a disc covering the scene's bounding sphere: its radius is half the
  // bounding box's diagonal, and a path carries E pi R^2 / N.
  const double discArea = M_PI * std::pow(0.5 * scene.diagonal(), 2);
  for (bool reuse : { false, true })
  {
    SolverOptions options = modeOptions(reuse, 100000, reuse ? 41 : 40);
    // The binomial variance below is that of the equal counts pathsPerDirection gives (balanced
    // counts have a smaller one here: mean z^2 0.67 against it).
    options.balanceFrames = false;
    const Solution solution = solve(scene, sunRig(sun), options);
    const std::vector<double> M = pathsPerDirection(sun, options.pathsPerFrame);
    double sumSine = 0;
    for (std::size_t k = 0; k < 4; ++k)
    {
      sumSine += M[k] * std::sin(elevations[k] * Degree);
    }
    double meanSquare = 0, maxAbs = 0;
    std::size_t count = 0;
    for (std::size_t f = 0; f < 4; ++f)
    {
      const double sine = std::sin(elevations[f] * Degree);
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        const double area = scene.elementArea(e);
        // The hits on an element are binomial: classic, N paths hitting with probability
        // q_f = A sin(e_f) / A_disc, each scoring rho E A_disc / (N A); reuse, M_k paths from
        // every direction k, each scoring rho E A_disc / A times the weight
        // sin(e_f) / sum_k M_k sin(e_k) (nothing occludes: the weight is the same everywhere).
        double variance = 0, score = 0;
        if (reuse)
        {
          score = discArea / area * sine / sumSine;
          for (std::size_t k = 0; k < 4; ++k)
          {
            const double q = area * std::sin(elevations[k] * Degree) / discArea;
            variance += M[k] * q * (1 - q);
          }
        }
        else
        {
          score = discArea / (double(options.pathsPerFrame) * area);
          const double q = area * sine / discArea;
          variance = double(options.pathsPerFrame) * q * (1 - q);
        }
        for (int c = 0; c < 3; ++c)
        {
          const double rhoE = scene.elementReflectance(e)[c] * irradiance[c];
          const double exact = rhoE * sine;
          const double z =
            (solution.direct(f, e, Side::Front)[c] - exact) / (rhoE * score * std::sqrt(variance));
          meanSquare += z * z;
          maxAbs = std::max(maxAbs, std::abs(z));
          ++count;
          EXPECT_EQ(solution.direct(f, e, Side::Back)[c], 0.0) << "the ground's underside is dark";
          EXPECT_EQ(solution.indirect(f, e, Side::Front)[c], 0.0)
            << "a lone plane reflects nothing onto itself";
        }
      }
    }
    meanSquare /= double(count);
    std::cout << (reuse ? "full reuse" : "classic") << ": mean z^2 " << meanSquare << ", max |z| "
              << maxAbs << " over " << count << "\n";
    // The scores are standard (binomial counts of 20 to 120 hits): their mean square is 1
    // within sqrt(2.05 / (count / 3)) = 0.03 (the channels share their hits).
    EXPECT_NEAR(meanSquare, 1.0, 0.15) << (reuse ? "full reuse" : "classic");
    EXPECT_LT(maxAbs, 5.5) << (reuse ? "full reuse" : "classic");
  }
}

TEST(Sun, BoxBuildingCastsItsProjectedShadow)
{
  const double groundSize = 6;
  const Vec3 lo(-0.5, -0.5, 0), hi(0.5, 0.5, 1);
  const Rgb groundRho(0.5, 0.3, 0.7);
  PatchMesh mesh;
  addGround(mesh, groundSize, 24, groundRho);
  const std::size_t groundElements = mesh.triangles.size() * Scene::ElementsPerPatch;
  scenes::addBox(mesh, lo, hi, 0.25, false, { Rgb(0.6) }, true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::vector<Vec3> directions = { sunDirection(35, 30), sunDirection(50, 160),
    sunDirection(70, 260) };
  const Rgb irradiance(1000, 900, 700);
  const DirectionalLight sun(directions, irradiance);
  const double discArea = M_PI * std::pow(0.5 * scene.diagonal(), 2);
  for (bool reuse : { false, true })
  {
    const std::string mode = reuse ? "full reuse" : "classic";
    const SolverOptions options = modeOptions(reuse, 200000, 7);
    const Solution solution = solve(scene, sunRig(sun), options);
    const double N = double(options.pathsPerFrame);
    const double M = N / double(directions.size());
    for (std::size_t f = 0; f < directions.size(); ++f)
    {
      const Vec3& s = directions[f];
      const std::vector<Vec3> shadow = boxShadow(lo, hi, s);
      const double litArea = groundSize * groundSize - polygonArea(shadow);
      Rgb power;
      std::size_t shadowed = 0;
      for (std::size_t e = 0; e < groundElements; ++e)
      {
        power += solution.direct(f, e, Side::Front) * scene.elementArea(e);
        const Triangle& t = scene.elementTriangles()[e];
        bool inShadow = true;
        for (std::uint32_t v : t)
        {
          inShadow = inShadow && insideConvex(shadow, scene.points()[v], 1e-6);
        }
        if (inShadow)
        {
          ++shadowed;
          EXPECT_EQ(solution.direct(f, e, Side::Front), Rgb())
            << mode << " frame " << f << " element " << e;
        }
      }
      EXPECT_GT(shadowed, 50u);
      // A path that reaches the lit ground scores rho E A_disc / N; q of them do, binomially.
      // With reuse a path scores at most 1/M_f of rho E A_disc in frame f (its weight), so
      // the variance is at most (rho E A_disc)^2 q / M_f: sigma is that bound.
      const double q = s.z * litArea / discArea;
      const double relativeSigma =
        reuse ? std::sqrt(q / M) / q : std::sqrt(N * q * (1 - q)) / (N * q);
      for (int c = 0; c < 3; ++c)
      {
        const double exact = groundRho[c] * irradiance[c] * s.z * litArea;
        EXPECT_NEAR(power[c] / exact, 1.0, 4 * relativeSigma)
          << mode << " frame " << f << " channel " << c << ": shadow area " << polygonArea(shadow);
      }
      std::cout << mode << " frame " << f << ": ground direct power / exact "
                << power.g / (groundRho.g * irradiance.g * s.z * litArea) << ", sigma "
                << relativeSigma << ", shadow " << polygonArea(shadow) << " m^2, " << shadowed
                << " elements fully in it\n";
    }
  }
}

TEST(Sun, ReuseMatchesClassicInEveryFrame)
{
  PatchMesh mesh;
  addGround(mesh, 4, 8, Rgb(0.5, 0.4, 0.3));
  const std::size_t groundElements = mesh.triangles.size() * Scene::ElementsPerPatch;
  scenes::addBox(mesh, { -0.5, -0.5, 0 }, { 0.5, 0.5, 1 }, 0.5, false,
    { Rgb(0.7, 0.2, 0.2), Rgb(0.2, 0.7, 0.2), Rgb(0.6), Rgb(0.4), Rgb(0.5), Rgb(0.6, 0.6, 0.2) },
    true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  // Groups: the ground, then the box's walls -x, +x, -y, +y and its roof, 8 patches each.
  const std::size_t faceElements = 8 * Scene::ElementsPerPatch;
  ASSERT_EQ(scene.elementCount(), groundElements + 5 * faceElements);
  auto groupOf = [&](std::size_t e)
  { return e < groundElements ? 0 : 1 + (e - groundElements) / faceElements; };
  const DirectionalLight sun(
    { sunDirection(20, 0), sunDirection(45, 60), sunDirection(65, 150), sunDirection(30, 230) },
    Rgb(1000), { Rgb(1), Rgb(0.8, 0.9, 1), Rgb(1), Rgb(0.5) });
  constexpr int runs = 20;
  SeedMoments moments[2];
  for (int mode = 0; mode < 2; ++mode)
  {
    for (int r = 0; r < runs; ++r)
    {
      const Solution solution =
        solve(scene, sunRig(sun), modeOptions(mode == 1, 4000, 700 + r + 100 * mode));
      moments[mode].add(checks::groupPowers(scene, solution, 6, groupOf, 1));
    }
  }
  const double chiSquare =
    checks::expectSameMeans(moments[1], { &moments[0] }, "reuse against classic");
  std::cout << "mean z^2 over 6 groups x 4 frames: " << chiSquare << "\n";
}

TEST(Sun, NightFrameIsDarkAndCastsNothing)
{
  PatchMesh mesh;
  addGround(mesh, 4, 6, Rgb(0.5));
  scenes::addBox(mesh, { -0.5, -0.5, 0 }, { 0.5, 0.5, 1 }, 0.5, false, { Rgb(0.6) }, true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  const Vec3 morning = sunDirection(25, 80), noon = sunDirection(60, 180),
             evening = sunDirection(20, 280);
  const DirectionalLight withNight(
    { morning, noon, evening }, Rgb(900), { Rgb(1), Rgb(0), Rgb(0.5, 1, 1) });
  const DirectionalLight dayOnly({ morning, evening }, Rgb(900), { Rgb(1), Rgb(0.5, 1, 1) });
  for (bool reuse : { false, true })
  {
    const std::string mode = reuse ? "full reuse" : "classic";
    const SolverOptions options = modeOptions(reuse, 20000, 5);
    const Solution a = solve(scene, sunRig(withNight), options);
    const Solution b = solve(scene, sunRig(dayOnly), options);
    EXPECT_EQ(a.statistics.pathsCast, reuse ? options.pathsPerFrame : 2 * options.pathsPerFrame)
      << mode;
    EXPECT_TRUE(a.warnings.empty()) << mode;
    double day = 0;
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      for (Side side : { Side::Front, Side::Back })
      {
        EXPECT_EQ(a.total(1, e, side), Rgb()) << mode << " element " << e;
        EXPECT_EQ(a.patchRadiosity(1, Scene::patchOfElement(e), side), Rgb()) << mode;
        day += a.total(0, e, side).sum() + a.total(2, e, side).sum();
        // Classic's first frame draws the same random numbers either way (a position's paths
        // are keyed by its frame, so with reuse the evening's differ: frame 2 here, 1 there).
        if (!reuse)
        {
          EXPECT_EQ(a.total(0, e, side), b.total(0, e, side)) << mode << " element " << e;
        }
      }
    }
    EXPECT_GT(day, 0.0);
    if (reuse)
    {
      // The night takes no share of the N paths and no shadow ray goes towards it: a first
      // hit asks for the visibility of the other day position only, at most one ray.
      EXPECT_EQ(a.statistics.pathsCast, b.statistics.pathsCast);
      EXPECT_GT(a.statistics.shadowRays, 0u);
      EXPECT_LE(a.statistics.shadowRays, a.statistics.firstHits)
        << "no shadow ray towards the night";
    }
  }
}

TEST(Sun, NoSurfaceFacingTheSunGivesZeroWithAWarning)
{
  // Four walls (no roof, no floor) under a sun at the zenith and then at the nadir: every
  // ray runs parallel to every wall.
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 0, 1, 0 }, { 0, 0, 1 }, 3, 3, Rgb(0.5));
  scenes::addGriddedQuad(mesh, { 1, 0, 0 }, { 0, 0, 1 }, { 0, 1, 0 }, 3, 3, Rgb(0.5));
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 0, 0, 1 }, { 1, 0, 0 }, 3, 3, Rgb(0.5));
  scenes::addGriddedQuad(mesh, { 0, 1, 0 }, { 1, 0, 0 }, { 0, 0, 1 }, 3, 3, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const DirectionalLight sun({ { 0, 0, 1 }, { 0, 0, -2 } }, Rgb(1000));
  for (bool reuse : { false, true })
  {
    Solution solution;
    ASSERT_NO_THROW(solution = solve(scene, sunRig(sun), modeOptions(reuse, 10000, 2)));
    ASSERT_EQ(solution.warnings.size(), 1u);
    EXPECT_NE(solution.warnings[0].find("no light reached the scene"), std::string::npos)
      << solution.warnings[0];
    for (std::size_t f = 0; f < 2; ++f)
    {
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        EXPECT_EQ(solution.total(f, e, Side::Front), Rgb());
        EXPECT_EQ(solution.total(f, e, Side::Back), Rgb());
      }
    }
  }
}

TEST(Sun, BadInputIsRefusedWithWhatToFix)
{
  const double nan = std::nan("");
  const std::vector<Vec3> two = { sunDirection(30, 0), sunDirection(40, 90) };
  expectError(
    [&] {
      DirectionalLight({ sunDirection(30, 0), Vec3(0, 0, 0) }, Rgb(1000));
    },
    "direction 1 towards the light is (0, 0, 0): it must be finite and not zero");
  expectError(
    [&] { DirectionalLight({ Vec3(nan, 0, 1) }, Rgb(1000)); }, "direction 0 towards the light");
  expectError([&] { DirectionalLight({}, Rgb(1000)); }, "no direction");
  for (const Rgb& bad : { Rgb(0), Rgb(-1000), Rgb(1000, -1, 1000), Rgb(nan), Rgb(1000, nan, 1000) })
  {
    expectError([&] { DirectionalLight(two, bad); }, "irradiance");
  }
  EXPECT_NO_THROW(DirectionalLight(two, Rgb(1000, 0, 0))) << "one dark channel is fine";
  expectError(
    [&] {
      DirectionalLight(two, Rgb(1000), { Rgb(1), Rgb(-0.5) });
    },
    "power factor of direction 1");
  expectError(
    [&] {
      DirectionalLight(two, Rgb(1000), { Rgb(nan), Rgb(1) });
    },
    "power factor of direction 0");
  expectError(
    [&] { DirectionalLight(two, Rgb(1000), { Rgb(1) }); }, "2 directions but 1 power factors");

  // A sun and a moving lamp must agree on the frames; a static lamp always does.
  LightRig rig;
  rig.directionalLights.emplace_back(two, Rgb(1000));
  const auto lamp = scenes::squareLightFacingDown({ 0.5, 0.5, 1 }, 0.2);
  rig.areaLights.emplace_back(lamp, Rgb(1), std::vector<Vec3>(1));
  EXPECT_EQ(frameCount(rig, false), 2u);
  rig.areaLights.emplace_back(lamp, Rgb(1), std::vector<Vec3>(3));
  expectError(
    [&] { frameCount(rig, false); }, "directional light 0 has 2 positions but light 1 has 3");

  PatchMesh mesh;
  addGround(mesh, 1, 2, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  expectError([&]
    { solve(scene, sunRig(DirectionalLight(two, Rgb(1000))), modeOptions(true, 1, 1)); },
    "give at least 2 paths per frame");
}
