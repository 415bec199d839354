// A closed box absorbs all the light's power: sum_i A_i (1-rho_i)/rho_i B_i = Phi.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

using namespace mlr;
using mlr::checks::Balance;
using mlr::checks::balanceOfFrame;

namespace
{
std::vector<Vec3> boxTrajectory(std::size_t frames)
{
  return scenes::translationsAlong(
    { 0.5, 0.5, 0.9 }, { 0.25, 0.3, 0.9 }, { 0.75, 0.7, 0.8 }, frames);
}

void expectAbsorbsAllPower(bool reuseShooting, bool reuseGathering)
{
  // Walls of different colours, so that channels and walls weigh differently.
  const std::vector<Rgb> walls = { Rgb(0.6, 0.2, 0.3), Rgb(0.3, 0.6, 0.2), Rgb(0.5, 0.5, 0.5),
    Rgb(0.7, 0.4, 0.6), Rgb(0.4, 0.3, 0.7), Rgb(0.55, 0.65, 0.45) };
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(6, true, walls));
  const Rgb power(3, 5, 7);
  const MovingLight light(
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), power, boxTrajectory(4));
  SolverOptions options;
  options.pathsPerFrame = 400000;
  options.reuseShooting = reuseShooting;
  options.reuseGathering = reuseGathering;
  const Solution solution = solve(scene, light, options);
  for (std::size_t f = 0; f < light.frameCount(); ++f)
  {
    const Balance b = balanceOfFrame(scene, solution, f);
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(b.absorbed[c] / power[c], 1.0, 0.01) << "frame " << f << " channel " << c;
    }
  }
}
}

TEST(EnergyBalance, ClosedBoxAbsorbsAllPowerClassic)
{
  expectAbsorbsAllPower(false, false);
}

TEST(EnergyBalance, ClosedBoxAbsorbsAllPowerFullReuse)
{
  expectAbsorbsAllPower(true, true);
}

TEST(EnergyBalance, ClosedBoxAbsorbsAllPowerShootingReuseOnly)
{
  expectAbsorbsAllPower(true, false);
}

TEST(EnergyBalance, ClosedBoxAbsorbsAllPowerGatheringReuseOnly)
{
  expectAbsorbsAllPower(false, true);
}

TEST(EnergyBalance, UniformReflectanceGivesGeometricSeries)
{
  // With one reflectance rho everywhere, the power leaving all surfaces is
  // Phi (rho + rho^2 + ...) = Phi rho / (1 - rho).
  for (double rho : { 0.3, 0.5, 0.8 })
  {
    const Scene scene = Scene::fromPatchMesh(scenes::closedBox(6, true, { Rgb(rho) }));
    const Rgb power(2, 2, 2);
    const MovingLight light(
      scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), power, boxTrajectory(3));
    SolverOptions options;
    options.pathsPerFrame = 300000;
    const Solution solution = solve(scene, light, options);
    for (std::size_t f = 0; f < light.frameCount(); ++f)
    {
      const Balance b = balanceOfFrame(scene, solution, f);
      EXPECT_NEAR(b.radiantPower.r / (power.r * rho / (1 - rho)), 1.0, 0.01)
        << "rho " << rho << " frame " << f;
    }
  }
}

TEST(EnergyBalance, WithoutGatheringPatchSolutionStillBalances)
{
  // k = 0: no final gathering, the elements take their patch's shooting solution.
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(5, true, { Rgb(0.5) }));
  const MovingLight light(
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), Rgb(1), boxTrajectory(2));
  SolverOptions options;
  options.pathsPerFrame = 300000;
  options.gatheringRatio = 0;
  const Solution solution = solve(scene, light, options);
  EXPECT_EQ(solution.statistics.gatheringRays, 0u);
  for (std::size_t f = 0; f < 2; ++f)
  {
    EXPECT_NEAR(balanceOfFrame(scene, solution, f).radiantPower.g, 1.0, 0.01);
  }
}

TEST(EnergyBalance, AnyPowerBalancesInAnyUnit)
{
  // The results are stored in 16-bit floats of range 2^-62 to 2^64 (PackedRgb), in a unit
  // taken from the lights' power over the scene's area: a light of 10^24 W in a box of
  // 10^-6 units (irradiance 10^36) or of 10^-24 W in a box of 10^6 units (10^-36) stays in
  // range, and with batches too, whose single batches have the noisiest elements.
  for (const auto& [watts, size] : { std::pair{ 1e24, 1e-6 }, std::pair{ 1e-24, 1e6 } })
  {
    PatchMesh box = scenes::closedBox(5, true, { Rgb(0.5) });
    for (Vec3& p : box.points)
    {
      p = p * size;
    }
    const Scene scene = Scene::fromPatchMesh(box);
    std::vector<Vec3> path = boxTrajectory(2);
    for (Vec3& p : path)
    {
      p = p * size;
    }
    const MovingLight light(
      scenes::squareLightFacingDown(Vec3{ 0.5, 0.5, 0.9 } * size, 0.2 * size), Rgb(watts), path);
    SolverOptions options;
    options.pathsPerFrame = 300000;
    options.errorBatches = 16;
    const Solution solution = solve(scene, light, options);
    for (std::size_t f = 0; f < 2; ++f)
    {
      EXPECT_NEAR(balanceOfFrame(scene, solution, f).absorbed.g / watts, 1.0, 0.01)
        << watts << " W, frame " << f;
    }
  }
}
