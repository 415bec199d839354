// Posing a moving light: aiming it at a point turns it rigidly about its centroid, so that it
// faces the point and keeps its shape, area and place.
#include "CoreChecks.h"
#include "MovingLight.h"
#include "PolygonTriangulation.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlr;
using mlr::checks::expectError;

namespace
{
/// A concave L and a triangle in the plane z = 2, facing down (clockwise seen from above).
std::vector<std::vector<Vec3>> lampPolygons()
{
  return { { { 0, 0, 2 }, { 0, 0.2, 2 }, { 0.1, 0.2, 2 }, { 0.1, 0.1, 2 }, { 0.3, 0.1, 2 },
             { 0.3, 0, 2 } },
    { { 0.4, 0, 2 }, { 0.4, 0.1, 2 }, { 0.5, 0, 2 } } };
}

std::vector<PoseInput> inputsAt(const std::vector<Vec3>& positions)
{
  std::vector<PoseInput> inputs(positions.size());
  for (std::size_t k = 0; k < positions.size(); ++k)
  {
    inputs[k].position = positions[k];
  }
  return inputs;
}

/// The light aimed at `target` from every one of `positions`.
MovingLight aimedLight(const std::vector<Vec3>& positions, const Vec3& target)
{
  std::vector<PoseInput> inputs = inputsAt(positions);
  EXPECT_FALSE(aimAt(inputs, target).has_value());
  std::vector<std::string> warnings;
  const MovingLight light(
    lampPolygons(), Rgb(1, 1, 1), posesFromInputs(lampPolygons(), inputs, warnings));
  EXPECT_TRUE(warnings.empty());
  return light;
}

double distance(const Vec3& a, const Vec3& b)
{
  return length(a - b);
}
} // namespace

TEST(MovingLightAim, FacesTheTargetFromEveryPosition)
{
  const std::vector<Vec3> positions = { { 0, 0, 2 }, { 1, -1, 2.5 }, { -2, 3, 0.5 },
    { 0.3, 0.2, -1 } };
  // Below, beside, diagonal, far away and straight above: the light faces down as given, so
  // the last needs the half turn of opposite directions.
  const std::vector<Vec3> targets = { { 0, 0, -5 }, { 4, 0, 1 }, { -1, 2, 3 }, { 100, -50, 20 },
    { 0, 0, 50 } };
  const Vec3 own = meanNormal(lampPolygons());
  ASSERT_LT(distance(own, Vec3(0, 0, -1)), 1e-15);
  for (const Vec3& target : targets)
  {
    const MovingLight light = aimedLight(positions, target);
    for (std::size_t k = 0; k < positions.size(); ++k)
    {
      // Nearly opposite directions lose digits in the turn (1 / (1 + cos) in Rodrigues).
      const Vec3 towards = normalize(target - positions[k]);
      EXPECT_LT(distance(light.turn(k, own), towards), 1e-10) << "frame " << k;
      for (const LightTriangle& t : light.triangles())
      {
        EXPECT_LT(distance(light.turn(k, t.normal), towards), 1e-10) << "frame " << k;
      }
    }
  }
}

TEST(MovingLightAim, KeepsTheAreaAndTheCentroid)
{
  const std::vector<Vec3> positions = { { 0, 0, 2 }, { 1, -1, 2.5 }, { -2, 3, 0.5 } };
  for (const Vec3& target : { Vec3(0, 0, -5), Vec3(4, 0, 1), Vec3(0, 0, 50) })
  {
    const MovingLight light = aimedLight(positions, target);
    for (std::size_t k = 0; k < positions.size(); ++k)
    {
      // Every polygon, placed, has the area it had (a Newell normal is twice the area).
      double area = 0;
      for (const std::vector<Vec3>& polygon : light.polygons())
      {
        std::vector<Vec3> placed;
        for (const Vec3& x : polygon)
        {
          placed.push_back(light.place(k, x));
        }
        const double before = length(newellNormal(polygon)) / 2;
        // Placed far from the origin, the Newell sum cancels digits.
        EXPECT_NEAR(length(newellNormal(placed)) / 2, before, 1e-11 * before) << "frame " << k;
        area += before;
        // The plane of the placed light is perpendicular to the aim, through the position.
        for (const Vec3& p : placed)
        {
          EXPECT_NEAR(dot(p - positions[k], normalize(target - positions[k])), 0, 1e-12);
        }
      }
      EXPECT_NEAR(area, light.area(), 1e-13 * area);
      // The area centroid of the placed triangles is the frame's position.
      Vec3 moment;
      double total = 0;
      for (const LightTriangle& t : light.triangles())
      {
        const Vec3 a = light.place(k, t.a), b = light.place(k, t.b), c = light.place(k, t.c);
        const double w = length(cross(b - a, c - a)) / 2;
        moment += (a + b + c) * (w / 3);
        total += w;
      }
      EXPECT_LT(distance(moment / total, positions[k]), 1e-12) << "frame " << k;
    }
  }
}

TEST(MovingLightAim, TurnsByTheSmallestRotation)
{
  // The axis perpendicular to the light's normal and the aim stays put: aiming does not spin
  // the light about the direction it faces.
  const Vec3 position(1, -1, 2.5), target(4, 0, 1);
  const MovingLight light = aimedLight({ position }, target);
  const Vec3 axis = normalize(cross(meanNormal(lampPolygons()), target - position));
  EXPECT_LT(distance(light.turn(0, axis), axis), 1e-12);
}

TEST(MovingLightAim, RigidMotionAsRotationRowsAndTranslation)
{
  // What the Light output draws with: x -> R x + t, from rows() and rigidTranslation().
  const MovingLight light = aimedLight({ { 1, -1, 2.5 }, { -2, 3, 0.5 } }, Vec3(4, 0, 1));
  for (std::size_t k = 0; k < light.frameCount(); ++k)
  {
    const auto r = light.pose(k).rotation.rows();
    const Vec3 t = light.rigidTranslation(k);
    for (const std::vector<Vec3>& polygon : light.polygons())
    {
      for (const Vec3& x : polygon)
      {
        const Vec3 moved(r[0][0] * x.x + r[0][1] * x.y + r[0][2] * x.z + t.x,
          r[1][0] * x.x + r[1][1] * x.y + r[1][2] * x.z + t.y,
          r[2][0] * x.x + r[2][1] * x.y + r[2][2] * x.z + t.z);
        EXPECT_LT(distance(moved, light.place(k, x)), 1e-12);
      }
    }
  }
}

TEST(MovingLightAim, ALightAtTheTargetCannotFaceIt)
{
  // The documented refusal: aimAt names the first frame at the target and leaves its Normal
  // zero, which posesFromInputs refuses, naming that frame.
  const Vec3 target(-2, 3, 0.5);
  std::vector<PoseInput> inputs = inputsAt({ { 0, 0, 2 }, { 1, -1, 2.5 }, target, target });
  const std::optional<std::size_t> frame = aimAt(inputs, target);
  ASSERT_TRUE(frame.has_value());
  EXPECT_EQ(*frame, 2u);
  std::vector<std::string> warnings;
  expectError(
    [&] { posesFromInputs(lampPolygons(), inputs, warnings); }, "Normal of light position 2");
}

TEST(MovingLightAim, AnOrientationWinsOverTheAim)
{
  // A frame with an Orientation keeps it, even at the target.
  const Vec3 target(-2, 3, 0.5);
  std::vector<PoseInput> inputs = inputsAt({ { 0, 0, 2 }, target });
  inputs[1].hasOrientation = true;
  inputs[1].orientation = { std::cos(0.3), std::sin(0.3), 0, 0 };
  EXPECT_FALSE(aimAt(inputs, target).has_value());
  std::vector<std::string> warnings;
  const std::vector<LightPose> poses = posesFromInputs(lampPolygons(), inputs, warnings);
  const Rotation expected = Rotation::fromQuaternion(std::cos(0.3), std::sin(0.3), 0, 0);
  EXPECT_TRUE(poses[1].rotation.row0 == expected.row0 && poses[1].rotation.row1 == expected.row1 &&
    poses[1].rotation.row2 == expected.row2);
  EXPECT_LT(distance(poses[0].rotation.apply(meanNormal(lampPolygons())),
              normalize(target - inputs[0].position)),
    1e-12);
}
