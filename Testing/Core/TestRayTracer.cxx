// RayTracer on a scene whose answers are known in closed form: a unit floor at z = 0 facing
// up and a small blocker [0.4, 0.6]^2 at z = 0.5 facing down. Nearest hits (element, side,
// point and distance), misses, nearestSide against intersect, visibility of segments and of
// directions, the surface offset, and a scene far from the origin.
#include "Random.h"
#include "RayTracer.h"
#include "Scene.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <optional>
#include <thread>
#include <vector>

using namespace mlr;

namespace
{
constexpr double BlockerLow = 0.4, BlockerHigh = 0.6, BlockerHeight = 0.5;

/// A horizontal square [lo, hi]^2 at height z as two patches, facing up or down.
void addSquare(PatchMesh& mesh, double lo, double hi, double z, bool up)
{
  const auto first = static_cast<std::uint32_t>(mesh.points.size());
  mesh.points.insert(
    mesh.points.end(), { { lo, lo, z }, { hi, lo, z }, { hi, hi, z }, { lo, hi, z } });
  if (up)
  {
    mesh.triangles.push_back({ first, first + 1, first + 2 });
    mesh.triangles.push_back({ first, first + 2, first + 3 });
  }
  else
  {
    mesh.triangles.push_back({ first, first + 2, first + 1 });
    mesh.triangles.push_back({ first, first + 3, first + 2 });
  }
  mesh.reflectance.insert(mesh.reflectance.end(), 2, Rgb(0.5));
}

PatchMesh floorAndBlocker(const Vec3& shift = Vec3())
{
  PatchMesh mesh;
  addSquare(mesh, 0, 1, 0, true);
  addSquare(mesh, BlockerLow, BlockerHigh, BlockerHeight, false);
  for (Vec3& p : mesh.points)
  {
    p += shift;
  }
  return mesh;
}

/// The element of `scene` whose triangle contains p (all elements are horizontal), or -1.
int elementAt(const Scene& scene, const Vec3& p)
{
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    const Triangle& t = scene.elementTriangles()[e];
    const Vec3 &a = scene.points()[t[0]], &b = scene.points()[t[1]], &c = scene.points()[t[2]];
    if (std::abs(p.z - a.z) > 1e-9)
    {
      continue;
    }
    auto edge = [&](const Vec3& u, const Vec3& v)
    { return (v.x - u.x) * (p.y - u.y) - (v.y - u.y) * (p.x - u.x); };
    const double e0 = edge(a, b), e1 = edge(b, c), e2 = edge(c, a);
    if ((e0 >= 0 && e1 >= 0 && e2 >= 0) || (e0 <= 0 && e1 <= 0 && e2 <= 0))
    {
      return static_cast<int>(e);
    }
  }
  return -1;
}

/// The analytic nearest hit of origin + t d, t > 0: the distance and whether it is the
/// blocker; nothing on a miss. `ambiguous` is set when the answer is within `margin` of an
/// edge of a square, where single-precision tracing may decide either way.
struct Expected
{
  double distance;
  bool blocker;
};
std::optional<Expected> analyticHit(
  const Vec3& o, const Vec3& d, bool& ambiguous, double margin = 1e-4)
{
  std::optional<Expected> best;
  ambiguous = false;
  auto consider = [&](double z, double lo, double hi, bool blocker)
  {
    if (d.z == 0)
    {
      return;
    }
    const double t = (z - o.z) / d.z;
    if (t <= 0)
    {
      return;
    }
    const double x = o.x + t * d.x, y = o.y + t * d.y;
    const double inside = std::min({ x - lo, hi - x, y - lo, hi - y });
    if (std::abs(inside) < margin || t * length(d) < margin)
    {
      ambiguous = true;
    }
    if (inside > 0 && (!best || t * length(d) < best->distance))
    {
      best = Expected{ t * length(d), blocker };
    }
  };
  consider(0, 0, 1, false);
  consider(BlockerHeight, BlockerLow, BlockerHigh, true);
  return best;
}

/// The segment from o to o + d crosses a square (ends excluded).
bool analyticallyBlocked(const Vec3& o, const Vec3& d, bool& ambiguous)
{
  const std::optional<Expected> hit = analyticHit(o, d, ambiguous);
  return hit && hit->distance < length(d) * (1 - 1e-6);
}

Vec3 randomDirection(RandomStream& random)
{
  Vec3 d;
  do
  {
    d = Vec3(2 * random.uniform() - 1, 2 * random.uniform() - 1, 2 * random.uniform() - 1);
  } while (lengthSquared(d) > 1 || lengthSquared(d) < 1e-6);
  return d;
}
}

TEST(RayTracer, HitsTheRightElementSideAndDistance)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  const struct
  {
    Vec3 origin, direction;
    Vec3 point;
    Side side;
    double distance;
  } cases[] = {
    // Onto the floor from above (its front), with a direction that is not unit.
    { { 0.2, 0.3, 1 }, { 0, 0, -1 }, { 0.2, 0.3, 0 }, Side::Front, 1.0 },
    { { 0.2, 0.3, 1 }, { 0, 0, -4 }, { 0.2, 0.3, 0 }, Side::Front, 1.0 },
    { { 0.8, 0.1, 2 }, { -0.2, 0.2, -2 }, { 0.6, 0.3, 0 }, Side::Front, std::sqrt(0.08 + 4) },
    // Onto the floor from below (its back).
    { { 0.7, 0.9, -0.25 }, { 0, 0, 1 }, { 0.7, 0.9, 0 }, Side::Back, 0.25 },
    // The blocker from above is its back (it faces down), from below its front.
    { { 0.52, 0.45, 1 }, { 0, 0, -1 }, { 0.52, 0.45, 0.5 }, Side::Back, 0.5 },
    { { 0.55, 0.42, 0.1 }, { 0, 0, 1 }, { 0.55, 0.42, 0.5 }, Side::Front, 0.4 },
  };
  for (const auto& c : cases)
  {
    RayHit hit;
    ASSERT_TRUE(tracer.intersect(c.origin, c.direction, hit)) << c.point.x << " " << c.point.y;
    EXPECT_EQ(static_cast<int>(hit.element), elementAt(scene, c.point));
    EXPECT_EQ(hit.side, c.side);
    EXPECT_NEAR(hit.distance, c.distance, 1e-5);
    EXPECT_NEAR(length(hit.point - c.point), 0.0, 1e-5);
    std::uint32_t element = 0;
    Side side = Side::Front;
    ASSERT_TRUE(tracer.nearestSide(c.origin, c.direction, element, side));
    EXPECT_EQ(element, hit.element);
    EXPECT_EQ(side, hit.side);
  }
}

TEST(RayTracer, MissesWhatIsNotThere)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  const struct
  {
    Vec3 origin, direction;
  } cases[] = {
    { { 2, 2, 1 }, { 0, 0, -1 } },      // beside the floor
    { { 0.2, 0.3, 1 }, { 0, 0, 1 } },   // away from everything
    { { 0.2, 0.3, 0.2 }, { 1, 0, 0 } }, // parallel to both squares, between them
    { { 0.5, 0.5, -1 }, { 0, 0, -1 } }, // below the floor, going down
  };
  for (const auto& c : cases)
  {
    RayHit hit;
    EXPECT_FALSE(tracer.intersect(c.origin, c.direction, hit));
    std::uint32_t element;
    Side side;
    EXPECT_FALSE(tracer.nearestSide(c.origin, c.direction, element, side));
  }
}

TEST(RayTracer, RandomRaysAgreeWithTheClosedFormAndNearestSide)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  RandomStream random(7, StreamPurpose::Shooting, 1);
  int hits = 0, blockerHits = 0, misses = 0;
  for (int i = 0; i < 20000; ++i)
  {
    const Vec3 origin(
      -0.5 + 2 * random.uniform(), -0.5 + 2 * random.uniform(), -1 + 3 * random.uniform());
    // A third of the rays aim at the floor's plane, a third at the blocker's, around and
    // across their edges; the others go anywhere.
    Vec3 direction = randomDirection(random);
    if (i % 3 == 0)
    {
      direction = Vec3(-0.2 + 1.4 * random.uniform(), -0.2 + 1.4 * random.uniform(), 0) - origin;
    }
    else if (i % 3 == 1)
    {
      direction =
        Vec3(0.3 + 0.4 * random.uniform(), 0.3 + 0.4 * random.uniform(), BlockerHeight) - origin;
    }
    direction = direction * (0.1 + 3 * random.uniform());
    bool ambiguous = false;
    const std::optional<Expected> expected = analyticHit(origin, direction, ambiguous);
    RayHit hit;
    const bool found = tracer.intersect(origin, direction, hit);
    std::uint32_t element = 0;
    Side side = Side::Front;
    ASSERT_EQ(tracer.nearestSide(origin, direction, element, side), found) << i;
    if (found)
    {
      EXPECT_EQ(element, hit.element) << i;
      EXPECT_EQ(side, hit.side) << i;
    }
    if (ambiguous)
    {
      continue;
    }
    ASSERT_EQ(found, expected.has_value()) << i;
    if (!found)
    {
      ++misses;
      continue;
    }
    ++hits;
    EXPECT_NEAR(hit.distance, expected->distance, 1e-5 * (1 + expected->distance)) << i;
    const Vec3 along = origin + direction * (hit.distance / length(direction));
    EXPECT_NEAR(length(hit.point - along), 0.0, 1e-4) << i;
    const bool onBlocker = scene.patchOfElement(hit.element) >= 2;
    EXPECT_EQ(onBlocker, expected->blocker) << i;
    blockerHits += onBlocker ? 1 : 0;
    EXPECT_EQ(static_cast<int>(hit.element), elementAt(scene, hit.point)) << i;
    // The side facing the ray: its normal points against the ray.
    EXPECT_LT(dot(scene.elementSideNormal(hit.element, hit.side), direction), 0) << i;
  }
  // The sample covers all three outcomes.
  std::printf("%d hits, %d of them on the blocker, %d misses\n", hits, blockerHits, misses);
  EXPECT_GT(hits, 2000);
  EXPECT_GT(blockerHits, 1000);
  EXPECT_GT(misses, 2000);
}

TEST(RayTracer, QueriesFromManyThreadsGiveTheSameAnswers)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  auto trace = [&](std::vector<std::int64_t>& out)
  {
    RandomStream random(3, StreamPurpose::Gathering, 9);
    for (int i = 0; i < 5000; ++i)
    {
      const Vec3 origin(random.uniform(), random.uniform(), 0.25);
      RayHit hit;
      out.push_back(tracer.intersect(origin, randomDirection(random), hit)
          ? static_cast<std::int64_t>(hit.element) * 2 + static_cast<int>(hit.side)
          : -1);
    }
  };
  std::vector<std::int64_t> serial;
  trace(serial);
  std::vector<std::vector<std::int64_t>> parallel(4);
  std::vector<std::thread> pool;
  for (auto& out : parallel)
  {
    pool.emplace_back([&] { trace(out); });
  }
  for (std::thread& t : pool)
  {
    t.join();
  }
  for (const auto& out : parallel)
  {
    EXPECT_EQ(out, serial);
  }
}

TEST(RayTracer, VisibilityOfSegmentsAndDirections)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  // Packets of 16 and a ragged tail: 53 segments from one origin above the floor, under the
  // blocker, to targets all around, some of them behind the blocker or under the floor.
  const Vec3 origin(0.5, 0.47, 0.05);
  RandomStream random(11, StreamPurpose::Shooting, 2);
  std::vector<float> dx, dy, dz;
  std::vector<int> expected;
  while (dx.size() < 53)
  {
    const Vec3 target(
      -0.2 + 1.4 * random.uniform(), -0.2 + 1.4 * random.uniform(), -0.3 + 1.3 * random.uniform());
    const Vec3 d = target - origin;
    bool ambiguous = false;
    const bool blocked = analyticallyBlocked(origin, d, ambiguous);
    if (ambiguous || std::abs(target.z) < 1e-3 || std::abs(target.z - BlockerHeight) < 1e-3)
    {
      continue;
    }
    dx.push_back(static_cast<float>(d.x));
    dy.push_back(static_cast<float>(d.y));
    dz.push_back(static_cast<float>(d.z));
    expected.push_back(blocked ? 0 : 1);
  }
  // A segment straight up through the blocker and one that stops short of it.
  dx.push_back(0), dy.push_back(0), dz.push_back(0.9f), expected.push_back(0);
  dx.push_back(0), dy.push_back(0), dz.push_back(0.4f), expected.push_back(1);
  std::vector<std::uint8_t> visible(dx.size(), 7);
  tracer.visibleFrom(origin, dx.data(), dy.data(), dz.data(), dx.size(), visible.data());
  int blocked = 0;
  for (std::size_t i = 0; i < visible.size(); ++i)
  {
    EXPECT_EQ(visible[i], expected[i])
      << "segment " << i << " to (" << dx[i] << ", " << dy[i] << ", " << dz[i] << ")";
    blocked += expected[i] == 0 ? 1 : 0;
  }
  EXPECT_GT(blocked, 5);
  EXPECT_LT(blocked, static_cast<int>(visible.size()) - 5);

  // To infinity: up through the blocker, up past it, down into the floor, sideways.
  const float ax[] = { 0, 1, 0, 1 }, ay[] = { 0, 0, 0, 0 }, az[] = { 1, 1, -1, 0 };
  std::uint8_t along[4] = { 7, 7, 7, 7 };
  tracer.visibleAlong(origin, ax, ay, az, 4, along);
  EXPECT_EQ(along[0], 0);
  EXPECT_EQ(along[1], 1);
  EXPECT_EQ(along[2], 0);
  EXPECT_EQ(along[3], 1);
}

TEST(RayTracer, RaysLeaveSurfacesFromTheOffset)
{
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker());
  const RayTracer tracer(scene);
  // 1e-5 of the diagonal of [0, 1] x [0, 1] x [0, 0.5], which is 1.5.
  EXPECT_DOUBLE_EQ(tracer.surfaceOffset(), 1.5e-5);
  const Vec3 floorPoint(0.52, 0.45, 0);
  const Vec3 start = tracer.liftOff(floorPoint, scene.elementNormal(0));
  EXPECT_NEAR(start.z, 1.5e-5, 1e-12);
  // Up from the lifted point: the blocker's front, not the floor again.
  RayHit hit;
  ASSERT_TRUE(tracer.intersect(start, { 0, 0, 1 }, hit));
  EXPECT_GE(scene.patchOfElement(hit.element), 2u);
  EXPECT_EQ(hit.side, Side::Front);
  EXPECT_NEAR(hit.distance, 0.5 - 1.5e-5, 1e-6);
  // A segment shorter than the offset is visible without tracing, even across a surface.
  const float dx[] = { 0 }, dy[] = { 0 }, dz[] = { -1e-5f };
  std::uint8_t visible[1] = { 7 };
  tracer.visibleFrom({ 0.2, 0.2, 5e-6 }, dx, dy, dz, 1, visible);
  EXPECT_EQ(visible[0], 1);
}

TEST(RayTracer, ASceneFarFromTheOriginTracesAsAccurately)
{
  // At 2e6 from the origin single precision resolves only 1/8: tracing relative to the
  // scene's centre keeps the answers of the scene at the origin.
  const Vec3 shift(2e6, -1e6, 3e5);
  const Scene scene = Scene::fromPatchMesh(floorAndBlocker(shift));
  const RayTracer tracer(scene);
  EXPECT_DOUBLE_EQ(tracer.surfaceOffset(), 1.5e-5);
  RayHit hit;
  ASSERT_TRUE(tracer.intersect(Vec3(0.2, 0.3, 1) + shift, { 0, 0, -1 }, hit));
  EXPECT_NEAR(hit.distance, 1.0, 1e-5);
  EXPECT_NEAR(length(hit.point - (Vec3(0.2, 0.3, 0) + shift)), 0.0, 1e-5);
  ASSERT_TRUE(tracer.intersect(Vec3(0.55, 0.42, 0.1) + shift, { 0, 0, 1 }, hit));
  EXPECT_NEAR(hit.distance, 0.4, 1e-5);
  EXPECT_EQ(hit.side, Side::Front);
  EXPECT_FALSE(tracer.intersect(Vec3(1.01, 0.5, 1) + shift, { 0, 0, -1 }, hit));
}
