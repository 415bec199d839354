// The surfaces whose elements show one side: smooth, consistently oriented patches joined
// through their shared edges, ended by creases and folds.
#include "GeneratedScenes.h"
#include "Scene.h"
#include "SurfaceRegions.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <set>

using namespace mlr;

namespace
{
constexpr double Degree = M_PI / 180.0;

/// Two unit squares of 2 x 2 cells sharing the edge x = 0 (y in [0, 1]): the first in the
/// plane z = 0 over x in [-1, 0], facing +z; the second bent up by `bend` degrees about the
/// shared edge, consistently oriented (its normal turned by `bend` too).
PatchMesh bentSheet(double bend)
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { -1, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  const Vec3 u(std::cos(bend * Degree), 0, std::sin(bend * Degree));
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, u, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  // The second square's points along x = 0 are the first's: share them, as a mesh does.
  const std::uint32_t firstOfSecond = 9;
  for (Triangle& t : mesh.triangles)
  {
    for (std::uint32_t& v : t)
    {
      // Point (0, j) of the second grid is point (2, j) of the first.
      if (v >= firstOfSecond && (v - firstOfSecond) % 3 == 0)
      {
        v = (v - firstOfSecond) / 3 * 3 + 2;
      }
    }
  }
  return mesh;
}

std::set<std::uint32_t> regionsOf(const Scene& scene, std::size_t begin, std::size_t end)
{
  std::set<std::uint32_t> regions;
  for (std::size_t p = begin; p < end; ++p)
  {
    regions.insert(scene.patchRegion(p));
  }
  return regions;
}
}

TEST(SurfaceRegions, ABendUpToTheCreaseAngleKeepsOneSurfaceAndASharperOneSplitsIt)
{
  for (const double bend : { 0.0, 20.0, 29.0, 31.0, 45.0, 90.0, 150.0 })
  {
    const Scene scene = Scene::fromPatchMesh(bentSheet(bend));
    SCOPED_TRACE(bend);
    ASSERT_EQ(scene.patchCount(), 16u);
    // Each square is one surface (its own cells are flat), numbered in patch order.
    EXPECT_EQ(regionsOf(scene, 0, 8), std::set<std::uint32_t>{ 0 });
    const std::uint32_t second = bend <= CreaseAngleDegrees ? 0 : 1;
    EXPECT_EQ(regionsOf(scene, 8, 16), std::set<std::uint32_t>{ second });
    EXPECT_EQ(scene.regionCount(), second + 1u);
  }
}

TEST(SurfaceRegions, AFlippedOrFoldedPatchIsNotJoined)
{
  // A flat grid with one triangle wound the other way: its normal is opposite, so it faces
  // the other way and is a surface of its own; its neighbours stay one surface through
  // the grid's other edges.
  PatchMesh flipped;
  scenes::addGriddedQuad(flipped, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 3, 3, Rgb(0.5));
  std::swap(flipped.triangles[8][1], flipped.triangles[8][2]);
  const Scene a = Scene::fromPatchMesh(flipped);
  EXPECT_EQ(a.regionCount(), 2u);
  EXPECT_EQ(a.patchRegion(8), 1u);
  EXPECT_EQ(regionsOf(a, 0, 8), std::set<std::uint32_t>{ 0 });
  EXPECT_EQ(regionsOf(a, 9, 18), std::set<std::uint32_t>{ 0 });

  // Two triangles on the same side of their shared edge, one folded back over the other
  // (almost flat onto it): their normals are 10 degrees apart but they run along the edge the
  // same way, so no surface passes from one to the other.
  PatchMesh folded;
  folded.points = { { 0, 0, 0 }, { 1, 0, 0 }, { 0.5, 1, 0 },
    { 0.5, std::cos(10 * Degree), std::sin(10 * Degree) } };
  folded.triangles = { { 0, 1, 2 }, { 0, 1, 3 } };
  folded.reflectance = { Rgb(0.5), Rgb(0.5) };
  const Scene b = Scene::fromPatchMesh(folded);
  ASSERT_GT(dot(b.patchNormal(0), b.patchNormal(1)), std::cos(CreaseAngleDegrees * Degree));
  EXPECT_EQ(b.regionCount(), 2u);
}

TEST(SurfaceRegions, ASphereIsOneSurfaceAndABoxSix)
{
  // A fine sphere bends by a few degrees per edge: one surface all round. A box's faces meet
  // at 90 degrees: six surfaces, whether they share their edges' points or not.
  const PolygonSoup sphere = scenes::icosphere(8);
  PatchMesh mesh;
  mesh.points = sphere.points;
  for (const std::vector<std::uint32_t>& polygon : sphere.polygons)
  {
    mesh.triangles.push_back({ polygon[0], polygon[1], polygon[2] });
    mesh.reflectance.push_back(Rgb(0.5));
  }
  const Scene ball = Scene::fromPatchMesh(mesh);
  EXPECT_EQ(ball.regionCount(), 1u);

  PatchMesh box;
  scenes::addBox(box, { 0, 0, 0 }, { 1, 2, 3 }, 0.25, false, { Rgb(0.5) });
  for (const bool welded : { false, true })
  {
    if (welded)
    {
      // The faces' points along the box's edges made one, as a closed mesh has them.
      std::map<std::array<double, 3>, std::uint32_t> first;
      for (Triangle& t : box.triangles)
      {
        for (std::uint32_t& v : t)
        {
          const Vec3& q = box.points[v];
          v = first.emplace(std::array<double, 3>{ q.x, q.y, q.z }, v).first->second;
        }
      }
    }
    const Scene six = Scene::fromPatchMesh(box);
    SCOPED_TRACE(welded ? "welded" : "faces apart");
    EXPECT_EQ(six.regionCount(), 6u);
    // One region per face, faces in patch order (-x, +x, -y, +y, -z, +z).
    const std::size_t perFace[] = { 192, 192, 96, 96, 64, 64 };
    std::size_t begin = 0;
    for (std::uint32_t face = 0; face < 6; ++face)
    {
      EXPECT_EQ(regionsOf(six, begin, begin + perFace[face]), std::set<std::uint32_t>{ face });
      begin += perFace[face];
    }
  }
}
