// Luminaires: point and area lights with intensity distributions (Lambertian, spot, table),
// moving and turning across frames; the TILT=INCLUDE factor of each pose's tilt, by the lamp's
// geometry, reaching the floor through the pose's power factor.
#include "CoreChecks.h"
#include "GeneratedScenes.h"
#include "LightSource.h"
#include "LuminaireTilt.h"
#include "RayTracer.h"
#include "Solver.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iostream>

using namespace mlr;
using mlr::checks::expectSameMeans;
using mlr::checks::modeOptions;
using mlr::checks::SeedMoments;

namespace
{
constexpr double Degree = M_PI / 180.0;

LightPose turned(const Vec3& position, const Vec3& axis, double degrees)
{
  const Vec3 a = normalize(axis);
  const double h = 0.5 * degrees * Degree;
  LightPose pose;
  pose.position = position;
  pose.rotation =
    Rotation::fromQuaternion(std::cos(h), a.x * std::sin(h), a.y * std::sin(h), a.z * std::sin(h));
  return pose;
}

/// Four frames that move and turn the light (the last turns the C planes about the nadir).
std::vector<LightPose> movingAndTurning(const Vec3& start)
{
  return { turned(start, { 0, 0, 1 }, 0), turned(start + Vec3(0.4, -0.2, 0.2), { 1, 0, 0 }, 25),
    turned(start + Vec3(-0.3, 0.3, -0.1), { 1, 1, 0 }, 40),
    turned(start + Vec3(0.1, 0.5, 0.1), { 0, 0, 1 }, 90) };
}

/// A table whose intensity depends on C, so that a wrong C = 0 plane or turn shows.
IntensityDistribution asymmetricTable()
{
  std::vector<double> gammas, planes, candela;
  for (int g = 0; g <= 6; ++g)
  {
    gammas.push_back(g * 15 * Degree); // 0 to 90 degrees, falling to 0: no edge to resolve
  }
  for (int p = 0; p <= 4; ++p)
  {
    planes.push_back(p * 90 * Degree);
  }
  for (double c : planes)
  {
    for (double g : gammas)
    {
      candela.push_back((120 + 80 * std::cos(c)) * std::cos(g));
    }
  }
  return IntensityDistribution::tabulated(gammas, planes, candela);
}

/**
 * The first-hit density p_k(y) = f(local direction) cos(theta_y) / r^2 of a point light,
 * from the pose and the frame before posing (nadir -z, C = 0 along +x, y = x cross z),
 * written out here rather than taken from Core's kernel.
 */
double pointDensity(const PointLight& light, std::size_t k, const Vec3& y, const Vec3& ny)
{
  const Rotation& r = light.pose(k).rotation;
  const Vec3 x0(1, 0, 0), z0(0, 0, -1);
  const Vec3 d = y - light.position(k);
  const double distance = length(d);
  const double cosY = -dot(ny, d) / distance;
  if (!(cosY > 0))
  {
    return 0;
  }
  const Vec3 u = d / distance;
  const Vec3 local(dot(u, r.apply(x0)), dot(u, r.apply(cross(x0, z0))), dot(u, r.apply(z0)));
  return light.distribution().density(local) * cosY / (distance * distance);
}

/// Points and weights (areas) of a 576-point midpoint rule on the triangle: fine enough for
/// the soft edges of a beam and of the reuse weights.
std::vector<std::pair<Vec3, double>> quadrature(const Vec3& a, const Vec3& b, const Vec3& c)
{
  constexpr int m = 24;
  std::vector<std::pair<Vec3, double>> points;
  const double area = 0.5 * length(cross(b - a, c - a)) / (m * m);
  auto at = [&](double i, double j) { return a + (b - a) * (i / m) + (c - a) * (j / m); };
  for (int i = 0; i < m; ++i)
  {
    for (int j = 0; i + j < m; ++j)
    {
      points.push_back({ (at(i, j) + at(i + 1, j) + at(i, j + 1)) / 3.0, area });
      if (i + j + 1 < m)
      {
        points.push_back({ (at(i + 1, j) + at(i, j + 1) + at(i + 1, j + 1)) / 3.0, area });
      }
    }
  }
  return points;
}

/**
 * Expects the direct radiosity of a bare floor (reflectance rho) lit by `light` to be rho
 * times the irradiance Phi p_f(y) averaged over each element, for every frame, with
 * z-scores from the exact binomial variance of the element's hits: classic, N paths each
 * landing with probability q = int_e p_f and scoring rho Phi / (N A); reuse, M_k paths from
 * each position k scoring rho Phi p_f / (A sum_m M_m p_m) where they land.
 */
void expectInverseSquare(const PointLight& light, bool reuse, std::uint64_t seed)
{
  const double rho = 0.5;
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -3, -3, 0 }, { 6, 0, 0 }, { 0, 6, 0 }, 12, 12, Rgb(rho));
  const Scene scene = Scene::fromPatchMesh(mesh);
  SolverOptions options = modeOptions(reuse, 200000, seed);
  options.twoSided = false;
  const Solution solution = solve(
    scene,
    [&]
    {
      LightRig rig;
      rig.pointLights.push_back(light);
      return rig;
    }(),
    options);
  const std::size_t n = light.frameCount();
  const double N = double(options.pathsPerFrame);
  // Paths per position: all N from the frame's own for classic.
  std::vector<double> M(n, reuse ? 0.0 : N);
  for (std::size_t k = 0; reuse && k < n; ++k)
  {
    M[k] = double(options.pathsPerFrame / n + (k < options.pathsPerFrame % n ? 1 : 0));
  }
  const Vec3 up(0, 0, 1);
  double meanSquare = 0, maxAbs = 0, lit = 0, total = 0, outside = 0, spread = 0;
  std::size_t count = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Triangle& t = scene.elementTriangles()[e];
    const auto points =
      quadrature(scene.points()[t[0]], scene.points()[t[1]], scene.points()[t[2]]);
    const double area = scene.elementArea(e);
    // first[f][k] = int_e s_f p_k and second[f][k] = int_e s_f^2 p_k, with s_f the score's
    // weight: p_f / sum_m M_m p_m for reuse, 1 / N for classic.
    std::vector<std::vector<double>> first(n, std::vector<double>(n, 0.0)), second = first;
    for (const auto& [y, w] : points)
    {
      std::vector<double> p(n);
      double mixture = 0;
      for (std::size_t k = 0; k < n; ++k)
      {
        p[k] = pointDensity(light, k, y, up);
        mixture += M[k] * p[k];
      }
      for (std::size_t f = 0; f < n; ++f)
      {
        for (std::size_t k = reuse ? 0 : f; k < (reuse ? n : f + 1); ++k)
        {
          const double s = !reuse ? 1 / N : mixture > 0 ? p[f] / mixture : 0;
          first[f][k] += w * s * p[k];
          second[f][k] += w * s * s * p[k];
        }
      }
    }
    for (std::size_t f = 0; f < n; ++f)
    {
      double mean = 0, variance = 0;
      for (std::size_t k = 0; k < n; ++k)
      {
        mean += M[k] * first[f][k];
        variance += M[k] * (second[f][k] - first[f][k] * first[f][k]);
      }
      for (int c = 0; c < 3; ++c)
      {
        // Frame f emits its pose's power factor (a TILT factor among them) times Phi.
        const double scale = rho * light.power()[c] * light.pose(f).power[c] / area;
        const double value = solution.direct(f, e, Side::Front)[c];
        total += value * area / (rho * light.power()[c] * light.pose(f).power[c]);
        if (!(variance > 0))
        {
          // The quadrature misses the beam's edge where it cuts a corner of an element.
          outside += value * area / (rho * light.power()[c] * light.pose(f).power[c]);
          continue;
        }
        lit += mean;
        spread += variance;
        if (mean * mean < 10 * variance)
        {
          // Fewer than about 10 hits expected: a single hit is far in the normal
          // approximation's tail. Such elements count in the flux only.
          continue;
        }
        const double z = (value - scale * mean) / (scale * std::sqrt(variance));
        meanSquare += z * z;
        maxAbs = std::max(maxAbs, std::abs(z));
        ++count;
      }
    }
  }
  ASSERT_GT(count, 0u);
  // A few thousand z-scores of elements with 10 or more effective hits: their mean square
  // is 1 within about 0.03.
  EXPECT_LT(meanSquare / double(count), 1.2) << (reuse ? "reuse" : "classic");
  EXPECT_LT(maxAbs, 6.0) << (reuse ? "reuse" : "classic");
  // The floor catches the flux the distribution sends to it: the sums agree within 5
  // standard errors (the elements' variances add up to a bound: their hits anticorrelate).
  EXPECT_NEAR(total / lit, 1.0, 5 * std::sqrt(spread) / lit) << (reuse ? "reuse" : "classic");
  EXPECT_LT(outside / total, 1e-3) << "light outside the beam";
  std::cout << (reuse ? "reuse" : "classic") << ": mean square z " << meanSquare / double(count)
            << ", max |z| " << maxAbs << ", flux on the floor / expected " << total / lit
            << ", outside the beam " << outside / total << "\n";
}

PointLight pointLight(const IntensityDistribution& distribution)
{
  return PointLight(Rgb(30, 20, 10), movingAndTurning({ 0, 0, 1 }), distribution);
}
}

TEST(Luminaires, LambertianPointLightFollowsTheInverseSquareLaw)
{
  expectInverseSquare(pointLight(IntensityDistribution::lambertian()), false, 71);
  expectInverseSquare(pointLight(IntensityDistribution::lambertian()), true, 72);
}

TEST(Luminaires, SpotPointLightFollowsTheInverseSquareLaw)
{
  const IntensityDistribution spot = IntensityDistribution::spot(30 * Degree, 10 * Degree);
  expectInverseSquare(pointLight(spot), false, 73);
  expectInverseSquare(pointLight(spot), true, 74);
}

TEST(Luminaires, TabulatedPointLightFollowsTheInverseSquareLaw)
{
  expectInverseSquare(pointLight(asymmetricTable()), false, 75);
  expectInverseSquare(pointLight(asymmetricTable()), true, 76);
}

TEST(Luminaires, EveryPathOfAClosedBoxLandsOnAWall)
{
  // Inside a closed box every classic path hits a wall once first: the direct radiosity over
  // rho, times the area, sums to the power per frame up to the rounding of the sums and of
  // the stored results, whatever the distribution does and however the light turns. A stored
  // value is within RelativeRounding of itself, so the sum is too: under half of one path's
  // power at N = 200.
  const double rho = 0.5;
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(rho) }));
  const Rgb power(3, 2, 1);
  LightRig rig;
  std::vector<LightPose> poses = movingAndTurning({ 0.4, 0.4, 0.5 });
  for (LightPose& pose : poses)
  {
    pose.position = pose.position * 0.5 + Vec3(0.25, 0.25, 0.25);
  }
  rig.pointLights.emplace_back(power, poses, IntensityDistribution::spot(50 * Degree, 20 * Degree));
  rig.areaLights.emplace_back(scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2), power, poses);
  rig.areaLights.back().setDistribution(IntensityDistribution::spot(35 * Degree));
  for (std::size_t light = 0; light < 2; ++light)
  {
    LightRig one;
    if (light == 0)
    {
      one.pointLights = rig.pointLights;
    }
    else
    {
      one.areaLights = rig.areaLights;
    }
    const std::uint64_t paths = 200;
    const Solution solution = solve(scene, one, modeOptions(false, paths, 90 + light));
    for (std::size_t f = 0; f < solution.frameCount(); ++f)
    {
      for (int c = 0; c < 3; ++c)
      {
        double sum = 0;
        for (std::size_t e = 0; e < scene.elementCount(); ++e)
        {
          sum += solution.direct(f, e, Side::Front)[c] * scene.elementArea(e) / rho;
        }
        const double tolerance = PackedRgb::RelativeRounding * sum / power[c] + 1e-6;
        EXPECT_LT(tolerance, 0.5 / double(paths));
        EXPECT_NEAR(sum / power[c], 1.0, tolerance) << "light " << light << " frame " << f;
      }
    }
  }
}

TEST(Luminaires, ReuseOfATurningSpotAveragesToClassic)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(
    4, true, { Rgb(0.6, 0.3, 0.3), Rgb(0.3, 0.6, 0.3), Rgb(0.6), Rgb(0.6), Rgb(0.5), Rgb(0.7) }));
  std::vector<LightPose> poses = movingAndTurning({ 0.4, 0.3, 0.8 });
  for (LightPose& pose : poses)
  {
    pose.position = pose.position * 0.5 + Vec3(0.25, 0.25, 0.25);
  }
  const IntensityDistribution spot = IntensityDistribution::spot(25 * Degree, 10 * Degree);
  for (int kind = 0; kind < 2; ++kind)
  {
    LightRig rig;
    if (kind == 0)
    {
      rig.pointLights.emplace_back(Rgb(1), poses, spot);
    }
    else
    {
      rig.areaLights.emplace_back(
        scenes::squareLightFacingDown({ 0.5, 0.5, 0.5 }, 0.2), Rgb(1), poses);
      rig.areaLights.back().setDistribution(spot);
    }
    SeedMoments moments[2];
    for (int mode = 0; mode < 2; ++mode)
    {
      for (int r = 0; r < 30; ++r)
      {
        const Solution solution =
          solve(scene, rig, modeOptions(mode == 1, 3000, 2000 + r + 100 * mode + 1000 * kind));
        const std::size_t perWall = scene.elementCount() / 6;
        std::vector<double> walls(6 * solution.frameCount(), 0.0);
        for (std::size_t f = 0; f < solution.frameCount(); ++f)
        {
          for (std::size_t e = 0; e < scene.elementCount(); ++e)
          {
            walls[f * 6 + e / perWall] +=
              solution.total(f, e, Side::Front).g * scene.elementArea(e);
          }
        }
        moments[mode].add(walls);
      }
    }
    expectSameMeans(moments[1], { &moments[0] }, kind == 0 ? "point spot" : "area spot");
  }
}

TEST(Luminaires, ExplicitLambertianAreaLightIsTheDefaultBitForBit)
{
  const Scene scene = Scene::fromPatchMesh(scenes::closedBox(4, true, { Rgb(0.5) }));
  const std::vector<LightPose> poses = movingAndTurning({ 0.5, 0.5, 0.7 });
  std::vector<LightPose> inside = poses;
  for (LightPose& pose : inside)
  {
    pose.position = pose.position * 0.5 + Vec3(0.25, 0.25, 0.25);
  }
  const MovingLight given(scenes::squareLightFacingDown({ 0.5, 0.5, 0.7 }, 0.2), Rgb(1), inside);
  MovingLight lambertian = given;
  lambertian.setDistribution(IntensityDistribution::lambertian());
  for (bool reuse : { false, true })
  {
    const SolverOptions options = modeOptions(reuse, 4000, 5);
    const Solution a = solve(scene, given, options), b = solve(scene, lambertian, options);
    for (std::size_t f = 0; f < a.frameCount(); ++f)
    {
      for (std::size_t e = 0; e < scene.elementCount(); ++e)
      {
        ASSERT_EQ(a.total(f, e, Side::Front), b.total(f, e, Side::Front));
      }
    }
  }
}

TEST(Luminaires, AreaLightFrameFollowsItsFirstPolygonAndPoses)
{
  const MovingLight light(scenes::squareLightFacingDown({ 0, 0, 1 }, 1), Rgb(1),
    std::vector<LightPose>{ turned({ 0, 0, 1 }, { 1, 0, 0 }, 90) });
  const PhotometricFrame own = light.ownPhotometricFrame();
  EXPECT_NEAR(own.z.z, -1.0, 1e-12) << "nadir: the emission normal";
  const auto& first = light.polygons()[0];
  const Vec3 edge = normalize(first[1] - first[0]);
  EXPECT_NEAR(dot(own.x, edge), 1.0, 1e-12) << "C = 0 along the first edge";
  const PhotometricFrame posed = light.photometricFrame(0);
  EXPECT_NEAR(length(posed.z - light.turn(0, own.z)), 0.0, 1e-12);
  EXPECT_NEAR(length(posed.x - light.turn(0, own.x)), 0.0, 1e-12);
}

TEST(Luminaires, PointLightRefusesBadInput)
{
  mlr::checks::expectError(
    [] { PointLight(Rgb(-1), { LightPose() }); }, "must be finite and not negative");
  // Beyond MaximumLightPower the single-precision outputs would overflow.
  mlr::checks::expectError(
    [] { PointLight(Rgb(1, 2e30, 1), { LightPose() }); }, "at most 1e+30 W per channel");
  EXPECT_NO_THROW(PointLight(Rgb(1e30), { LightPose() }));
  mlr::checks::expectError([] { PointLight(Rgb(1), {}); }, "zero frames");
}

TEST(Luminaires, PointKernelIsTheFirstHitDensityAndSeesEveryPosition)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -3, -3, 0 }, { 6, 0, 0 }, { 0, 6, 0 }, 4, 4, Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const RayTracer tracer(scene);
  const PointLight light = pointLight(IntensityDistribution::spot(30 * Degree, 10 * Degree));
  const LightSource source(PointSource(light), 0);
  KernelScratch scratch;
  scratch.resize(light.frameCount());
  const Vec3 up(0, 0, 1);
  for (const Vec3& y :
    { Vec3(0.51, -0.72, 0), Vec3(0, 0, 0), Vec3(0.3, 0.4, 0), Vec3(-0.6, 0.2, 0) })
  {
    EmittedPath path;
    const std::size_t rays = source.kernel(path, y, up, 0, tracer, scratch);
    std::size_t lit = 0;
    for (std::size_t k = 0; k < light.frameCount(); ++k)
    {
      EXPECT_NEAR(scratch.kernel[k], pointDensity(light, k, y, up), 1e-12)
        << "position " << k << " at (" << y.x << ", " << y.y << ")";
      lit += k > 0 && scratch.kernel[k] > 0 ? 1 : 0;
    }
    ASSERT_EQ(rays, lit);
    for (std::size_t s = 0; s < rays; ++s)
    {
      EXPECT_TRUE(scratch.visible[s]) << "nothing stands between the floor and the light";
    }
  }
}

namespace
{
/// The photometric frame of a point light before posing (nadir -z, C = 0 along +x) turned by
/// `pose`.
PhotometricFrame posedFrame(const LightPose& pose)
{
  const PhotometricFrame own;
  return { pose.rotation.apply(own.x), pose.rotation.apply(own.y), pose.rotation.apply(own.z) };
}
}

TEST(Luminaires, TiltAnglesFollowTheLampGeometry)
{
  using G = TiltTable::Geometry;
  const Vec3 up(0, 0, 1), at(0, 0, 2);
  auto tilt = [&](G g, const Vec3& axis, double degrees)
  { return luminaireTilt(g, posedFrame(turned(at, axis, degrees)), up); };
  // A vertical lamp tilts with the nadir, whatever the plane: 35 degrees about a horizontal
  // axis, none about the vertical, 150 (aimed nearly up).
  EXPECT_NEAR(tilt(G::Vertical, { 1, 2, 0 }, 35).angle, 35, 1e-9);
  EXPECT_NEAR(tilt(G::Vertical, { 0, 0, 1 }, 70).angle, 0, 1e-6);
  EXPECT_NEAR(tilt(G::Vertical, { 1, 0, 0 }, 150).angle, 150, 1e-9);
  EXPECT_EQ(tilt(G::Vertical, { 1, 2, 0 }, 35).untabulated, 0);
  // Turning +30 about the photometric horizontal (+x) swings the nadir towards +y.
  const PhotometricFrame swung = posedFrame(turned(at, { 1, 0, 0 }, 30));
  EXPECT_GT(swung.z.y, 0.49);
  // Geometry 3 (lamp along y): that turn tilts the lamp 30 degrees; a turn about y leaves it
  // horizontal; a turn about the vertical too.
  EXPECT_NEAR(tilt(G::HorizontalAlongC90, { 1, 0, 0 }, 30).angle, 30, 1e-9);
  EXPECT_NEAR(tilt(G::HorizontalAlongC90, { 1, 0, 0 }, -20).angle, -20, 1e-9);
  EXPECT_NEAR(tilt(G::HorizontalAlongC90, { 0, 1, 0 }, 40).angle, 0, 1e-9);
  EXPECT_NEAR(tilt(G::HorizontalAlongC90, { 0, 0, 1 }, 60).angle, 0, 1e-9);
  EXPECT_EQ(tilt(G::HorizontalAlongC90, { 0, 1, 0 }, 40).untabulated, 0);
  // Geometry 2 (lamp along x): the turn about x is the lamp's roll; a turn about y leans the
  // lamp's axis, which the table does not give.
  const LuminaireTilt roll = tilt(G::HorizontalAlongC0, { 1, 0, 0 }, 30);
  EXPECT_NEAR(roll.angle, 30, 1e-9);
  EXPECT_NEAR(roll.untabulated, 0, 1e-9);
  EXPECT_NEAR(tilt(G::HorizontalAlongC0, { 1, 0, 0 }, 120).angle, 120, 1e-9);
  const LuminaireTilt lean = tilt(G::HorizontalAlongC0, { 0, 1, 0 }, 40);
  EXPECT_NEAR(lean.angle, 0, 1e-9);
  EXPECT_NEAR(lean.untabulated, 40, 1e-9);
  // The vertical is the scene's: with +y up, a luminaire aimed along -z is tilted 90 degrees.
  EXPECT_NEAR(luminaireTilt(G::Vertical, PhotometricFrame(), { 0, 3, 0 }).angle, 90, 1e-9);
  EXPECT_NE(checks::errorOf([] { luminaireTilt(G::Vertical, PhotometricFrame(), Vec3()); })
              .find("up direction (0, 0, 0) must be finite and not zero"),
    std::string::npos);
}

TEST(Luminaires, TiltFactorsScaleThePosesAndTheirIrradiance)
{
  // A vertical lamp losing output as it tilts: the four poses tilt it 0, 25, 40 and 0 degrees
  // (the last only turns about the nadir), so they emit 1, 1 - 0.2 (25 / 30), 0.8 - 0.3 (10 /
  // 30) and 1 times their own power factors.
  TiltTable table;
  table.geometry = TiltTable::Geometry::Vertical;
  table.angles = { 0, 30, 60, 90 };
  table.factors = { 1, 0.8, 0.5, 0.2 };
  std::vector<LightPose> poses = movingAndTurning({ 0, 0, 1 });
  poses[1].power = Rgb(0.5, 1, 2);
  std::vector<std::string> warnings;
  const std::vector<LightPose> tilted =
    tiltPoses(table, PhotometricFrame(), poses, { 0, 0, 1 }, "lamp.ies", warnings);
  EXPECT_TRUE(warnings.empty());
  const double expected[] = { 1, 1 - 0.2 * 25 / 30, 0.8 - 0.3 * 10 / 30, 1 };
  for (std::size_t k = 0; k < poses.size(); ++k)
  {
    for (int c = 0; c < 3; ++c)
    {
      EXPECT_NEAR(tilted[k].power[c], poses[k].power[c] * expected[k], 1e-12) << "pose " << k;
    }
    EXPECT_EQ(tilted[k].position, poses[k].position);
  }
  // The factors reach the floor as Phi s_k f p_k(y): the inverse-square law, classic and with
  // reuse, whose mixture weights stay those of the unit-power kernels.
  const PointLight light(Rgb(30, 20, 10), tilted, asymmetricTable());
  expectInverseSquare(light, false, 77);
  expectInverseSquare(light, true, 78);

  // Poses beyond the table take its end factor, with a warning naming the first of them.
  const std::vector<LightPose> beyond = tiltPoses(table, PhotometricFrame(),
    { turned({ 0, 0, 1 }, { 1, 0, 0 }, 120), turned({ 0, 0, 1 }, { 1, 0, 0 }, 10) }, { 0, 0, 1 },
    "lamp.ies", warnings);
  EXPECT_NEAR(beyond[0].power.r, 0.2, 1e-12);
  EXPECT_NEAR(beyond[1].power.r, 1 - 0.2 / 3, 1e-12);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("lamp.ies: light position 0 tilts the luminaire by 120 degrees, "
                             "outside the TILT table's 0 to 90 (1 of 2 positions are)"),
    std::string::npos)
    << warnings[0];
  // A horizontal lamp's table of angles 0 and up is symmetric in the turn's sign; geometry 2
  // warns of a lamp axis leaning out of the horizontal.
  table.geometry = TiltTable::Geometry::HorizontalAlongC0;
  warnings.clear();
  const std::vector<LightPose> rolled = tiltPoses(table, PhotometricFrame(),
    { turned({ 0, 0, 1 }, { 1, 0, 0 }, -45), turned({ 0, 0, 1 }, { 0, 1, 0 }, 20) }, { 0, 0, 1 },
    "lamp.ies", warnings);
  EXPECT_NEAR(rolled[0].power.r, 0.65, 1e-12);
  EXPECT_NEAR(rolled[1].power.r, 1, 1e-12);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("light position 1 leans the lamp axis (C0-C180, lamp-to-luminaire "
                             "geometry 2) 20 degrees out of the horizontal"),
    std::string::npos)
    << warnings[0];
}
