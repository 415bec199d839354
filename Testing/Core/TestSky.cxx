// The sky: its models, their normalisation to the diffuse horizontal irradiance, its paths
// from the disc around the scene, and their reuse over frames without shadow rays.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "Random.h"
#include "Sky.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <utility>

using namespace mlr;
using mlr::checks::expectError;
using mlr::checks::modeOptions;
using mlr::checks::SeedMoments;

namespace
{
constexpr double Degree = M_PI / 180.0;
constexpr double Edh = 120.0;

Vec3 sunDirection(double elevation, double azimuth)
{
  const double e = elevation * Degree, a = azimuth * Degree;
  return { std::cos(e) * std::cos(a), std::cos(e) * std::sin(a), std::sin(e) };
}

/// Midpoint quadrature over the upper hemisphere (z up), in cos(theta) and phi: uniform in
/// solid angle, fine enough that its error is far below the tests' tolerances.
double hemisphere(const std::function<double(const Vec3&)>& f, int n = 300)
{
  double sum = 0;
  for (int i = 0; i < n; ++i)
  {
    const double cz = (i + 0.5) / n, sz = std::sqrt(1 - cz * cz);
    for (int j = 0; j < 2 * n; ++j)
    {
      const double phi = (j + 0.5) * M_PI / n;
      sum += f({ sz * std::cos(phi), sz * std::sin(phi), cz });
    }
  }
  return sum * (2 * M_PI / (2.0 * n * n));
}

/// The irradiance on a surface of normal n under the continuous model of `frame`,
/// normalised to E_dh on a horizontal surface: the reference the tabulated sky must meet.
double modelIrradiance(SkyModel model, const SkyFrame& frame, const Vec3& n,
  const std::function<double(const Vec3&)>& seen = {})
{
  const SkyDistribution f(model, frame.sun, frame.diffuseHorizontal, frame.directNormal);
  const double horizontal = hemisphere([&](const Vec3& w) { return f(w) * w.z; });
  const double onSurface = hemisphere(
    [&](const Vec3& w) { return f(w) * std::max(0.0, dot(n, w)) * (seen ? seen(w) : 1.0); });
  return frame.diffuseHorizontal * onSurface / horizontal;
}

const SkyFrame ClearFrame{ sunDirection(35, 20), Edh, 0 };
const SkyFrame PerezFrame{ sunDirection(40, 200), Edh, 650 };

/// A solve's path-count tolerance for the mean direct irradiance E over surfaces of area A:
/// a path hits them with probability q = E A / (pi R^2 Lambda) and, drawn with the frame's
/// own density, always scores the same, so the hits are binomial.
double tolerance(double E, double A, const Sky& sky, const Scene& scene, std::uint64_t N)
{
  const double R = 0.5 * scene.diagonal();
  const double q = E * A / (M_PI * R * R * sky.integral(0));
  return 5 * E * std::sqrt((1 - q) / (double(N) * q)) + 1e-9;
}

/// Area-weighted mean of `value` over the elements whose front normal is close to `n`.
double meanOver(const Scene& scene, const Vec3& n, const std::function<double(std::size_t)>& value,
  double* area = nullptr)
{
  double sum = 0, a = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    if (dot(scene.elementSideNormal(e, Side::Front), n) > 0.999)
    {
      sum += scene.elementArea(e) * value(e);
      a += scene.elementArea(e);
    }
  }
  if (area)
  {
    *area = a;
  }
  return sum / a;
}

LightRig skyRig(const Sky& sky)
{
  LightRig rig;
  rig.skies.push_back(sky);
  return rig;
}
}

TEST(Sky, ModelsAndTheirNames)
{
  for (const char* name : { "uniform", "cie-overcast", "cie-clear", "perez" })
  {
    EXPECT_EQ(skyModelName(parseSkyModel(name)), name);
  }
  expectError([] { parseSkyModel("clear"); }, "uniform, cie-overcast, cie-clear or perez");
  expectError(
    [] {
      Sky(SkyModel::Uniform, { 0, 0, 1 }, { SkyFrame{ {}, -1, 0 } });
    },
    "diffuse horizontal irradiance of frame 0");
  expectError([] { Sky(SkyModel::Uniform, { 0, 0, 0 }, { SkyFrame{ {}, 1, 0 } }); }, "up");
  expectError(
    [] {
      Sky(SkyModel::Perez, { 0, 0, 1 }, { SkyFrame{ { 0, 0, 1 }, 1, -2 } });
    },
    "direct normal irradiance of frame 0");
}

TEST(Sky, CieOvercastIsOneThirdAtTheHorizonAndTheCie12GradationHolds)
{
  const SkyDistribution overcast(SkyModel::CieOvercast, { 0, 0, 1 }, 1, 0);
  EXPECT_NEAR(overcast({ 1, 0, 0 }) / overcast({ 0, 0, 1 }), 1.0 / 3, 1e-12);
  // Type 12, looking at the zenith with the sun at the zenith: phi(0) f(0) with
  // phi(0) = 1 - exp(-0.32) and f(0) = 1 + 10 (1 - exp(-3 pi / 2)) + 0.45.
  const SkyDistribution clear(SkyModel::CieClear, { 0, 0, 1 }, 1, 0);
  EXPECT_NEAR(clear({ 0, 0, 1 }),
    (1 - std::exp(-0.32)) * (1 + 10 * (1 - std::exp(-1.5 * M_PI)) + 0.45), 1e-12);
}

TEST(Sky, PerezIndicesAndEfficacyFollowGendaylit)
{
  // An overcast hour: E_dn = 0 gives clearness 1 (the first bin), whatever the sun.
  const SkyDistribution overcast(SkyModel::Perez, sunDirection(30, 0), 200, 0);
  EXPECT_DOUBLE_EQ(overcast.clearness(), 1.0);
  // A clear hour: epsilon = ((E_dh + E_dn) / E_dh + 1.041 Z^3) / (1 + 1.041 Z^3).
  const double Z = 50 * Degree, z3 = 1.041 * Z * Z * Z;
  const SkyDistribution clear(SkyModel::Perez, sunDirection(40, 0), 100, 800);
  EXPECT_NEAR(clear.clearness(), (9 + z3) / (1 + z3), 1e-12);
  EXPECT_GT(clear.brightness(), 0.01);
  EXPECT_LT(clear.brightness(), 0.6);
  const DaylightEfficacy e = perezEfficacy({ sunDirection(40, 0), 100, 800 }, { 0, 0, 1 });
  EXPECT_GT(e.diffuse, 100);
  EXPECT_LT(e.diffuse, 160);
  EXPECT_GT(e.direct, 60);
  EXPECT_LT(e.direct, 110);
}

TEST(Sky, AnHourWithDirectSunAndNoDiffuseLightIsTheClearestSky)
{
  // E_dh = 0 with E_dn > 0: epsilon's (E_dh + E_dn) / E_dh is infinite, clamped to the top
  // of the range, as in gendaylit; the direct efficacy is then that of any vanishing E_dh
  // (104 lm/W here, where the overcast bin gave 49).
  const SkyFrame noDiffuse{ sunDirection(60, 0), 0, 800 };
  EXPECT_DOUBLE_EQ(SkyDistribution(SkyModel::Perez, noDiffuse.sun, 0, 800).clearness(), 12.0);
  EXPECT_DOUBLE_EQ(perezEfficacy(noDiffuse, { 0, 0, 1 }).direct,
    perezEfficacy({ noDiffuse.sun, 1e-9, 800 }, { 0, 0, 1 }).direct);
  // Neither: no sky to speak of, the overcast bin.
  EXPECT_DOUBLE_EQ(SkyDistribution(SkyModel::Perez, noDiffuse.sun, 0, 0).clearness(), 1.0);
}

TEST(Sky, APerezSkyOfALowClearSunKeepsItsLightOffTheHorizon)
{
  // A low sun in a clear sky gives many frames a Perez gradation b > 0, whose a e^(b/cos t)
  // has no finite integral towards the horizon: the wall facing away from the sun got ten
  // times E_dh. Radiance evaluates no such sky below 6 degrees (gendaylit's 145 directions
  // start there, gendaymtx's default patches are centred there): below, the gradation may
  // depart from 1 by no more than it does at 6 degrees. That sky's quadrature, from the
  // model at 6 degrees and above only, bounds every plane (0.35 to 0.53 E_dh on the wall
  // facing away), to the table's error of 0.3 % of E_dh.
  const double s6 = std::sin(6 * Degree);
  for (double elevation : { 1.0, 3.0, 5.0, 7.0 })
  {
    for (const auto& [dhi, dni] : { std::pair{ 30.0, 300.0 }, { 100.0, 1000.0 }, { 50.0, 900.0 } })
    {
      const SkyFrame frame{ sunDirection(elevation, 200), dhi, dni, 172 };
      const SkyDistribution f(SkyModel::Perez, frame.sun, dhi, dni, 172);
      const double departure6 = std::abs(f.gradation(s6) - 1);
      auto L = [&](const Vec3& w)
      {
        const double g = f.gradation(w.z);
        return f(w, w.z < s6 ? 1 + std::clamp(g - 1, -departure6, departure6) : g);
      };
      const double horizontal = hemisphere([&](const Vec3& w) { return L(w) * w.z; }, 600);
      const Sky sky(SkyModel::Perez, { 0, 0, 1 }, { frame });
      EXPECT_NEAR(
        hemisphere([&](const Vec3& w) { return sky.radiance(0, w) * w.z; }, 600), dhi, 2e-3 * dhi);
      const Vec3 away = normalize(Vec3(-frame.sun.x, -frame.sun.y, 0));
      for (const Vec3& n :
        { away, -away, Vec3(away.y, -away.x, 0), normalize(away + Vec3(0, 0, 1)) })
      {
        auto onPlane = [&](const std::function<double(const Vec3&)>& radiance) {
          return hemisphere(
            [&](const Vec3& w) { return radiance(w) * std::max(0.0, dot(n, w)); }, 600);
        };
        const double expected = dhi * onPlane(L) / horizontal;
        EXPECT_NEAR(
          onPlane([&](const Vec3& w) { return sky.radiance(0, w); }), expected, 3e-3 * dhi)
          << "sun at " << elevation << " degrees, E_dh " << dhi << ", E_dn " << dni << ", normal "
          << n.x << "," << n.y << "," << n.z;
      }
    }
  }
}

TEST(Sky, APerezSkyNegativeEverywhereIsDrawnAsAUniformSky)
{
  // A high sun with little diffuse light and two to three times as much direct: the Perez fit
  // is negative over the whole sky. That stopped the run ("dark everywhere"), a weather year
  // at its first such hour; Radiance's gendaymtx draws such an hour as a uniform sky.
  const SkyFrame negative{ sunDirection(70, 0), 40, 100, 172 };
  const SkyFrame clear{ sunDirection(70, 0), 100, 800, 172 };
  const SkyDistribution f(SkyModel::Perez, negative.sun, 40, 100, 172);
  EXPECT_EQ(hemisphere([&](const Vec3& w) { return f(w, f.gradation(w.z)); }), 0.0);
  const Sky sky(SkyModel::Perez, { 0, 0, 1 }, { clear, negative });
  EXPECT_EQ(sky.uniformInsteadFrames(), std::vector<std::size_t>{ 1 });
  for (const Vec3& w : { Vec3(0, 0, 1), normalize(Vec3(1, 2, 0.3)), negative.sun })
  {
    EXPECT_NEAR(sky.radiance(1, w), 40 / M_PI, 1e-9);
    EXPECT_NEAR(sky.modelRadiance(1, w), 40 / M_PI, 1e-9);
  }
  EXPECT_NEAR(hemisphere([&](const Vec3& w) { return sky.radiance(1, w) * w.z; }), 40, 1e-6);
  // The other frame is the Perez sky it was.
  const Sky alone(SkyModel::Perez, { 0, 0, 1 }, { clear });
  EXPECT_EQ(sky.radiance(0, negative.sun), alone.radiance(0, negative.sun));
}

TEST(Sky, TheTableMeetsTheModelAndDrawsItsOwnDensity)
{
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const SkyFrame frame = model == SkyModel::Perez ? PerezFrame : ClearFrame;
    const Sky sky(model, { 0, 0, 1 }, { frame });
    // Horizontal: E_dh exactly, by construction; a wall: within the grid's error.
    EXPECT_NEAR(
      hemisphere([&](const Vec3& w) { return sky.radiance(0, w) * w.z; }, 600), Edh, 2e-3 * Edh);
    for (const Vec3& n : { Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, 0.6, 0.8) })
    {
      EXPECT_NEAR(
        hemisphere(
          [&](const Vec3& w) { return sky.radiance(0, w) * std::max(0.0, dot(n, w)); }, 600),
        modelIrradiance(model, frame, n), 3e-3 * Edh)
        << skyModelName(model);
    }
    // The samples fall in cells in proportion to their density.
    std::vector<double> hits(Sky::Cells, 0.0);
    const int samples = 200000;
    RandomStream random(7, StreamPurpose::Shooting, 0, 0);
    for (int i = 0; i < samples; ++i)
    {
      const Vec3 w = sky.sample(0, random.uniform(), random.uniform(), random.uniform());
      ASSERT_GT(w.z, 0);
      hits[sky.cell(w)] += 1;
    }
    // The zenith cap's ring (the first 120 cells) as one count.
    double capHits = 0, capProbability = 0;
    for (std::size_t c = 0; c < std::size_t(Sky::Sectors); ++c)
    {
      capHits += hits[c];
      capProbability +=
        sky.density(0, c) * (2 * M_PI / Sky::Sectors) * (1 - std::cos(M_PI / 2 / Sky::Rings));
    }
    EXPECT_NEAR(capHits / samples, capProbability, 5 * std::sqrt(capProbability / samples) + 1e-12)
      << skyModelName(model);
  }
}

TEST(Sky, OpenGroundGetsRhoTimesTheDiffuseHorizontalInEveryFrame)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -1, -1, 0 }, { 2, 0, 0 }, { 0, 2, 0 }, 4, 4, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::uint64_t N = 40000;
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const std::vector<SkyFrame> frames = { { sunDirection(20, 10), 80, 300 },
      { sunDirection(60, 140), 150, 700 } };
    const Sky sky(model, { 0, 0, 1 }, frames);
    ASSERT_EQ(sky.positions(), 2u);
    const Solution solution = solve(scene, skyRig(sky), modeOptions(false, N, 3));
    for (std::size_t f = 0; f < 2; ++f)
    {
      double area = 0;
      const double B = meanOver(
        scene, { 0, 0, 1 }, [&](std::size_t e) { return solution.total(f, e, Side::Front).r; },
        &area);
      const Sky one(model, { 0, 0, 1 }, { frames[f] });
      EXPECT_NEAR(B, 0.5 * frames[f].diffuseHorizontal,
        0.5 * tolerance(frames[f].diffuseHorizontal, area, one, scene, N))
        << skyModelName(model) << " frame " << f;
    }
  }
}

TEST(Sky, ALoneBlockWithNoGround)
{
  PatchMesh mesh;
  scenes::addBox(mesh, { 0, 0, 0 }, { 1, 1, 1 }, 0.5, false, std::vector<Rgb>(6, Rgb(0.5)));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::uint64_t N = 60000;
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const SkyFrame frame = model == SkyModel::Perez ? PerezFrame : ClearFrame;
    const Sky sky(model, { 0, 0, 1 }, { frame });
    ASSERT_TRUE(sky.positions() == 1);
    const Solution solution = solve(scene, skyRig(sky), modeOptions(true, N, 11));
    auto E = [&](const Vec3& n, double* area)
    {
      return meanOver(
        scene, n, [&](std::size_t e) { return solution.directIrradiance(0, e, Side::Front).r; },
        area);
    };
    double area = 0;
    const double roof = E({ 0, 0, 1 }, &area);
    EXPECT_NEAR(roof, Edh, tolerance(Edh, area, sky, scene, N)) << skyModelName(model);
    EXPECT_EQ(E({ 0, 0, -1 }, &area), 0.0) << "nothing below the horizon";
    for (const Vec3& n : { Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0) })
    {
      const double wall = E(n, &area);
      double expected = modelIrradiance(model, frame, n);
      if (model == SkyModel::Uniform)
      {
        EXPECT_NEAR(expected, Edh / 2, 1e-4 * Edh);
      }
      if (model == SkyModel::CieOvercast)
      {
        EXPECT_NEAR(expected, (M_PI / 2 + 4.0 / 3) / (7 * M_PI / 3) * Edh, 1e-4 * Edh);
        EXPECT_NEAR(expected / Edh, 0.396, 5e-4);
      }
      // The grid's error, measured in TheTableMeetsTheModel, on top of the paths' noise.
      EXPECT_NEAR(wall, expected, tolerance(expected, area, sky, scene, N) + 3e-3 * Edh)
        << skyModelName(model) << " wall " << n.x << "," << n.y;
    }
  }
}

TEST(Sky, AWellWithBlackWallsSeesTheSkyThroughItsOpening)
{
  // A floor a x a at z = 0 and black walls of height h: the floor sees the sky through the
  // opening only, a fraction overlap(w) of the floor in direction w.
  const double a = 1, h = 0.8;
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { a, 0, 0 }, { 0, a, 0 }, 2, 2, Rgb(0.5));
  const Rgb black(0.0);
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 0, 0, h }, { a, 0, 0 }, 2, 2, black);
  scenes::addGriddedQuad(mesh, { a, a, 0 }, { 0, 0, h }, { -a, 0, 0 }, 2, 2, black);
  scenes::addGriddedQuad(mesh, { 0, a, 0 }, { 0, 0, h }, { 0, -a, 0 }, 2, 2, black);
  scenes::addGriddedQuad(mesh, { a, 0, 0 }, { 0, 0, h }, { 0, a, 0 }, 2, 2, black);
  const Scene scene = Scene::fromPatchMesh(mesh);
  auto overlap = [&](const Vec3& w)
  {
    const double dx = std::abs(h * w.x / w.z), dy = std::abs(h * w.y / w.z);
    return std::max(0.0, 1 - dx / a) * std::max(0.0, 1 - dy / a);
  };
  // The configuration factor between directly opposed parallel squares.
  const double X = a / h, s = std::sqrt(1 + X * X);
  const double F = 2 / (M_PI * X * X) *
    (std::log((1 + X * X) / std::sqrt(1 + 2 * X * X)) + 2 * X * s * std::atan(X / s) -
      2 * X * std::atan(X));
  const std::uint64_t N = 80000;
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const SkyFrame frame = model == SkyModel::Perez ? PerezFrame : ClearFrame;
    const double expected = modelIrradiance(model, frame, { 0, 0, 1 }, overlap);
    if (model == SkyModel::Uniform)
    {
      EXPECT_NEAR(expected, F * Edh, 1e-3 * Edh);
    }
    const Sky sky(model, { 0, 0, 1 }, { frame });
    const Solution solution = solve(scene, skyRig(sky), modeOptions(true, N, 5));
    double area = 0;
    const double floor = meanOver(
      scene, { 0, 0, 1 },
      [&](std::size_t e) { return solution.directIrradiance(0, e, Side::Front).r; }, &area);
    EXPECT_NEAR(floor, expected, tolerance(expected, area, sky, scene, N) + 3e-3 * Edh)
      << skyModelName(model);
  }
}

TEST(Sky, AZenithAlongAnyUpIsTheSameSky)
{
  // The roof of a block under a sky whose zenith is +y gets E_dh; the +z face, a wall now,
  // gets half of it under the uniform sky.
  PatchMesh mesh;
  scenes::addBox(mesh, { 0, 0, 0 }, { 1, 1, 1 }, 0.5, false, std::vector<Rgb>(6, Rgb(0.5)));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const Sky sky(SkyModel::Uniform, { 0, 2, 0 }, { SkyFrame{ {}, Edh, 0 } });
  const std::uint64_t N = 40000;
  const Solution solution = solve(scene, skyRig(sky), modeOptions(true, N, 2));
  double area = 0;
  auto E = [&](const Vec3& n)
  {
    return meanOver(
      scene, n, [&](std::size_t e) { return solution.directIrradiance(0, e, Side::Front).r; },
      &area);
  };
  const double top = E({ 0, 1, 0 });
  EXPECT_NEAR(top, Edh, tolerance(Edh, area, sky, scene, N));
  const double side = E({ 0, 0, 1 });
  EXPECT_NEAR(side, Edh / 2, tolerance(Edh / 2, area, sky, scene, N));
  EXPECT_EQ(E({ 0, -1, 0 }), 0.0);
}

TEST(Sky, ReuseOfAChangingClearSkyMatchesClassicOverSeeds)
{
  // A block on a ground, grey: interreflection and occlusion both matter. The sun of the
  // clear sky moves, and E_dh changes, over four frames.
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -1.5, -1.5, 0 }, { 3, 0, 0 }, { 0, 3, 0 }, 3, 3, Rgb(0.4));
  scenes::addBox(
    mesh, { -0.5, -0.5, 0 }, { 0.5, 0.5, 1 }, 0.5, false, std::vector<Rgb>(6, Rgb(0.6)), true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  std::vector<SkyFrame> frames;
  for (int k = 0; k < 4; ++k)
  {
    frames.push_back({ sunDirection(15 + 20 * k, 90 + 40 * k), 60.0 + 30 * k, 0 });
  }
  const Sky sky(SkyModel::CieClear, { 0, 0, 1 }, frames);
  ASSERT_EQ(sky.positions(), 4u);
  const LightRig rig = skyRig(sky);
  auto groupOf = [&](std::size_t e)
  {
    const Vec3 n = scene.elementSideNormal(e, Side::Front);
    return n.z > 0.5 ? (scene.elementArea(e) > 0.08 ? 0u : 1u) : 2u + (n.x > 0.5) + 2 * (n.y > 0.5);
  };
  SeedMoments classic, reused;
  for (std::uint64_t seed = 0; seed < 12; ++seed)
  {
    classic.add(checks::groupPowers(
      scene, solve(scene, rig, modeOptions(false, 4000, 100 + seed)), 5, groupOf, 0));
    reused.add(checks::groupPowers(
      scene, solve(scene, rig, modeOptions(true, 4000, 200 + seed)), 5, groupOf, 0));
  }
  checks::expectSameMeans(reused, { &classic }, "reuse against classic");
}

TEST(Sky, AConstantSkyIsOnePositionSolvedOnce)
{
  const std::vector<SkyFrame> frames(3, SkyFrame{ sunDirection(30, 0), Edh, 0 });
  EXPECT_EQ(Sky(SkyModel::CieClear, { 0, 0, 1 }, frames).positions(), 1u);
  std::vector<SkyFrame> moving = frames;
  moving[1].sun = sunDirection(40, 0);
  EXPECT_EQ(Sky(SkyModel::CieClear, { 0, 0, 1 }, moving).positions(), 3u);
  // The uniform and overcast skies ignore the sun.
  EXPECT_EQ(Sky(SkyModel::CieOvercast, { 0, 0, 1 }, moving).positions(), 1u);
}

TEST(Sky, TheTablesAreTheSameBitsForAnyThreadCount)
{
  // Every model over frames whose sun and irradiances change, tabulated on 1 and 3 workers:
  // each position's cells, integral and draws agree bit for bit.
  std::vector<SkyFrame> frames;
  for (int k = 0; k < 7; ++k)
  {
    frames.push_back(
      SkyFrame{ sunDirection(10 + 9 * k, 25 * k), 80.0 + 5 * k, 100.0 + 60 * k, 30 * k });
  }
  for (SkyModel model :
    { SkyModel::Uniform, SkyModel::CieOvercast, SkyModel::CieClear, SkyModel::Perez })
  {
    const Sky one(model, { 0.1, 0, 1 }, frames, 1), three(model, { 0.1, 0, 1 }, frames, 3);
    ASSERT_EQ(one.positions(), three.positions());
    std::uint64_t hash = 1469598103934665603ULL;
    for (std::size_t j = 0; j < one.positions(); ++j)
    {
      EXPECT_EQ(one.integral(j), three.integral(j)) << skyModelName(model) << " " << j;
      for (std::size_t cell = 0; cell < Sky::Cells; ++cell)
      {
        ASSERT_EQ(one.density(j, cell), three.density(j, cell)) << skyModelName(model);
        double d = one.density(j, cell);
        std::uint64_t bits;
        std::memcpy(&bits, &d, sizeof bits);
        hash = (hash ^ bits) * 1099511628211ULL;
      }
      const Vec3 a = one.sample(j, 0.3, 0.6, 0.2), b = three.sample(j, 0.3, 0.6, 0.2);
      EXPECT_TRUE(a.x == b.x && a.y == b.y && a.z == b.z);
    }
    std::printf(
      "%s: tables %016llx\n", skyModelName(model).c_str(), static_cast<unsigned long long>(hash));
  }
}
