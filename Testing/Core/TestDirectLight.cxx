// Direct light on an unoccluded floor against Lambert's exact polygon form factor.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

using namespace mlr;
using mlr::checks::elementFormFactor;

namespace
{
struct DirectLightCase
{
  Scene scene;
  std::vector<std::vector<Vec3>> light;
  Rgb power{ 10, 10, 10 };
  std::vector<Vec3> translations;
};

DirectLightCase floorUnderSquareLight()
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 8, 8, Rgb(0.5, 0.3, 0.7));
  DirectLightCase c{ Scene::fromPatchMesh(mesh),
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2), Rgb(10, 10, 10), {} };
  c.translations =
    scenes::translationsAlong({ 0.5, 0.5, 0.5 }, { 0.35, 0.35, 0.5 }, { 0.65, 0.6, 0.45 }, 5);
  return c;
}

struct ZScores
{
  double meanSquare = 0;
  double maxAbs = 0;
  std::size_t count = 0;
};

/// z = (B - B_exact) / sigma per element, channel and frame, where sigma is the binomial
/// standard deviation of N independent paths scoring rho Phi / N on hitting the element.
ZScores compareWithLambert(const DirectLightCase& c, const Solution& solution, std::uint64_t paths)
{
  ZScores z;
  const MovingLight light(c.light, c.power, c.translations);
  for (std::size_t f = 0; f < c.translations.size(); ++f)
  {
    std::vector<Vec3> polygon = c.light[0];
    for (Vec3& v : polygon)
    {
      v += c.translations[f];
    }
    for (std::size_t e = 0; e < c.scene.elementCount(); ++e)
    {
      const Triangle& t = c.scene.elementTriangles()[e];
      const auto& p = c.scene.points();
      const double F =
        elementFormFactor(p[t[0]], p[t[1]], p[t[2]], c.scene.elementNormal(e), polygon);
      const Rgb& rho = c.scene.elementReflectance(e);
      const double area = c.scene.elementArea(e);
      for (int ch = 0; ch < 3; ++ch)
      {
        const double exact = rho[ch] * c.power[ch] / light.area() * F;
        // Fraction of the paths whose first hit is this element.
        const double hitProbability = F * area / light.area();
        const double sigma = rho[ch] * c.power[ch] / (double(paths) * area) *
          std::sqrt(double(paths) * hitProbability * (1 - hitProbability));
        const double value = solution.direct(f, e, Side::Front)[ch];
        const double score = (value - exact) / sigma;
        z.meanSquare += score * score;
        z.maxAbs = std::max(z.maxAbs, std::abs(score));
        ++z.count;
        EXPECT_EQ(solution.direct(f, e, Side::Back)[ch], 0.0)
          << "the floor's underside sees no light";
      }
    }
  }
  z.meanSquare /= double(z.count);
  return z;
}
}

TEST(DirectLight, ClassicMatchesLambertFormFactorWithinBinomialNoise)
{
  const DirectLightCase c = floorUnderSquareLight();
  SolverOptions options;
  options.pathsPerFrame = 200000;
  options.reuseShooting = false;
  options.reuseGathering = false;
  options.seed = 7;
  const Solution solution = solve(c.scene, MovingLight(c.light, c.power, c.translations), options);
  const ZScores z = compareWithLambert(c, solution, options.pathsPerFrame);
  std::cout << "classic: mean z^2 " << z.meanSquare << ", max |z| " << z.maxAbs << "\n";
  // Independent paths: the z-scores are standard normal, so their mean square is 1 up to
  // sqrt(2/count) and none of 3840 exceeds ~4.5 sigma.
  EXPECT_NEAR(z.meanSquare, 1.0, 0.12) << "noise not binomial: the estimator is off";
  EXPECT_LT(z.maxAbs, 5.0);
  // Nothing but the floor: no indirect light.
  for (std::size_t e = 0; e < c.scene.elementCount(); ++e)
  {
    EXPECT_EQ(solution.indirect(0, e, Side::Front), Rgb());
  }
}

TEST(DirectLight, ReuseMatchesLambertFormFactorAtEveryPosition)
{
  const DirectLightCase c = floorUnderSquareLight();
  SolverOptions options;
  options.pathsPerFrame = 200000;
  options.seed = 11;
  const Solution solution = solve(c.scene, MovingLight(c.light, c.power, c.translations), options);
  const ZScores z = compareWithLambert(c, solution, options.pathsPerFrame);
  std::cout << "reuse: mean z^2 " << z.meanSquare << ", max |z| " << z.maxAbs << "\n";
  // Reuse weights each path by G(x_j,y)/sum_k G(x_k,y): unbiased, with a variance close to
  // that of independent paths when the positions are close (here 0.4 apart at height 0.5).
  EXPECT_LT(z.meanSquare, 2.0);
  EXPECT_GT(z.meanSquare, 0.3);
  EXPECT_LT(z.maxAbs, 6.0);
  // Reuse cast N paths in all, not N per frame, and one shadow ray per other position from
  // each first hit (about half the paths miss the floor).
  EXPECT_EQ(solution.statistics.pathsCast, options.pathsPerFrame);
  EXPECT_LE(solution.statistics.shadowRays, options.pathsPerFrame * 4);
  EXPECT_GT(solution.statistics.shadowRays, options.pathsPerFrame * 2);
}
