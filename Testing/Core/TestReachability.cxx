// Reachability and the choice of gathering sides on their own, without a solve: which patch
// sides light can reach comes from geometry alone, and only reachable, reflecting sides gather.
#include "Gathering.h"
#include "GeneratedScenes.h"
#include "LightSource.h"
#include "OccluderScenes.h"
#include "RayTracer.h"
#include "Reachability.h"

#include <gtest/gtest.h>

#include <algorithm>

using namespace mlr;
using mlr::scenes::FaceGroup;
using mlr::scenes::OccludedRoom;

namespace
{
/// The sides (patch * 2 + side) the occluded room's light can reach: the faces' sides, less
/// the floor closed in under the block.
std::vector<std::uint8_t> expectedSides(const OccludedRoom& room, std::size_t patches)
{
  std::vector<std::uint8_t> expected(2 * patches, 0);
  for (const FaceGroup& face : room.faces)
  {
    for (std::size_t p = face.firstPatch; p < face.firstPatch + face.patchCount; ++p)
    {
      expected[2 * p + static_cast<std::size_t>(face.side)] = 1;
    }
  }
  for (std::size_t p : room.patchesUnderBlock)
  {
    expected[2 * p] = 0;
  }
  return expected;
}

std::vector<std::uint8_t> reachable(const Scene& scene, const LightRig& rig,
  const SolverOptions& options, int workers, std::uint64_t& rays)
{
  const RayTracer tracer(scene);
  const std::vector<LightSource> sources = lightSources(scene, rig, sceneEmitters(scene));
  return reachableSides(
    scene, tracer, sources, options, workers, [](double) { return true; }, rays);
}
}

TEST(Reachability, EverySideLightCanReachAndNoOther)
{
  const OccludedRoom room = scenes::occludedRoom(3);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  LightRig rig;
  rig.areaLights.emplace_back(room.light, room.power, room.translations);
  const std::vector<std::uint8_t> expected = expectedSides(room, scene.patchCount());
  SolverOptions options;
  for (int workers : { 1, 2 })
  {
    std::uint64_t rays = 0;
    const std::vector<std::uint8_t> sides = reachable(scene, rig, options, workers, rays);
    EXPECT_EQ(sides, expected) << workers << " workers";
    // The light's 16384 probes spread evenly over its 3 positions, then
    // ReachabilityProbesPerSide from every side.
    EXPECT_EQ(rays, 16384 / 3 * 3 + scene.patchCount() * 2 * ReachabilityProbesPerSide);
  }
  // The sides the light probes hit first: reached, some of them, and the same for any
  // worker count (the memory plan counts direct light there).
  std::vector<std::uint8_t> oneWorker, twoWorkers;
  {
    const RayTracer tracer(scene);
    const std::vector<LightSource> sources = lightSources(scene, rig, sceneEmitters(scene));
    std::uint64_t rays = 0;
    reachableSides(
      scene, tracer, sources, options, 1, [](double) { return true; }, rays, &oneWorker);
    reachableSides(
      scene, tracer, sources, options, 2, [](double) { return true; }, rays, &twoWorkers);
  }
  EXPECT_EQ(oneWorker, twoWorkers);
  ASSERT_EQ(oneWorker.size(), expected.size());
  std::size_t firstHits = 0;
  for (std::size_t i = 0; i < expected.size(); ++i)
  {
    EXPECT_LE(oneWorker[i], expected[i]) << "side " << i;
    firstHits += oneWorker[i];
  }
  EXPECT_GT(firstHits, 0u);
  EXPECT_LT(firstHits, static_cast<std::size_t>(std::count(expected.begin(), expected.end(), 1)))
    << "some reachable sides are lit only by bounces";
  // From geometry alone: the solve's seed and N do not change it.
  options.seed = 99;
  options.pathsPerFrame = 17;
  std::uint64_t rays = 0;
  EXPECT_EQ(reachable(scene, rig, options, 2, rays), expected);
}

TEST(Reachability, OneSidedBackFacesAreNeverReached)
{
  const OccludedRoom room = scenes::occludedRoom(2);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  LightRig rig;
  rig.areaLights.emplace_back(room.light, room.power, room.translations);
  SolverOptions options;
  options.twoSided = false;
  std::uint64_t rays = 0;
  const std::vector<std::uint8_t> sides = reachable(scene, rig, options, 2, rays);
  std::vector<std::uint8_t> expected = expectedSides(room, scene.patchCount());
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    EXPECT_EQ(sides[2 * p + 1], 0) << "patch " << p;
    EXPECT_EQ(sides[2 * p], expected[2 * p]) << "patch " << p;
  }
}

TEST(Reachability, ALightOffInEveryFrameReachesNothing)
{
  const OccludedRoom room = scenes::occludedRoom(2);
  const Scene scene = Scene::fromPatchMesh(room.mesh);
  std::vector<LightPose> poses(2);
  for (std::size_t k = 0; k < 2; ++k)
  {
    poses[k].position =
      room.translations[k] + MovingLight(room.light, room.power, room.translations).centroid();
    poses[k].power = Rgb(0, 0, 0);
  }
  LightRig rig;
  rig.areaLights.emplace_back(room.light, room.power, poses);
  std::uint64_t rays = 0;
  const std::vector<std::uint8_t> sides = reachable(scene, rig, SolverOptions(), 1, rays);
  EXPECT_EQ(std::count(sides.begin(), sides.end(), 1), 0);
}

TEST(GatheringSides, OnlyReachableSidesThatReflectGatherAndShareTheRays)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  mesh.reflectance[3] = Rgb(0, 0, 0); // black: it reflects nothing it would gather
  const Scene scene = Scene::fromPatchMesh(mesh);
  std::vector<std::uint8_t> reachableSides(2 * scene.patchCount(), 0);
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    reachableSides[2 * p] = 1; // the fronts
  }
  reachableSides[2 * 5 + 1] = 1; // and one back
  double rays = 0;
  const std::vector<std::uint32_t> sides = gatheringSides(scene, reachableSides, rays, 1000);
  std::vector<std::uint32_t> expected;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const std::size_t p = Scene::patchOfElement(e);
    if (p != 3)
    {
      expected.push_back(static_cast<std::uint32_t>(2 * e));
    }
    if (p == 5)
    {
      expected.push_back(static_cast<std::uint32_t>(2 * e + 1));
    }
  }
  EXPECT_EQ(sides, expected);
  EXPECT_DOUBLE_EQ(rays, 1000.0 / static_cast<double>(expected.size()));
  // Fewer rays than sides: every side still casts one.
  gatheringSides(scene, reachableSides, rays, 3);
  EXPECT_EQ(rays, 1.0);
  // Nothing reachable: nothing gathers.
  EXPECT_TRUE(
    gatheringSides(scene, std::vector<std::uint8_t>(2 * scene.patchCount(), 0), rays, 1000)
      .empty());
  EXPECT_EQ(rays, 0.0);
}
