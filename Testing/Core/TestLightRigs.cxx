// Light rigs: lights that turn, dim and multiply, static lights solved once, and
// emissive scene surfaces.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "PointLight.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <limits>

#include <cmath>
#include <iostream>

using namespace mlr;
using mlr::checks::elementFormFactor;
using mlr::checks::expectError;
using mlr::checks::modeOptions;
using mlr::checks::SeedMoments;

namespace
{
constexpr double Degree = M_PI / 180.0;

/// v turned by `angle` about the unit `axis` (Rodrigues), written out here so that the
/// reference does not share Core's Rotation code.
Vec3 turnAbout(const Vec3& axis, double angle, const Vec3& v)
{
  return v * std::cos(angle) + cross(axis, v) * std::sin(angle) +
    axis * (dot(axis, v) * (1 - std::cos(angle)));
}

/// A pose and the same turn as axis and angle, for the reference.
struct Turn
{
  LightPose pose;
  Vec3 axis{ 0, 0, 1 };
  double angle = 0;
};

Turn quaternionTurn(const Vec3& position, const Vec3& axis, double angle)
{
  Turn t;
  t.axis = normalize(axis);
  t.angle = angle;
  const Vec3 q = t.axis * std::sin(angle / 2);
  t.pose.position = position;
  t.pose.rotation = Rotation::fromQuaternion(std::cos(angle / 2), q.x, q.y, q.z);
  return t;
}

Turn turnTowards(const Vec3& position, const Vec3& from, const Vec3& to)
{
  Turn t;
  t.axis = normalize(cross(from, to));
  t.angle = std::acos(dot(from, to));
  t.pose.position = position;
  t.pose.rotation = Rotation::between(from, to);
  return t;
}

std::vector<LightPose> posesOf(const std::vector<Turn>& turns)
{
  std::vector<LightPose> poses;
  for (const Turn& t : turns)
  {
    poses.push_back(t.pose);
  }
  return poses;
}

const Vec3 Down(0, 0, -1);

/// A square light (0.2 m, facing down at height 0.5 above a unit floor) that moves and tilts
/// its normal by up to 70 degrees: frames 1-3 by quaternions, frame 4 by `between`.
std::vector<Turn> turningLightPoses()
{
  const Vec3 axis(1, 0.4, 0);
  return { quaternionTurn({ 0.5, 0.5, 0.5 }, axis, 0),
    quaternionTurn({ 0.55, 0.46, 0.47 }, axis, 25 * Degree),
    quaternionTurn({ 0.6, 0.42, 0.44 }, axis, 50 * Degree),
    quaternionTurn({ 0.45, 0.55, 0.45 }, axis, -70 * Degree),
    turnTowards({ 0.4, 0.6, 0.5 }, Down, normalize(Vec3(0.3, -0.5, -1))) };
}

struct ZScores
{
  double meanSquare = 0;
  double maxAbs = 0;
  std::size_t count = 0;
};

/**
 * z = (B - B_exact) / sigma of the floor's direct light per element, channel and frame, with
 * B_exact = rho Phi / A_L * F(element -> turned light), the light turned by the test's own
 * rotation. Classic: sigma is the binomial deviation of N paths scoring rho Phi / (N A_e) when
 * they hit the element first. Reuse: a path scores at most 1/M_j of rho Phi / A_e in frame j
 * (its weight G_j / sum_k M_k G_k), so the variance is at most (rho Phi / A_e)^2 p_j / M_j,
 * p_j the probability that a frame-j path hits the element: sigma is that bound.
 */
ZScores compareWithLambert(const Scene& scene, const std::vector<Vec3>& light, const Rgb& power,
  const std::vector<Turn>& turns, const Solution& solution, const SolverOptions& options)
{
  ZScores z;
  const double lightArea = 0.5 * length(newellNormal(light));
  Vec3 centroid;
  for (const Vec3& v : light)
  {
    centroid += v / double(light.size()); // a square: vertex mean = area centroid
  }
  const double N = double(options.pathsPerFrame);
  const double M = N / double(turns.size());
  for (std::size_t f = 0; f < turns.size(); ++f)
  {
    std::vector<Vec3> polygon;
    for (const Vec3& v : light)
    {
      polygon.push_back(
        turnAbout(turns[f].axis, turns[f].angle, v - centroid) + turns[f].pose.position);
    }
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      const Triangle& t = scene.elementTriangles()[e];
      const auto& p = scene.points();
      const double F =
        elementFormFactor(p[t[0]], p[t[1]], p[t[2]], scene.elementNormal(e), polygon);
      const Rgb& rho = scene.elementReflectance(e);
      const double area = scene.elementArea(e);
      const double hitProbability = F * area / lightArea;
      const Vec3 lightNormal = turnAbout(turns[f].axis, turns[f].angle, Down);
      bool behindLight = true;
      for (std::uint32_t v : t)
      {
        behindLight = behindLight && dot(p[v] - turns[f].pose.position, lightNormal) < 0;
      }
      for (int ch = 0; ch < 3; ++ch)
      {
        const double exact = rho[ch] * power[ch] / lightArea * F;
        const double score = rho[ch] * power[ch] / area;
        const double sigma = options.reuseShooting
          ? score * std::sqrt(hitProbability / M)
          : score / N * std::sqrt(N * hitProbability * (1 - hitProbability));
        const double value = solution.direct(f, e, Side::Front)[ch];
        if (behindLight)
        {
          EXPECT_EQ(value, 0.0) << "frame " << f << " element " << e << " is behind the light";
          continue;
        }
        if (sigma == 0)
        {
          continue; // a sliver in front of the light's plane, lit by almost grazing light
        }
        const double s = (value - exact) / sigma;
        z.meanSquare += s * s;
        z.maxAbs = std::max(z.maxAbs, std::abs(s));
        ++z.count;
        EXPECT_EQ(solution.direct(f, e, Side::Back)[ch], 0.0)
          << "the floor's underside sees no light";
      }
    }
  }
  z.meanSquare /= double(z.count);
  return z;
}

Scene unitFloor(int cells)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(
    mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, cells, cells, Rgb(0.5, 0.3, 0.7));
  return Scene::fromPatchMesh(mesh);
}

/// The closed unit box of coloured walls (inward), its elements grouped by wall.
struct ColouredBox
{
  Scene scene = Scene::fromPatchMesh(scenes::closedBox(
    4, true, { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.6), Rgb(0.6), Rgb(0.5), Rgb(0.7) }));
  std::size_t wallOf(std::size_t element) const
  {
    return element / (this->scene.elementCount() / 6);
  }
  std::vector<double> wallPowers(const Solution& solution, int channel = 1) const
  {
    return checks::groupPowers(
      this->scene, solution, 6, [this](std::size_t e) { return this->wallOf(e); }, channel);
  }
};

/// A light near the ceiling of the unit box that pans from facing down to facing a wall.
MovingLight panningLight(const Rgb& power = Rgb(1))
{
  const Vec3 axis(0.2, 1, 0);
  const std::vector<Turn> turns = { quaternionTurn({ 0.5, 0.5, 0.8 }, axis, 0),
    quaternionTurn({ 0.45, 0.5, 0.8 }, axis, 30 * Degree),
    quaternionTurn({ 0.4, 0.55, 0.75 }, axis, 60 * Degree),
    turnTowards({ 0.35, 0.55, 0.7 }, Down, Vec3(-1, 0, 0)),
    turnTowards({ 0.5, 0.4, 0.75 }, Down, normalize(Vec3(0, 1, -0.3))) };
  return MovingLight(scenes::squareLightFacingDown({ 0.5, 0.5, 0.8 }, 0.2), power, posesOf(turns));
}

/// Expects `scaled` to be `factor` times `reference`, channel by channel, to the last bits.
void expectScaled(
  const Rgb& scaled, const Rgb& reference, const Rgb& factor, const std::string& what)
{
  for (int c = 0; c < 3; ++c)
  {
    // The factors are powers of two, which scale a stored value (PackedRgb) exactly; the
    // margin is the fixed-point sums' rounding.
    EXPECT_NEAR(scaled[c], factor[c] * reference[c],
      4 * std::numeric_limits<float>::epsilon() * std::abs(factor[c] * reference[c]))
      << what << " channel " << c;
  }
}
}

TEST(LightRigs, TurningLightMatchesLambertOnTheTurnedPolygon)
{
  const Scene scene = unitFloor(8);
  const std::vector<Vec3> light = scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2)[0];
  const Rgb power(10, 6, 3);
  const std::vector<Turn> turns = turningLightPoses();
  const MovingLight moving({ light }, power, posesOf(turns));
  ASSERT_TRUE(moving.rotates());
  for (bool reuse : { false, true })
  {
    SolverOptions options = modeOptions(reuse, 100000, reuse ? 21 : 20);
    options.gatheringRatio = 0; // a lone floor reflects nothing onto itself
    const Solution solution = solve(scene, moving, options);
    const ZScores z = compareWithLambert(scene, light, power, turns, solution, options);
    std::cout << (reuse ? "full reuse" : "classic") << ": mean z^2 " << z.meanSquare << ", max |z| "
              << z.maxAbs << " over " << z.count << "\n";
    if (reuse)
    {
      // sigma is an upper bound: the mean square is at most 1, plus its own noise.
      EXPECT_LT(z.meanSquare, 1.2);
      EXPECT_LT(z.maxAbs, 5.5);
    }
    else
    {
      // Independent paths: standard normal scores, whose mean square is 1 within
      // sqrt(2 / (count / 3)) (the three channels share their hits): 0.04 here.
      EXPECT_NEAR(z.meanSquare, 1.0, 0.15);
      EXPECT_LT(z.maxAbs, 5.5);
    }
  }
}

TEST(LightRigs, ReuseStaysUnbiasedUnderRotation)
{
  const ColouredBox box;
  const MovingLight light = panningLight();
  constexpr int runs = 24;
  SeedMoments moments[2];
  for (int mode = 0; mode < 2; ++mode)
  {
    for (int r = 0; r < runs; ++r)
    {
      const Solution solution =
        solve(box.scene, light, modeOptions(mode == 1, 3000, 500 + r + 100 * mode));
      moments[mode].add(box.wallPowers(solution));
    }
  }
  const double chiSquare =
    checks::expectSameMeans(moments[1], { &moments[0] }, "reuse against classic");
  std::cout << "mean z^2 over 6 walls x 5 frames: " << chiSquare << "\n";
}

TEST(LightRigs, PowerFactorScalesItsFrameExactly)
{
  const ColouredBox box;
  const MovingLight full = panningLight(Rgb(2, 3, 4));
  std::vector<LightPose> poses = full.poses();
  poses[1].power = Rgb(0.5);
  poses[3].power = Rgb(1, 0.5, 0.25);
  const MovingLight dimmed(
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.8 }, 0.2), Rgb(2, 3, 4), poses);
  poses[2].power = Rgb(0);
  const MovingLight off(scenes::squareLightFacingDown({ 0.5, 0.5, 0.8 }, 0.2), Rgb(2, 3, 4), poses);
  for (bool reuse : { false, true })
  {
    const SolverOptions options = modeOptions(reuse, 20000, 3);
    const std::string mode = reuse ? "full reuse" : "classic";
    const Solution a = solve(box.scene, full, options);
    const Solution b = solve(box.scene, dimmed, options);
    const Solution c = solve(box.scene, off, options);
    double lit = 0;
    for (std::size_t f = 0; f < full.frameCount(); ++f)
    {
      const Rgb factor = dimmed.pose(f).power;
      for (std::size_t e = 0; e < box.scene.elementCount(); ++e)
      {
        for (Side side : { Side::Front, Side::Back })
        {
          const std::string what =
            mode + " frame " + std::to_string(f) + " element " + std::to_string(e);
          expectScaled(b.direct(f, e, side), a.direct(f, e, side), factor, what + " direct");
          expectScaled(b.indirect(f, e, side), a.indirect(f, e, side), factor, what + " indirect");
          lit += a.total(f, e, side).sum();
        }
        if (f == 2)
        {
          EXPECT_EQ(c.total(f, e, Side::Front), Rgb()) << mode << " element " << e;
          EXPECT_EQ(c.total(f, e, Side::Back), Rgb()) << mode << " element " << e;
          EXPECT_EQ(c.patchRadiosity(f, Scene::patchOfElement(e), Side::Front), Rgb());
        }
      }
    }
    EXPECT_GT(lit, 0.0);
    // A position that is off casts no path.
    EXPECT_EQ(c.statistics.pathsCast, reuse ? options.pathsPerFrame : 4 * options.pathsPerFrame)
      << mode;
    if (!reuse)
    {
      // Classic frames are independent: the others are those of the light that stays on.
      for (std::size_t e = 0; e < box.scene.elementCount(); ++e)
      {
        EXPECT_EQ(c.total(0, e, Side::Front), b.total(0, e, Side::Front));
        EXPECT_EQ(c.total(4, e, Side::Front), b.total(4, e, Side::Front));
      }
    }
  }
}

TEST(LightRigs, TwoLightsTogetherEqualTheSumOfEachAlone)
{
  const ColouredBox box;
  const MovingLight panning = panningLight(Rgb(1, 2, 3));
  // A second light with other colours, sliding under the ceiling and facing down.
  const MovingLight sliding(scenes::squareLightFacingDown({ 0.3, 0.7, 0.9 }, 0.15), Rgb(3, 1, 0.5),
    scenes::translationsAlong({ 0.3, 0.7, 0.9 }, { 0.3, 0.7, 0.9 }, { 0.7, 0.2, 0.85 }, 5));
  LightRig both;
  both.areaLights = { panning, sliding };
  constexpr int runs = 16;
  for (int channel : { 0, 2 })
  {
    SeedMoments together, first, second;
    for (int r = 0; r < runs; ++r)
    {
      const Solution s12 = solve(box.scene, both, modeOptions(true, 3000, 1000 + r));
      EXPECT_EQ(s12.statistics.sources, 2u);
      EXPECT_EQ(s12.statistics.pathsCast, 2 * 3000u) << "each moving light reuses its own N paths";
      together.add(box.wallPowers(s12, channel));
      first.add(
        box.wallPowers(solve(box.scene, panning, modeOptions(true, 3000, 2000 + r)), channel));
      second.add(
        box.wallPowers(solve(box.scene, sliding, modeOptions(true, 3000, 3000 + r)), channel));
    }
    const double chiSquare = checks::expectSameMeans(together, { &first, &second },
      "channel " + std::to_string(channel) + ": both lights against the sum of each");
    std::cout << "channel " << channel << ": mean z^2 " << chiSquare << "\n";
  }
}

TEST(LightRigs, LightsOfOneRigAreIndependentEstimates)
{
  // Two copies of a light in one rig are two independent estimates of half the light each:
  // their sum has half the variance of one light of twice the power. Were the copies to draw
  // the same random numbers, the sum would be that one light exactly, variance and all.
  const ColouredBox box;
  const MovingLight half = panningLight(Rgb(1));
  const MovingLight whole = panningLight(Rgb(2));
  LightRig copies;
  copies.areaLights = { half, half };
  // No final gathering: it runs once on the sum of the sources, with the same noise either way.
  auto options = [](std::uint64_t seed)
  {
    SolverOptions o = modeOptions(true, 2000, seed);
    o.gatheringRatio = 0;
    return o;
  };
  constexpr int runs = 30;
  SeedMoments two, one;
  for (int r = 0; r < runs; ++r)
  {
    two.add(box.wallPowers(solve(box.scene, copies, options(4000 + r))));
    one.add(box.wallPowers(solve(box.scene, whole, options(5000 + r))));
  }
  double varianceTwo = 0, varianceOne = 0;
  for (std::size_t i = 0; i < two.sum.size(); ++i)
  {
    varianceTwo += two.meanVariance(i);
    varianceOne += one.meanVariance(i);
  }
  const double ratio = varianceTwo / varianceOne;
  std::cout << "variance of two half-power copies / one full-power light: " << ratio << "\n";
  // 0.5 in theory, 1 for copies that replay the same numbers. Each variance is summed over
  // 30 values from 30 runs: over seeds the ratio spreads by about 0.06.
  EXPECT_LT(ratio, 0.75);
  EXPECT_GT(ratio, 0.3);
  checks::expectSameMeans(two, { &one }, "two copies against one light of twice the power");
}

TEST(LightRigs, StaticLightIsCastOnceAndLightsEveryFrameAlike)
{
  const ColouredBox box;
  const MovingLight moving = panningLight(Rgb(1));
  const Rgb staticPower(0.5, 1.5, 2.5);
  const MovingLight lamp(scenes::squareLightFacingDown({ 0.7, 0.3, 0.95 }, 0.1), staticPower,
    std::vector<Vec3>{ Vec3() });
  ASSERT_EQ(lamp.frameCount(), 1u);
  LightRig withLamp, withoutLamp;
  withLamp.areaLights = { moving, lamp };
  withoutLamp.areaLights = { moving };
  for (bool reuse : { false, true })
  {
    const std::string mode = reuse ? "full reuse" : "classic";
    const SolverOptions options = modeOptions(reuse, 20000, 8);
    const Solution a = solve(box.scene, withLamp, options);
    const Solution b = solve(box.scene, withoutLamp, options);
    const std::uint64_t N = options.pathsPerFrame;
    EXPECT_EQ(a.statistics.frames, 5u);
    EXPECT_EQ(a.statistics.sources, 2u);
    EXPECT_EQ(a.statistics.staticPathsCast, N) << mode << ": the lamp is shot once, not per frame";
    EXPECT_EQ(a.statistics.pathsCast, (reuse ? 1 : 5) * N + N) << mode;
    EXPECT_EQ(b.statistics.staticPathsCast, 0u) << mode;

    // The moving light's part is the same in both solves (same seed, and it is shot first), so
    // the difference is the lamp's own light. In a closed box every path of the lamp lands
    // somewhere: its first hits carry exactly its power, sum A rho^-1 B_direct = Phi, in
    // every frame, up to the fixed-point rounding and the rounding of the stored results, each
    // within RelativeRounding of itself: a sum of differences is within RelativeRounding of
    // the sum of both terms.
    std::vector<Rgb> lampDirect(5), lampIndirect(5), directRounding(5), indirectRounding(5);
    const auto rounding = [](double x) { return PackedRgb::RelativeRounding * x; };
    for (std::size_t f = 0; f < 5; ++f)
    {
      for (std::size_t e = 0; e < box.scene.elementCount(); ++e)
      {
        const Rgb& rho = box.scene.elementReflectance(e);
        for (Side side : { Side::Front, Side::Back })
        {
          const Rgb direct = a.direct(f, e, side) - b.direct(f, e, side);
          const Rgb indirect = a.indirect(f, e, side) - b.indirect(f, e, side);
          const double area = box.scene.elementArea(e);
          for (int c = 0; c < 3; ++c)
          {
            lampDirect[f][c] += area * direct[c] / rho[c];
            lampIndirect[f][c] += area * indirect[c];
            directRounding[f][c] += rounding(area * a.direct(f, e, side)[c] / rho[c]) +
              rounding(area * b.direct(f, e, side)[c] / rho[c]);
            indirectRounding[f][c] += rounding(area * a.indirect(f, e, side)[c]) +
              rounding(area * b.indirect(f, e, side)[c]);
          }
        }
      }
      for (int c = 0; c < 3; ++c)
      {
        EXPECT_LT(directRounding[f][c], 0.01 * staticPower[c]);
        EXPECT_NEAR(lampDirect[f][c], staticPower[c], 1e-6 * staticPower[c] + directRounding[f][c])
          << mode << " frame " << f;
        EXPECT_NEAR(lampDirect[f][c], lampDirect[0][c], directRounding[f][c] + directRounding[0][c])
          << mode << " frame " << f;
        EXPECT_GT(lampIndirect[f][c], 0.0);
        if (reuse)
        {
          // One set of gathering rays serves every frame: the lamp's indirect light is the same.
          EXPECT_NEAR(
            lampIndirect[f][c], lampIndirect[0][c], indirectRounding[f][c] + indirectRounding[0][c])
            << mode << " frame " << f;
        }
      }
    }
  }
}

TEST(LightRigs, EmissiveWallInClosedBoxBalancesEmittedAndLightPower)
{
  const std::vector<Rgb> walls = { Rgb(0.6, 0.2, 0.3), Rgb(0.3, 0.6, 0.2), Rgb(0.5, 0.5, 0.5),
    Rgb(0.7, 0.4, 0.6), Rgb(0.4, 0.3, 0.7), Rgb(0.55, 0.65, 0.45) };
  PatchMesh mesh = scenes::closedBox(6, true, walls);
  // The +x wall (the second 6 x 6 x 2 patches, area 1) emits into the box and still reflects.
  const Rgb exitance(1.5, 0.6, 3);
  mesh.emission.assign(mesh.triangles.size(), Rgb());
  for (std::size_t p = 72; p < 144; ++p)
  {
    mesh.emission[p] = exitance;
  }
  const Scene scene = Scene::fromPatchMesh(mesh);
  const Rgb lightPower(2, 4, 1);
  const MovingLight light(scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2), lightPower,
    scenes::translationsAlong({ 0.5, 0.5, 0.9 }, { 0.25, 0.3, 0.9 }, { 0.75, 0.7, 0.8 }, 3));
  for (bool reuse : { false, true })
  {
    const std::string mode = reuse ? "full reuse" : "classic";
    const SolverOptions options = modeOptions(reuse, 200000, 4);
    const Solution solution = solve(scene, light, options);
    EXPECT_EQ(solution.statistics.sources, 2u) << mode << ": the light and the emissive wall";
    EXPECT_EQ(solution.statistics.staticPathsCast, options.pathsPerFrame) << mode;
    // balanceOfFrame counts (1 - rho)/rho A B with B including the emission E; an emitter
    // absorbs (1 - rho)/rho A (B - E), so the emitters' term is taken off.
    Rgb emitterTerm, emitted;
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      EXPECT_EQ(solution.emitted(e, Side::Back), Rgb());
      EXPECT_EQ(solution.emitted(e, Side::Front), scene.elementEmission(e));
      const Rgb& E = solution.emitted(e, Side::Front);
      const Rgb& rho = scene.elementReflectance(e);
      for (int c = 0; c < 3; ++c)
      {
        emitterTerm[c] += scene.elementArea(e) * (1 - rho[c]) / rho[c] * E[c];
        emitted[c] += scene.elementArea(e) * E[c];
      }
    }
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(emitted[c], exitance[c], 1e-12 * exitance[c]);
    }
    for (std::size_t f = 0; f < light.frameCount(); ++f)
    {
      const checks::Balance b = checks::balanceOfFrame(scene, solution, f);
      for (int c = 0; c < 3; ++c)
      {
        const double absorbed = b.absorbed[c] - emitterTerm[c];
        EXPECT_NEAR(absorbed / (emitted[c] + lightPower[c]), 1.0, 0.01)
          << mode << " frame " << f << " channel " << c;
      }
    }
  }
}

TEST(LightRigs, BadInputIsRefusedWithWhatToFix)
{
  const std::vector<std::vector<Vec3>> square =
    scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2);
  const std::vector<LightPose> twoPoses(2);
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 1 }, { 1, 1, 1 }, { 2, 2, 1 } } }, Rgb(1), twoPoses);
    },
    "zero area");
  expectError(
    [&] {
      MovingLight({ { { 0, 0, 1 }, { 0, 0, 1 }, { 0, 0, 1 }, { 0, 0, 1 } } }, Rgb(1), twoPoses);
    },
    "zero area");
  expectError([&] { MovingLight(square, Rgb(1), std::vector<LightPose>{}); }, "zero frames");

  auto withPose = [&](std::size_t frame, const std::function<void(LightPose&)>& change)
  {
    return [&square, frame, change]
    {
      std::vector<LightPose> poses(3);
      for (LightPose& p : poses)
      {
        p.position = Vec3(0.5, 0.5, 0.5);
      }
      change(poses[frame]);
      MovingLight(square, Rgb(1), poses);
    };
  };
  expectError(withPose(1, [](LightPose& p) { p.power = Rgb(1, -0.1, 1); }),
    "power factor of light position 1");
  expectError(withPose(2, [](LightPose& p) { p.power = Rgb(std::nan("")); }),
    "power factor of light position 2");
  // Finite, but over the bound on a light's power: the outputs would hold infinities.
  expectError(withPose(1, [](LightPose& p) { p.power = Rgb(1, 2e30, 1); }),
    "power factor of light position 1 takes the light to (1, 2e+30, 1) W, over 1e+30 W");
  expectError(
    [] {
      PointLight(Rgb(1e29), { LightPose{ Vec3(), Rotation(), Rgb(100) } });
    },
    "power factor of light position 0 takes the light to (1e+31, 1e+31, 1e+31) W");
  expectError(withPose(0, [](LightPose& p) { p.position.y = std::nan(""); }), "light position 0");
  // Scaled, sheared, mirrored, NaN: none is a rotation.
  expectError(withPose(1,
                [](LightPose& p) {
                  p.rotation.row0 = { 2, 0, 0 };
                }),
    "orientation of light position 1 is not a rotation");
  expectError(withPose(1, [](LightPose& p) { p.rotation.row0 = { 1, 0.3, 0 }; }), "not a rotation");
  expectError(withPose(2, [](LightPose& p) { p.rotation.row2 = { 0, 0, -1 }; }), "not a rotation");
  expectError(
    withPose(0, [](LightPose& p) { p.rotation.row1.x = std::nan(""); }), "not a rotation");
  // A proper rotation, far from the identity, is accepted.
  withPose(1, [](LightPose& p) { p.rotation = Rotation::fromQuaternion(0.5, 0.5, -0.5, 0.5); })();

  // Moving lights that disagree on the frame count.
  LightRig rig;
  rig.areaLights.emplace_back(square, Rgb(1), std::vector<Vec3>(4));
  rig.areaLights.emplace_back(square, Rgb(1), std::vector<Vec3>(1)); // static: fine
  EXPECT_EQ(frameCount(rig, false), 4u);
  rig.areaLights.emplace_back(square, Rgb(1), std::vector<Vec3>(3));
  expectError([&] { frameCount(rig, false); }, "light 2 has 3 positions but light 0 has 4");
  const Scene scene = unitFloor(2);
  expectError([&] { solve(scene, rig, modeOptions(true, 1000, 1)); },
    "every moving light needs one position per frame");
  expectError([&] { frameCount(LightRig(), false); }, "nothing emits");
  EXPECT_EQ(frameCount(LightRig(), true), 1u) << "the scene's own emitters are enough";

  // Reuse needs a path per light position that emits; the message names the minimum.
  const MovingLight six(square, Rgb(1), std::vector<Vec3>(6));
  expectError(
    [&] { solve(scene, six, modeOptions(true, 5, 1)); }, "give at least 6 paths per frame");
  EXPECT_NO_THROW(solve(scene, six, modeOptions(true, 6, 1)));
  EXPECT_NO_THROW(solve(scene, six, modeOptions(false, 5, 1))) << "classic has no such minimum";
}
