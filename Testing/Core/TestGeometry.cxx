// Scene model, light polygons and the exact form factor the physics tests rely on.
#include "FormFactor.h"
#include "GeneratedScenes.h"
#include "MovingLight.h"
#include "PolygonTriangulation.h"
#include "Scene.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlr;

namespace
{
constexpr double pi = 3.14159265358979323846;

/// Differential area below the corner of a parallel a x b rectangle at distance c
/// (Howell's catalogue, case B-3).
double cornerFormFactor(double a, double b, double c)
{
  const double x = a / c, y = b / c;
  return (x / std::sqrt(1 + x * x) * std::atan(y / std::sqrt(1 + x * x)) +
           y / std::sqrt(1 + y * y) * std::atan(x / std::sqrt(1 + y * y))) /
    (2 * pi);
}
}

TEST(FormFactor, MatchesHowellCatalogueForParallelRectangle)
{
  const double a = 0.6, b = 0.3, c = 0.5;
  const std::vector<Vec3> rect = { { 0, 0, c }, { a, 0, c }, { a, b, c }, { 0, b, c } };
  EXPECT_NEAR(
    pointToPolygonFormFactor({ 0, 0, 0 }, { 0, 0, 1 }, rect), cornerFormFactor(a, b, c), 1e-12);
  // Below the centre: four corner rectangles.
  EXPECT_NEAR(pointToPolygonFormFactor({ a / 2, b / 2, 0 }, { 0, 0, 1 }, rect),
    4 * cornerFormFactor(a / 2, b / 2, c), 1e-12);
  // Winding does not matter.
  const std::vector<Vec3> reversed(rect.rbegin(), rect.rend());
  EXPECT_NEAR(pointToPolygonFormFactor({ 0.1, 0.1, 0 }, { 0, 0, 1 }, reversed),
    pointToPolygonFormFactor({ 0.1, 0.1, 0 }, { 0, 0, 1 }, rect), 1e-14);
}

TEST(FormFactor, TiltedReceiverFollowsCosineForDistantSmallSource)
{
  // A tiny square far away: F ~ cos(theta_r) cos(theta_s) A / (pi r^2).
  const double s = 1e-3, r = 10;
  const std::vector<Vec3> tiny = { { -s, -s, r }, { s, -s, r }, { s, s, r }, { -s, s, r } };
  const double theta = 0.7;
  const Vec3 n(std::sin(theta), 0, std::cos(theta));
  EXPECT_NEAR(pointToPolygonFormFactor({ 0, 0, 0 }, n, tiny),
    std::cos(theta) * 4 * s * s / (pi * r * r), 1e-12);
}

TEST(PolygonTriangulation, ConcavePolygonKeepsItsArea)
{
  // An L shape (area 3) and a star (concave), both counter-clockwise in the xy plane.
  const std::vector<Vec3> ell = { { 0, 0, 0 }, { 2, 0, 0 }, { 2, 1, 0 }, { 1, 1, 0 }, { 1, 2, 0 },
    { 0, 2, 0 } };
  const auto triangles = triangulatePolygon(ell);
  ASSERT_EQ(triangles.size(), 4u);
  double area = 0;
  for (const auto& t : triangles)
  {
    const Vec3 n = triangleAreaVector(ell[t[0]], ell[t[1]], ell[t[2]]);
    EXPECT_GT(n.z, 0) << "every ear keeps the polygon's orientation";
    area += 0.5 * length(n);
  }
  EXPECT_NEAR(area, 3.0, 1e-12);

  std::vector<Vec3> star;
  for (int i = 0; i < 10; ++i)
  {
    const double r = i % 2 ? 0.4 : 1.0, a = 2 * pi * i / 10;
    star.push_back({ r * std::cos(a), r * std::sin(a), 0 });
  }
  EXPECT_EQ(triangulatePolygon(star).size(), 8u);
}

TEST(PolygonTriangulation, SelfIntersectingPolygonIsRefused)
{
  const std::vector<Vec3> bowtie = { { 0, 0, 0 }, { 1, 1, 0 }, { 1, 0, 0 }, { 0, 1, 0 } };
  EXPECT_TRUE(triangulatePolygon(bowtie).empty());
}

TEST(Scene, SplitsEveryPatchIntoFourElementsOfAQuarterArea)
{
  const PatchMesh mesh = scenes::closedBox(3, true, { Rgb(0.5) });
  const Scene scene = Scene::fromPatchMesh(mesh);
  ASSERT_EQ(scene.elementCount(), 4 * scene.patchCount());
  EXPECT_EQ(scene.patchCount(), 6u * 3 * 3 * 2);
  EXPECT_NEAR(scene.totalArea(), 6.0, 1e-12);
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const std::size_t p = Scene::patchOfElement(e);
    EXPECT_NEAR(scene.elementArea(e), scene.patchArea(p) / 4, 1e-14);
    const Triangle& t = scene.elementTriangles()[e];
    const Vec3 n = normalize(
      triangleAreaVector(scene.points()[t[0]], scene.points()[t[1]], scene.points()[t[2]]));
    EXPECT_GT(dot(n, scene.patchNormal(p)), 0.999999)
      << "element " << e << " keeps its patch's orientation";
  }
  // Inward normals: the floor's normal points up.
  EXPECT_GT(scene.patchNormal(static_cast<std::size_t>(4 * 18)).z, 0.99);
  // Patches that share an edge share its midpoint: per face, (n+1)^2 corners plus one
  // midpoint per edge of the triangulated n x n grid.
  const std::size_t n = 3;
  EXPECT_EQ(scene.points().size(), 6 * ((n + 1) * (n + 1) + 2 * n * (n + 1) + n * n));
}

TEST(MovingLight, AreaCentroidNormalAndUniformSampling)
{
  const auto polygons = scenes::squareLightFacingDown({ 1, 2, 3 }, 0.5);
  const MovingLight light(polygons, Rgb(1, 2, 3), { Vec3(0, 0, 0), Vec3(1, 0, 0) });
  EXPECT_NEAR(light.area(), 0.25, 1e-14);
  EXPECT_NEAR(length(light.centroid() - Vec3(1, 2, 3)), 0, 1e-14);
  EXPECT_EQ(light.frameCount(), 2u);
  Vec3 mean, p, n;
  const int samples = 20000;
  for (int i = 0; i < samples; ++i)
  {
    light.samplePoint(
      (i + 0.5) / samples, std::fmod(i * 0.618034, 1.0), std::fmod(i * 0.7548777, 1.0), p, n);
    EXPECT_NEAR(n.z, -1.0, 1e-14);
    mean += p / samples;
  }
  EXPECT_NEAR(length(mean - light.centroid()), 0, 2e-3);
}
