// The light interface on its own, without a solve: each kind's reuse kernel against the
// exact form factor, the directional disc against the scene, emitted power and positions.
#include "FormFactor.h"
#include "GeneratedScenes.h"
#include "LightSource.h"
#include "RayTracer.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlr;

namespace
{
/// A 2 x 2 m floor at z = 0, facing up.
Scene floorScene()
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -1, -1, 0 }, { 2, 0, 0 }, { 0, 2, 0 }, 4, 4, Rgb(0.5, 0.5, 0.5));
  return Scene::fromPatchMesh(mesh);
}

/// (A / pi) times the mean of the kernel over uniform points of the light: the form factor
/// from y to the light in `position`, a quadrature of the kernel.
double kernelQuadrature(const MovingLight& light, const LightSource& source, std::size_t position,
  const Vec3& y, const Vec3& ny, const RayTracer& tracer, std::uint64_t samples)
{
  KernelScratch scratch;
  scratch.resize(source.positions());
  RandomStream random(3, StreamPurpose::Shooting, position);
  double sum = 0;
  for (std::uint64_t i = 0; i < samples; ++i)
  {
    EmittedPath path;
    const double u0 = random.uniform(), u1 = random.uniform(), u2 = random.uniform();
    light.samplePoint(u0, u1, u2, path.ownPoint, path.ownNormal);
    source.kernel(path, y, ny, position, tracer, scratch);
    sum += scratch.kernel[position];
  }
  return light.area() / M_PI * sum / static_cast<double>(samples);
}

std::vector<Vec3> placed(const MovingLight& light, std::size_t position)
{
  std::vector<Vec3> polygon;
  for (const Vec3& v : light.polygons()[0])
  {
    polygon.push_back(light.place(position, v));
  }
  return polygon;
}
}

TEST(LightSource, AreaKernelIntegratesToTheFormFactorOfEveryPosition)
{
  const Scene scene = floorScene();
  const RayTracer tracer(scene);
  // Moving and turning: the second and third positions tilt the light by 0.3 and 0.6 rad.
  std::vector<LightPose> poses(3);
  for (std::size_t k = 0; k < poses.size(); ++k)
  {
    const double half = 0.15 * static_cast<double>(k);
    poses[k].position = Vec3(0.2 * static_cast<double>(k), -0.1, 0.6);
    poses[k].rotation = Rotation::fromQuaternion(std::cos(half), std::sin(half), 0, 0);
  }
  const MovingLight light(scenes::squareLightFacingDown({ 0, 0, 0.6 }, 0.3), Rgb(5, 5, 5), poses);
  ASSERT_TRUE(light.rotates());
  const LightSource source(AreaSource(light), 0);
  const Vec3 up(0, 0, 1);
  for (const Vec3& y : { Vec3(0, 0, 0), Vec3(0.4, 0.3, 0), Vec3(-0.5, 0.2, 0) })
  {
    for (std::size_t k = 0; k < light.frameCount(); ++k)
    {
      const double exact = pointToPolygonFormFactor(y, up, placed(light, k));
      const double estimate = kernelQuadrature(light, source, k, y, up, tracer, 200000);
      EXPECT_NEAR(estimate, exact, 0.01 * exact)
        << "position " << k << " at (" << y.x << ", " << y.y << ")";
    }
  }
}

TEST(LightSource, AreaKernelIsZeroBehindTheLightAndForPositionsThatAreOff)
{
  const Scene scene = floorScene();
  const RayTracer tracer(scene);
  std::vector<LightPose> poses(3);
  poses[0].position = Vec3(0, 0, 0.5);
  poses[1].position = Vec3(0, 0, -0.5); // under the floor: the floor's upper side is behind it
  poses[2].position = Vec3(0.2, 0, 0.5);
  poses[2].power = Rgb(0, 0, 0);
  const MovingLight light(scenes::squareLightFacingDown({ 0, 0, 0.5 }, 0.2), Rgb(1, 1, 1), poses);
  const LightSource source(AreaSource(light), 0);
  EXPECT_EQ(source.activePositions(), (std::vector<std::size_t>{ 0, 1 }));
  KernelScratch scratch;
  scratch.resize(3);
  EmittedPath path;
  path.ownPoint = light.centroid();
  path.ownNormal = Vec3(0, 0, -1);
  const std::size_t shadowRays =
    source.kernel(path, Vec3(0.1, 0, 0), Vec3(0, 0, 1), 0, tracer, scratch);
  EXPECT_GT(scratch.kernel[0], 0);
  EXPECT_EQ(scratch.kernel[1], 0);
  EXPECT_EQ(scratch.kernel[2], 0);
  // The origin's visibility is known: no shadow ray for it, nor for zero kernels.
  EXPECT_EQ(shadowRays, 0u);
}

TEST(LightSource, DirectionalKernelIsTheCosineTowardsTheLight)
{
  const Scene scene = floorScene();
  const RayTracer tracer(scene);
  const std::vector<Vec3> towards = { { 0, 0, 1 }, { 1, 0, 1 }, { 0, -3, 1 }, { 1, 0, -1 },
    { 0, 1, 2 } };
  const std::vector<Rgb> factors = { Rgb(1), Rgb(1), Rgb(0.5), Rgb(1), Rgb(0) };
  const DirectionalLight light(towards, Rgb(100, 100, 100), factors);
  const LightSource source(DirectionalSource(light, Vec3(0, 0, 0), 1.5), 0);
  KernelScratch scratch;
  scratch.resize(towards.size());
  const Vec3 ny(0, 0, 1);
  const std::size_t shadowRays = source.kernel({}, Vec3(0.3, 0.2, 0), ny, 0, tracer, scratch);
  for (std::size_t k = 0; k < towards.size(); ++k)
  {
    const double expected =
      factors[k].maxComponent() > 0 ? std::max(0.0, dot(ny, light.direction(k))) : 0.0;
    EXPECT_DOUBLE_EQ(scratch.kernel[k], expected) << "position " << k;
  }
  // Positions 1 and 2 are above the horizon, lit and not the origin: the open sky is visible.
  ASSERT_EQ(shadowRays, 2u);
  EXPECT_EQ(scratch.targetFrames[0], 1u);
  EXPECT_EQ(scratch.targetFrames[1], 2u);
  EXPECT_TRUE(scratch.visible[0] && scratch.visible[1]);
}

TEST(LightSource, DirectionalDiscCoversTheSceneAndCarriesItsIrradiance)
{
  PatchMesh mesh;
  scenes::addBox(mesh, { 2, -1, 0 }, { 5, 3, 4 }, 1.0, false, std::vector<Rgb>(6, Rgb(0.5)), true);
  const Scene scene = Scene::fromPatchMesh(mesh);
  LightRig rig;
  rig.directionalLights.emplace_back(
    std::vector<Vec3>{ { 0, 0, 1 }, { 1, 2, 0.5 }, { -1, 0, 0.1 } }, Rgb(1000, 800, 600));
  const std::vector<LightSource> sources = lightSources(scene, rig, {});
  ASSERT_EQ(sources.size(), 1u);
  const LightSource& source = sources[0];
  const DirectionalSource& sun = std::get<DirectionalSource>(source.kind());
  const DirectionalLight& light = rig.directionalLights[0];
  const double offset = 1e-3;
  RandomStream random(5, StreamPurpose::Shooting, 0);
  for (std::size_t k = 0; k < light.frameCount(); ++k)
  {
    const BoundingDisc disc = sun.boundingDisc(k, offset);
    EXPECT_NEAR(length(disc.normal - light.direction(k)), 0, 1e-15);
    // Every point of the scene is behind the disc and within its radius across: every
    // ray towards the scene that could hit it starts on the disc.
    for (const Vec3& p : scene.points())
    {
      const Vec3 d = p - disc.centre;
      EXPECT_LT(dot(d, disc.normal), 0);
      EXPECT_LE(length(d - disc.normal * dot(d, disc.normal)), disc.radius);
    }
    // The power a path set carries is the irradiance times the disc's area.
    const Rgb expected = light.irradiance() * (M_PI * disc.radius * disc.radius);
    EXPECT_DOUBLE_EQ(source.power().r, expected.r);
    EXPECT_DOUBLE_EQ(source.power().b, expected.b);
    for (int i = 0; i < 1000; ++i)
    {
      EmittedPath path;
      source.emit(k, random, offset, path);
      const Vec3 d = path.start - disc.centre;
      EXPECT_NEAR(dot(d, disc.normal), 0, 1e-12);
      EXPECT_LE(length(d), disc.radius);
      EXPECT_NEAR(length(path.direction + disc.normal), 0, 1e-15);
    }
  }
}

TEST(LightSource, EmittedPathsStartOnTheLightAndLeaveItsFront)
{
  const Scene scene = floorScene();
  std::vector<LightPose> poses(2);
  poses[0].position = Vec3(0, 0, 0.5);
  poses[1].position = Vec3(0.3, 0.1, 0.7);
  poses[1].rotation = Rotation::fromQuaternion(std::cos(0.2), 0, std::sin(0.2), 0);
  const MovingLight light(scenes::squareLightFacingDown({ 0, 0, 0.5 }, 0.2), Rgb(2, 3, 4), poses);
  const LightSource source(AreaSource(light), 0);
  EXPECT_EQ(source.power(), light.power());
  RandomStream random(1, StreamPurpose::Shooting, 0);
  for (std::size_t k = 0; k < 2; ++k)
  {
    const Vec3 normal = light.turn(k, Vec3(0, 0, -1));
    const Vec3 centre = light.place(k, light.centroid());
    for (int i = 0; i < 1000; ++i)
    {
      EmittedPath path;
      source.emit(k, random, 1e-6, path);
      EXPECT_GT(dot(path.direction, normal), 0);
      EXPECT_NEAR(dot(path.start - centre, normal), 1e-6, 1e-12); // on the plane, lifted
      EXPECT_LE(length(path.start - centre), 0.2 * std::sqrt(0.5) + 1e-9);
    }
  }
}
