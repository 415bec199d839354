// How gathering reads a patch's bounced light at its four elements (Core/Reconstruction.h): a
// linear field is read exactly, the patch's mean and its neighbours' range are kept whatever
// the values, and creases, other materials and flipped neighbours are told apart.
#include "Gathering.h"
#include "GeneratedScenes.h"
#include "Reconstruction.h"
#include "Scene.h"
#include "Solution.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>

namespace mlr
{
namespace
{
Vec3 centroidOf(const Scene& scene, const Triangle& t)
{
  return (scene.points()[t[0]] + scene.points()[t[1]] + scene.points()[t[2]]) / 3.0;
}

/// A floor of 6 x 6 cells (72 patches) in the plane z = 0.
Scene floorOfCells()
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 3, 0, 0 }, { 0, 3, 0 }, 6, 6, Rgb(0.5));
  return Scene::fromPatchMesh(mesh);
}

double linearField(const Vec3& p)
{
  return 2.0 + 0.5 * p.x - 0.3 * p.y;
}
}

TEST(Reconstruction, ALinearFieldIsReadExactlyAtTheElements)
{
  // A patch's mean of a linear field is its value at the centroid; the least-squares gradient
  // from three neighbours is the field's, so each element reads the field at its centroid.
  // Through the solution as gathering reads it: the bounced light is stored per patch.
  const Scene scene = floorOfCells();
  Solution solution(1, scene.elementCount(), scene.patchCount());
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    solution.patchData()[solution.patchIndex(0, p, Side::Front)] =
      solution.store(Rgb(linearField(centroidOf(scene, scene.patchTriangles()[p]))));
  }
  std::size_t inner = 0;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    if (scene.patchStencil(p).count < 3)
    {
      continue; // on the floor's edge: a gradient along the edge only
    }
    ++inner;
    for (std::size_t k = 0; k < Scene::ElementsPerPatch; ++k)
    {
      const std::size_t e = p * Scene::ElementsPerPatch + k;
      const double expected = linearField(centroidOf(scene, scene.elementTriangles()[e]));
      // Each stored value is rounded to within PackedRgb::RelativeRounding.
      EXPECT_NEAR(gatheredRadiosity(scene, solution, 0, e, Side::Front).r, expected,
        4 * PackedRgb::RelativeRounding * expected)
        << "element " << k << " of patch " << p;
    }
  }
  EXPECT_GE(inner, 40u);
  // A field that does not vary is read as it is on every patch, edges included.
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    const Rgb v(1.5, 0.25, 0);
    Rgb neighbours[LinearStencil::MaxNeighbours] = { v, v, v }, out[4];
    scene.patchStencil(p).elementValues(v, neighbours, out);
    for (const Rgb& x : out)
    {
      EXPECT_EQ(x.r, v.r);
      EXPECT_EQ(x.g, v.g);
      EXPECT_EQ(x.b, v.b);
    }
  }
}

TEST(Reconstruction, KeepsThePatchMeanAndNeverReadsBelowZero)
{
  // Any values, zeros and spikes included: the four elements' mean is the patch's value (its
  // elements have equal areas), and no element reads less than zero, where a patch of 0.1
  // beside one of 100 would have a corner far below zero without the limiter.
  const Scene scene = floorOfCells();
  std::mt19937 random(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  std::size_t limited = 0;
  for (int trial = 0; trial < 200; ++trial)
  {
    for (std::size_t p = 0; p < scene.patchCount(); ++p)
    {
      const LinearStencil& s = scene.patchStencil(p);
      auto draw = [&]
      {
        const double u = uniform(random);
        return u < 0.3 ? 0.0 : (u > 0.9 ? 100 * u : u);
      };
      const Rgb v(draw(), draw(), draw());
      Rgb neighbours[LinearStencil::MaxNeighbours], out[4];
      for (int i = 0; i < s.count; ++i)
      {
        neighbours[i] = Rgb(draw(), draw(), draw());
      }
      s.elementValues(v, neighbours, out);
      for (int c = 0; c < 3; ++c)
      {
        double sum = 0;
        bool zero = false;
        for (const Rgb& x : out)
        {
          EXPECT_GE(x[c], 0.0);
          zero = zero || x[c] == 0;
          sum += x[c];
        }
        // Limited: an element at zero that the unlimited gradient would have taken below it.
        limited += zero && v[c] > 0;
        EXPECT_NEAR(sum / 4, v[c], 1e-12 * (v[c] + 1));
      }
    }
  }
  EXPECT_GT(limited, 0u) << "the limiter never acted: the test does not test it";
}

TEST(Reconstruction, CreasesOtherMaterialsAndFlippedNeighbours)
{
  // A floor and a wall meeting at an edge, the wall's top row of another reflectance, and a
  // triangle beside the floor wound the other way.
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 2, 2, Rgb(0.5));
  const std::size_t floorPatches = mesh.triangles.size();
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 0, 0, 1 }, { 1, 0, 0 }, 2, 2, Rgb(0.5));
  for (std::size_t t = mesh.triangles.size() - 2; t < mesh.triangles.size(); ++t)
  {
    mesh.reflectance[t] = Rgb(0.7, 0.1, 0.1);
  }
  // The flipped triangle shares the floor's edge x = 1 from (1,0) to (1,0.5), if the grid has
  // that edge, else one of its edges along x = 1.
  const Scene floorOnly = Scene::fromPatchMesh(mesh);
  std::uint32_t a = 0, b = 0;
  bool found = false;
  for (std::size_t p = 0; p < floorPatches && !found; ++p)
  {
    const Triangle& t = floorOnly.patchTriangles()[p];
    for (int i = 0; i < 3 && !found; ++i)
    {
      const std::uint32_t u = t[static_cast<std::size_t>(i)],
                          w = t[static_cast<std::size_t>((i + 1) % 3)];
      if (mesh.points[u].x == 1 && mesh.points[w].x == 1 && mesh.points[u].z == 0 &&
        mesh.points[w].z == 0)
      {
        a = u;
        b = w;
        found = true;
      }
    }
  }
  ASSERT_TRUE(found);
  mesh.points.push_back({ 1.5, 0.5 * (mesh.points[a].y + mesh.points[b].y), 0 });
  // Wound so that its normal faces down while the floor's faces up (or the other way).
  const auto apex = static_cast<std::uint32_t>(mesh.points.size() - 1);
  mesh.triangles.push_back({ a, b, apex });
  mesh.reflectance.push_back(Rgb(0.5));
  const Scene scene = Scene::fromPatchMesh(mesh);
  const std::size_t flippedPatch = scene.patchCount() - 1;

  std::size_t flips = 0;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    const LinearStencil& s = scene.patchStencil(p);
    for (int i = 0; i < s.count; ++i)
    {
      const std::size_t q = s.neighbour[static_cast<std::size_t>(i)];
      const double c = dot(scene.patchNormal(p), scene.patchNormal(q));
      EXPECT_GE(std::abs(c), 0.99) << "patch " << p << " reads " << q << " across a crease";
      EXPECT_EQ(s.flipped[static_cast<std::size_t>(i)], c < 0);
      const Rgb& r = scene.patchReflectance(p);
      const Rgb& rq = scene.patchReflectance(q);
      EXPECT_TRUE(r.r == rq.r && r.g == rq.g && r.b == rq.b)
        << "patch " << p << " reads " << q << " of another material";
      flips += s.flipped[static_cast<std::size_t>(i)];
    }
  }
  const Vec3& n = scene.patchNormal(flippedPatch);
  const Triangle& t = scene.patchTriangles()[0];
  const Vec3 floorNormal =
    normalize(triangleAreaVector(scene.points()[t[0]], scene.points()[t[1]], scene.points()[t[2]]));
  ASSERT_LT(dot(n, floorNormal), -0.99) << "the added triangle is not wound the other way";
  EXPECT_EQ(scene.patchStencil(flippedPatch).count, 1);
  EXPECT_TRUE(scene.patchStencil(flippedPatch).flipped[0]);
  EXPECT_EQ(flips, 2u); // the flipped triangle and its floor neighbour read each other
}

} // namespace mlr
