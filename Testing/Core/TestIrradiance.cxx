// Irradiance: the light arriving on each element side, which black surfaces have too, against
// Lambert's exact form factor and against the radiosity it makes.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

using namespace mlr;
using mlr::checks::elementFormFactor;

namespace
{
Scene floorOf(const Rgb& rho)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 8, 8, rho);
  return Scene::fromPatchMesh(mesh);
}

SolverOptions classic(std::uint64_t paths, std::uint64_t seed)
{
  SolverOptions options;
  options.pathsPerFrame = paths;
  options.reuseShooting = false;
  options.reuseGathering = false;
  options.seed = seed;
  return options;
}

/// The inward unit box with a black floor and coloured walls; its ceiling's patches with
/// x < 0.5 emit.
Scene roomWithBlackFloor()
{
  PatchMesh mesh = scenes::closedBox(4, true,
    { Rgb(0.7, 0.2, 0.2), Rgb(0.2, 0.7, 0.2), Rgb(0.6), Rgb(0.6), Rgb(0, 0, 0),
      Rgb(0.5, 0.5, 0.8) });
  mesh.emission.assign(mesh.triangles.size(), Rgb());
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t)
  {
    const Triangle& tri = mesh.triangles[t];
    bool ceiling = true, left = true;
    for (std::uint32_t i : tri)
    {
      ceiling = ceiling && mesh.points[i].z == 1.0;
      left = left && mesh.points[i].x <= 0.5;
    }
    if (ceiling && left)
    {
      mesh.emission[t] = Rgb(3, 2, 1);
    }
  }
  return Scene::fromPatchMesh(mesh);
}

bool isFloor(const Scene& scene, std::size_t e)
{
  const Triangle& t = scene.elementTriangles()[e];
  const auto& p = scene.points();
  return p[t[0]].z == 0 && p[t[1]].z == 0 && p[t[2]].z == 0;
}
}

TEST(Irradiance, BlackAndWhiteFloorsReceiveTheSameLight)
{
  const auto light = scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2);
  const std::vector<Vec3> path =
    scenes::translationsAlong({ 0.5, 0.5, 0.5 }, { 0.4, 0.4, 0.5 }, { 0.6, 0.6, 0.5 }, 3);
  const Scene white = floorOf(Rgb(0.9));
  const Scene black = floorOf(Rgb(0, 0, 0));
  for (bool reuse : { false, true })
  {
    SolverOptions options = classic(20000, 3);
    options.reuseShooting = options.reuseGathering = reuse;
    const MovingLight lamp(light, Rgb(10, 8, 6), path);
    const Solution w = solve(white, lamp, options);
    const Solution b = solve(black, lamp, options);
    double lit = 0;
    for (std::size_t f = 0; f < path.size(); ++f)
    {
      for (std::size_t e = 0; e < white.elementCount(); ++e)
      {
        // The first hits do not depend on the floor's colour: the same seed scores the same
        // shares, bit for bit.
        ASSERT_EQ(b.irradiance(f, e, Side::Front), w.irradiance(f, e, Side::Front))
          << "frame " << f << " element " << e << " reuse " << reuse;
        ASSERT_EQ(b.total(f, e, Side::Front), Rgb()) << "a black floor reflects nothing";
        ASSERT_EQ(b.litSide(e), Side::Front) << "the side light arrives on";
        lit += b.irradiance(f, e, Side::Front).sum();
      }
    }
    EXPECT_GT(lit, 0) << "the black floor has irradiance";
  }
}

TEST(Irradiance, DirectIrradianceIsTheFormFactorTimesTheLightsExitance)
{
  // E(x) = Phi / A_L * F(x -> light) for a Lambertian light: the inverse-square law integrated
  // over the light. Black, so that nothing but the arriving light enters the check.
  const Scene scene = floorOf(Rgb(0, 0, 0));
  const auto light = scenes::squareLightFacingDown({ 0.5, 0.5, 0.3 }, 0.1);
  const Rgb power(10, 5, 2);
  const std::uint64_t paths = 200000;
  const MovingLight lamp(light, power, { Vec3() });
  const Solution solution = solve(scene, lamp, classic(paths, 7));
  double meanSquare = 0, maxAbs = 0;
  std::size_t count = 0;
  const auto& p = scene.points();
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Triangle& t = scene.elementTriangles()[e];
    const double F = elementFormFactor(p[t[0]], p[t[1]], p[t[2]], scene.elementNormal(e), light[0]);
    const double area = scene.elementArea(e);
    const double hitProbability = F * area / lamp.area();
    for (int ch = 0; ch < 3; ++ch)
    {
      const double exact = power[ch] / lamp.area() * F;
      // Binomial noise of N paths each bringing Phi / (N A) on a hit.
      const double sigma = power[ch] / (double(paths) * area) *
        std::sqrt(double(paths) * hitProbability * (1 - hitProbability));
      const double z = (solution.directIrradiance(0, e, Side::Front)[ch] - exact) / sigma;
      meanSquare += z * z;
      maxAbs = std::max(maxAbs, std::abs(z));
      ++count;
    }
    EXPECT_EQ(solution.indirectIrradiance(0, e, Side::Front), Rgb()) << "a lone floor";
  }
  meanSquare /= double(count);
  std::cout << "direct irradiance: mean z^2 " << meanSquare << ", max |z| " << maxAbs << "\n";
  EXPECT_NEAR(meanSquare, 1.0, 0.15);
  EXPECT_LT(maxAbs, 5.0);
  // Under the light's centre a small light is a point: E = Phi / (pi h^2).
  const double h = 0.3, side = 0.1;
  const double centreF = pointToPolygonFormFactor({ 0.5, 0.5, 0 }, { 0, 0, 1 }, light[0]);
  EXPECT_NEAR(
    power.r / (side * side) * centreF, power.r / (M_PI * h * h), 0.05 * power.r / (M_PI * h * h));
}

TEST(Irradiance, TimesReflectanceIsRadiosityMinusEmissionEverywhere)
{
  const Scene scene = roomWithBlackFloor();
  ASSERT_TRUE(scene.hasEmission());
  const auto light = scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2);
  const std::vector<Vec3> path =
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.3, 0.5, 0.9 }, { 0.7, 0.5, 0.8 }, 3);
  for (double k : { 1.0, 0.0 })
  {
    SolverOptions options;
    options.pathsPerFrame = 20000;
    options.gatheringRatio = k;
    options.seed = 5;
    const Solution s = solve(scene, MovingLight(light, Rgb(20, 20, 20), path), options);
    double floorIndirect = 0, floorDirect = 0;
    for (std::size_t f = 0; f < s.frameCount(); ++f)
    {
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        const Rgb& rho = scene.elementReflectance(e);
        for (Side side : { Side::Front, Side::Back })
        {
          const Rgb E = s.irradiance(f, e, side);
          const Rgb reflected = s.total(f, e, side) - s.emitted(e, side);
          for (int ch = 0; ch < 3; ++ch)
          {
            ASSERT_GE(E[ch], 0.0);
            ASSERT_NEAR(rho[ch] * E[ch], reflected[ch], 1e-6 * std::max(1.0, reflected[ch]))
              << "k " << k << " frame " << f << " element " << e << " channel " << ch;
          }
        }
        if (isFloor(scene, e))
        {
          floorDirect += s.directIrradiance(f, e, Side::Front).sum();
          floorIndirect += s.indirectIrradiance(f, e, Side::Front).sum();
        }
      }
    }
    EXPECT_GT(floorDirect, 0);
    if (k > 0)
    {
      // The black floor gathers the walls' light for its irradiance.
      EXPECT_GT(floorIndirect, 0.1 * floorDirect);
    }
    else
    {
      // Without gathering its indirect irradiance is unknown: the patch solution of a black
      // patch is zero, so only the direct light shows (Documentation/Method.md, section 15).
      EXPECT_EQ(floorIndirect, 0.0);
    }
  }
}
