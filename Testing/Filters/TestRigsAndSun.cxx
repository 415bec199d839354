// Light rigs and the sun through the filter's interface: the
// Trajectory's point arrays Normal, Orientation and Power, several lights by LightId, scene
// Emission, LightType Directional, AimAtPoint and the Light output.
#include "FilterTestSupport.h"

#include "GeneratedScenes.h"
#include "Sky.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIntArray.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

using namespace mlr;
using namespace mlr::testing;

namespace
{
constexpr double Pi = 3.14159265358979323846;

/// Every component of the output's cell array `name`, in order (empty when it is missing).
std::vector<double> cellValues(vtkPolyData* data, const char* name)
{
  std::vector<double> values;
  vtkDataArray* array = data->GetCellData()->GetArray(name);
  for (vtkIdType t = 0; array && t < array->GetNumberOfTuples(); ++t)
  {
    for (int c = 0; c < array->GetNumberOfComponents(); ++c)
    {
      values.push_back(array->GetComponent(t, c));
    }
  }
  return values;
}

/// The cell array `name` of output 0 in every time step the filter declares.
std::vector<std::vector<double>> everyFrame(vtkMovingLightRadiosity* filter, const char* name)
{
  std::vector<std::vector<double>> frames;
  for (double t : timeSteps(filter))
  {
    EXPECT_TRUE(filter->UpdateTimeStep(t));
    frames.push_back(cellValues(filter->GetOutput(0), name));
  }
  return frames;
}

/// max |a - b| / max |b|: 0 for identical arrays, large for arrays of different sizes.
double relativeDifference(const std::vector<double>& a, const std::vector<double>& b)
{
  if (a.size() != b.size() || b.empty())
  {
    return std::numeric_limits<double>::infinity();
  }
  double scale = 0, difference = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
  {
    scale = std::max(scale, std::abs(b[i]));
    difference = std::max(difference, std::abs(a[i] - b[i]));
  }
  return scale > 0 ? difference / scale : difference;
}

/// The largest relativeDifference of Radiosity between the two filters' frames (infinite
/// when they have different frame counts).
double frameDifference(vtkMovingLightRadiosity* a, vtkMovingLightRadiosity* b)
{
  const auto x = everyFrame(a, "Radiosity");
  const auto y = everyFrame(b, "Radiosity");
  double worst = x.size() == y.size() && !x.empty() ? 0.0 : std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < std::min(x.size(), y.size()); ++f)
  {
    worst = std::max(worst, relativeDifference(x[f], y[f]));
  }
  return worst;
}

double maxValue(const std::vector<double>& values)
{
  return values.empty() ? 0.0 : *std::max_element(values.begin(), values.end());
}

/// The Newell vector of cell `cell` (twice its area times its unit normal, right-hand rule)
/// and the mean of its points.
void cellGeometry(vtkPolyData* data, vtkIdType cell, Vec3& areaVector, Vec3& centre)
{
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  data->GetCellPoints(cell, count, ids);
  areaVector = centre = Vec3();
  for (vtkIdType i = 0; i < count; ++i)
  {
    double a[3], b[3];
    data->GetPoint(ids[i], a);
    data->GetPoint(ids[(i + 1) % count], b);
    areaVector += cross(Vec3(a[0], a[1], a[2]), Vec3(b[0], b[1], b[2]));
    centre += Vec3(a[0], a[1], a[2]) / double(count);
  }
}

/// Power (W, summed over channels) that the cells of the box wall on `axis` at `high` (the
/// plane coordinate 0 or 1) carry in the cell array `name`: sum of area x radiosity.
double wallPower(vtkPolyData* elements, int axis, bool high, const char* name)
{
  vtkDataArray* array = elements->GetCellData()->GetArray(name);
  double power = 0;
  for (vtkIdType c = 0; array && c < elements->GetNumberOfCells(); ++c)
  {
    Vec3 area, centre;
    cellGeometry(elements, c, area, centre);
    if (std::abs(centre[axis] - (high ? 1.0 : 0.0)) < 1e-9)
    {
      power += 0.5 * length(area) *
        (array->GetComponent(c, 0) + array->GetComponent(c, 1) + array->GetComponent(c, 2));
    }
  }
  return power;
}

/// Adds the point array `name` with `components` components to `data`.
void addPointArray(
  vtkPolyData* data, const char* name, int components, const std::vector<double>& values)
{
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfComponents(components);
  for (std::size_t i = 0; i + components <= values.size(); i += components)
  {
    array->InsertNextTuple(values.data() + i);
  }
  data->GetPointData()->AddArray(array);
}

/// A Trajectory of one polyline per entry of `lines`, each the given points in order.
vtkSmartPointer<vtkPolyData> polylines(const std::vector<std::vector<Vec3>>& lines)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> cells;
  for (const auto& line : lines)
  {
    cells->InsertNextCell(static_cast<vtkIdType>(line.size()));
    for (const Vec3& p : line)
    {
      cells->InsertCellPoint(points->InsertNextPoint(p.x, p.y, p.z));
    }
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(points);
  data->SetLines(cells);
  return data;
}

/// The box's filter with two threads (every test runs with the same settings and seed).
vtkSmartPointer<vtkMovingLightRadiosity> boxFilter(const BoxSetup& setup, vtkIdType paths = 20000)
{
  auto filter = fastFilter(setup);
  filter->SetNumberOfThreads(2);
  filter->SetNumberOfPaths(paths);
  return filter;
}

struct FilterRun
{
  bool succeeded = false;
  vtkSmartPointer<MessageRecorder> messages;
  vtkIdType cells[3] = { 0, 0, 0 };
};

/// Updates the filter at its first time step, recording errors and warnings.
FilterRun run(vtkMovingLightRadiosity* filter)
{
  FilterRun result;
  result.messages = vtkSmartPointer<MessageRecorder>::New();
  result.messages->watch(filter);
  result.succeeded = filter->UpdateTimeStep(0) != 0;
  for (int port = 0; port < 3; ++port)
  {
    result.cells[port] = filter->GetOutput(port)->GetNumberOfCells();
  }
  filter->RemoveAllObservers();
  return result;
}

/// The filter fails with an error containing `expected` and every output is empty.
void expectError(vtkMovingLightRadiosity* filter, const std::string& expected)
{
  const FilterRun r = run(filter);
  EXPECT_FALSE(r.succeeded);
  EXPECT_NE(r.messages->allErrors().find(expected), std::string::npos)
    << "expected an error with \"" << expected << "\", got: " << r.messages->allErrors();
  for (int port = 0; port < 3; ++port)
  {
    EXPECT_EQ(r.cells[port], 0) << "output port " << port;
  }
}

/// The box's light turned 45 degrees from straight down towards +x: as a Normal and as the
/// quaternion of that smallest rotation (about -y).
const Vec3 TiltedNormal(std::sqrt(0.5), 0.0, -std::sqrt(0.5));
const std::vector<double> TiltQuaternion = { std::cos(Pi / 8), 0.0, -std::sin(Pi / 8), 0.0 };

/// The box with a 3-frame trajectory whose every point carries `name` = `tuple`.
BoxSetup turnedBox(const std::vector<std::pair<const char*, std::vector<double>>>& arrays)
{
  BoxSetup setup = closedBoxSetup(3);
  for (const auto& [name, tuple] : arrays)
  {
    std::vector<double> values;
    for (int i = 0; i < 3; ++i)
    {
      values.insert(values.end(), tuple.begin(), tuple.end());
    }
    addPointArray(setup.trajectory, name, static_cast<int>(tuple.size()), values);
  }
  return setup;
}
}

// ------------------------------------------------------------------------ Normal, Orientation

TEST(FilterRigs, NormalAndOrientationTurnTheLightAlike)
{
  const std::vector<double> normal = { TiltedNormal.x, TiltedNormal.y, TiltedNormal.z };
  auto byNormal = boxFilter(turnedBox({ { "Normal", normal } }));
  auto byOrientation = boxFilter(turnedBox({ { "Orientation", TiltQuaternion } }));
  auto unturned = boxFilter(closedBoxSetup(3));
  const auto n = everyFrame(byNormal, "Radiosity");
  const auto q = everyFrame(byOrientation, "Radiosity");
  const auto u = everyFrame(unturned, "Radiosity");
  ASSERT_EQ(n.size(), 3u);
  ASSERT_EQ(q.size(), 3u);
  for (std::size_t f = 0; f < 3; ++f)
  {
    // The same seed and the same rotation (up to rounding in building it) give the same paths.
    EXPECT_LT(relativeDifference(n[f], q[f]), 1e-6) << "frame " << f;
    EXPECT_GT(relativeDifference(n[f], u[f]), 0.2) << "frame " << f;
  }
  // The turned light shines on the +x wall.
  ASSERT_TRUE(byNormal->UpdateTimeStep(1));
  ASSERT_TRUE(unturned->UpdateTimeStep(1));
  const double turned = wallPower(byNormal->GetOutput(), 0, true, "DirectRadiosity");
  const double straight = wallPower(unturned->GetOutput(), 0, true, "DirectRadiosity");
  EXPECT_GT(turned, 1.5 * straight) << "turned " << turned << " W, straight " << straight << " W";
}

TEST(FilterRigs, OrientationWinsOverNormal)
{
  // The Normal turns the light towards -x, the Orientation towards +x: Orientation wins.
  auto both = boxFilter(turnedBox(
    { { "Normal", { -TiltedNormal.x, 0.0, TiltedNormal.z } }, { "Orientation", TiltQuaternion } }));
  auto orientation = boxFilter(turnedBox({ { "Orientation", TiltQuaternion } }));
  EXPECT_EQ(frameDifference(both, orientation), 0.0);
}

TEST(FilterRigs, NonUnitQuaternionIsNormalisedWithAWarning)
{
  std::vector<double> doubled = TiltQuaternion;
  for (double& c : doubled)
  {
    c *= 2;
  }
  auto unit = boxFilter(turnedBox({ { "Orientation", TiltQuaternion } }));
  auto scaled = boxFilter(turnedBox({ { "Orientation", doubled } }));
  const FilterRun unitRun = run(unit);
  const FilterRun scaledRun = run(scaled);
  ASSERT_TRUE(scaledRun.succeeded) << scaledRun.messages->allErrors();
  EXPECT_TRUE(unitRun.messages->warnings.empty()) << unitRun.messages->allWarnings();
  EXPECT_NE(scaledRun.messages->allWarnings().find("Orientation"), std::string::npos)
    << scaledRun.messages->allWarnings();
  EXPECT_EQ(timeSteps(scaled).size(), 3u);
  EXPECT_EQ(frameDifference(scaled, unit), 0.0);
}

TEST(FilterRigs, ZeroNormalIsAnError)
{
  BoxSetup setup = closedBoxSetup(3);
  addPointArray(setup.trajectory, "Normal", 3, { 0, 0, -1, 0, 0, 0, 0, 0, -1 });
  expectError(boxFilter(setup), "Normal");
}

// ------------------------------------------------------------------------------------ Power

TEST(FilterRigs, PowerScalesItsFrameOnly)
{
  // Power 1, 0.5, 1 against 1, 1, 1 with the same seed: frame 1 is exactly half (up to the
  // float rounding of the output), the others are unchanged.
  BoxSetup full = closedBoxSetup(3);
  addPointArray(full.trajectory, "Power", 1, { 1, 1, 1 });
  BoxSetup dimmed = closedBoxSetup(3);
  addPointArray(dimmed.trajectory, "Power", 1, { 1, 0.5, 1 });
  for (const char* name : { "Radiosity", "DirectRadiosity", "IndirectRadiosity" })
  {
    const auto a = everyFrame(boxFilter(full), name);
    const auto b = everyFrame(boxFilter(dimmed), name);
    ASSERT_EQ(a.size(), 3u);
    ASSERT_EQ(b.size(), 3u);
    EXPECT_GT(maxValue(a[1]), 0.0) << name;
    std::vector<double> half = a[1];
    for (double& v : half)
    {
      v *= 0.5;
    }
    EXPECT_LT(relativeDifference(b[1], half), 1e-6) << name;
    EXPECT_EQ(relativeDifference(b[0], a[0]), 0.0) << name;
    EXPECT_EQ(relativeDifference(b[2], a[2]), 0.0) << name;
  }
}

TEST(FilterRigs, PowerPerChannelAndZeroIsDark)
{
  BoxSetup full = closedBoxSetup(3);
  BoxSetup coloured = closedBoxSetup(3);
  addPointArray(coloured.trajectory, "Power", 3, { 1, 1, 1, 0, 0, 0, 1, 0.5, 0.25 });
  const auto a = everyFrame(boxFilter(full), "Radiosity");
  const auto b = everyFrame(boxFilter(coloured), "Radiosity");
  ASSERT_EQ(b.size(), 3u);
  // Frame 1 is off: no light at all.
  EXPECT_EQ(maxValue(b[1]), 0.0);
  EXPECT_EQ(b[1].size(), a[1].size());
  // Frame 2 is dimmed per channel: on a grey scene the channels of one path set differ by the
  // factors alone. An inactive frame casts no paths, so the other frames' paths may differ
  // from the run without Power: against that run, frame 2 agrees within noise only.
  double sums[3] = { 0, 0, 0 }, white[3] = { 0, 0, 0 };
  for (std::size_t i = 0; i < b[2].size(); ++i)
  {
    sums[i % 3] += b[2][i];
    white[i % 3] += a[2][i];
  }
  ASSERT_GT(white[0], 0.0);
  EXPECT_NEAR(sums[1] / sums[0], 0.5, 1e-6);
  EXPECT_NEAR(sums[2] / sums[0], 0.25, 1e-6);
  EXPECT_NEAR(sums[0] / white[0], 1.0, 0.05);
}

TEST(FilterRigs, NegativeOrNaNPowerIsAnError)
{
  for (double bad : { -1.0, std::numeric_limits<double>::quiet_NaN() })
  {
    BoxSetup setup = closedBoxSetup(3);
    addPointArray(setup.trajectory, "Power", 1, { 1, bad, 1 });
    SCOPED_TRACE(bad);
    expectError(boxFilter(setup), "the Trajectory's point array Power");
  }
}

// ----------------------------------------------------------------------- Several lights

namespace
{
/// Two lights of the box, LightId 0 (the box's light, at (0.5, 0.5, 0.9)) and 1 (a 0.2 m
/// square facing down at (0.5, 0.5, 0.7)), with LightPower per light.
vtkSmartPointer<vtkPolyData> twoLights(const Rgb& power0, const Rgb& power1)
{
  auto polygons = scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 }, 0.2);
  const auto second = scenes::squareLightFacingDown({ 0.5, 0.5, 0.7 }, 0.2);
  polygons.insert(polygons.end(), second.begin(), second.end());
  auto light = lightPolyData(polygons);
  vtkNew<vtkIntArray> ids;
  ids->SetName("LightId");
  vtkNew<vtkDoubleArray> power;
  power->SetName("LightPower");
  power->SetNumberOfComponents(3);
  const std::size_t first = polygons.size() - second.size();
  for (std::size_t c = 0; c < polygons.size(); ++c)
  {
    const Rgb& p = c < first ? power0 : power1;
    ids->InsertNextValue(c < first ? 0 : 1);
    power->InsertNextTuple3(p.r, p.g, p.b);
  }
  light->GetCellData()->AddArray(ids);
  light->GetCellData()->AddArray(power);
  return light;
}

/// Light 0 moves on the box's diagonal in 3 frames; light 1 moves along x below it, or stays
/// at its place when `staticSecond`.
vtkSmartPointer<vtkPolyData> twoLightTrajectory(bool staticSecond)
{
  const std::vector<Vec3> first = { { 0.25, 0.3, 0.9 }, { 0.5, 0.5, 0.9 }, { 0.75, 0.7, 0.9 } };
  const std::vector<Vec3> second = staticSecond
    ? std::vector<Vec3>{ { 0.3, 0.6, 0.7 } }
    : std::vector<Vec3>{ { 0.7, 0.3, 0.7 }, { 0.5, 0.3, 0.7 }, { 0.3, 0.3, 0.7 } };
  return polylines({ first, second });
}

/// Per frame, the power (W, all channels) each of the six walls carries in `name`.
std::vector<std::vector<double>> wallPowers(vtkMovingLightRadiosity* filter, const char* name)
{
  std::vector<std::vector<double>> frames;
  for (double t : timeSteps(filter))
  {
    EXPECT_TRUE(filter->UpdateTimeStep(t));
    frames.emplace_back();
    for (int wall = 0; wall < 6; ++wall)
    {
      frames.back().push_back(wallPower(filter->GetOutput(), wall / 2, wall % 2 == 1, name));
    }
  }
  return frames;
}
}

TEST(FilterRigs, TwoLightsAddUp)
{
  // Light transport is linear: the lights together light each wall as the sum of each alone
  // (a light is switched off by a LightPower of 0, keeping the LightId groups).
  const Rgb p0(2, 3, 4), p1(4, 2, 1), off(0, 0, 0);
  BoxSetup setup = closedBoxSetup(3);
  auto solve = [&](const Rgb& a, const Rgb& b, const char* name)
  {
    setup.light = twoLights(a, b);
    setup.trajectory = twoLightTrajectory(false);
    auto filter = boxFilter(setup, 200000);
    return wallPowers(filter, name);
  };
  for (const char* name : { "DirectRadiosity", "Radiosity" })
  {
    SCOPED_TRACE(name);
    const auto both = solve(p0, p1, name);
    const auto first = solve(p0, off, name);
    const auto second = solve(off, p1, name);
    ASSERT_EQ(both.size(), 3u);
    ASSERT_EQ(first.size(), 3u);
    ASSERT_EQ(second.size(), 3u);
    for (std::size_t f = 0; f < 3; ++f)
    {
      double total = 0;
      for (int wall = 0; wall < 6; ++wall)
      {
        total += both[f][wall];
      }
      ASSERT_GT(total, 0.0);
      for (int wall = 0; wall < 6; ++wall)
      {
        // 200,000 paths per frame: a wall's share is known to about 1% of the total.
        EXPECT_NEAR(both[f][wall], first[f][wall] + second[f][wall], 0.03 * total)
          << "frame " << f << " wall " << wall;
      }
    }
  }
}

TEST(FilterRigs, LightPowerPerLightSetsEachLightsPower)
{
  // In a closed box (reflectance 0.5) every watt is absorbed: sum A B (1 - rho) / rho = sum A B
  // equals the lights' total power, per channel, in every frame.
  BoxSetup setup = closedBoxSetup(3);
  setup.light = twoLights({ 2, 3, 4 }, { 4, 2, 1 });
  setup.trajectory = twoLightTrajectory(false);
  auto filter = boxFilter(setup, 200000);
  for (double t : timeSteps(filter))
  {
    ASSERT_TRUE(filter->UpdateTimeStep(t));
    vtkPolyData* elements = filter->GetOutput();
    vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
    ASSERT_NE(radiosity, nullptr);
    double absorbed[3] = { 0, 0, 0 };
    for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
    {
      for (int k = 0; k < 3; ++k)
      {
        absorbed[k] += triangleArea(elements, c) * radiosity->GetComponent(c, k);
      }
    }
    const double expected[3] = { 6, 5, 5 };
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_NEAR(absorbed[k] / expected[k], 1.0, 0.02) << "time " << t << " channel " << k;
    }
  }
}

TEST(FilterRigs, OnePointPolylineIsAStaticLight)
{
  // Light 0 moves but is off in every frame (Power 0); light 1 is one point: a light that does
  // not move, solved once and added to every frame alike.
  BoxSetup setup = closedBoxSetup(3);
  setup.light = twoLights({ 2, 3, 4 }, { 4, 2, 1 });
  setup.trajectory = twoLightTrajectory(true);
  addPointArray(setup.trajectory, "Power", 1, { 0, 0, 0, 1 });
  auto filter = boxFilter(setup);
  EXPECT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2 }));
  const auto frames = everyFrame(filter, "Radiosity");
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_GT(maxValue(frames[0]), 0.0);
  EXPECT_EQ(relativeDifference(frames[1], frames[0]), 0.0);
  EXPECT_EQ(relativeDifference(frames[2], frames[0]), 0.0);
  // It is cast once for all frames, not once per frame (light 0, off, casts nothing).
  EXPECT_EQ(fieldValue(filter->GetOutput(), "PathsCast"), 20000.0);
  // And the Light output shows the static light at its one point in every frame.
  for (double t : timeSteps(filter))
  {
    ASSERT_TRUE(filter->UpdateTimeStep(t));
    vtkPolyData* lights = filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT);
    ASSERT_EQ(lights->GetNumberOfCells(), 2);
    Vec3 area, centre;
    cellGeometry(lights, 1, area, centre);
    EXPECT_NEAR(length(centre - Vec3(0.3, 0.6, 0.7)), 0.0, 1e-12) << "time " << t;
  }
}

TEST(FilterRigs, LightIdWithoutItsPolylineIsAnError)
{
  BoxSetup setup = closedBoxSetup(3);
  setup.light = twoLights({ 1, 1, 1 }, { 1, 1, 1 });
  setup.trajectory = polylines({ { { 0.25, 0.3, 0.9 }, { 0.5, 0.5, 0.9 }, { 0.75, 0.7, 0.9 } } });
  expectError(boxFilter(setup), "2 lights (LightId) but the Trajectory has 1 polyline:");
  // Points without polylines are no rig either.
  setup.trajectory = trajectoryPolyData({ { 0.25, 0.3, 0.9 }, { 0.5, 0.5, 0.9 } });
  expectError(boxFilter(setup), "polylines");
}

TEST(FilterRigs, MovingLightsWithDifferentPointCountsAreAnError)
{
  BoxSetup setup = closedBoxSetup(3);
  setup.light = twoLights({ 1, 1, 1 }, { 1, 1, 1 });
  setup.trajectory = polylines({ { { 0.25, 0.3, 0.9 }, { 0.5, 0.5, 0.9 }, { 0.75, 0.7, 0.9 } },
    { { 0.7, 0.3, 0.7 }, { 0.3, 0.3, 0.7 } } });
  expectError(boxFilter(setup), "polyline 1 of the Trajectory has 2 points but polyline 0 has 3");
  // The count compared with is the first moving light's: light 0 here does not move.
  std::vector<std::vector<Vec3>> polygons;
  vtkNew<vtkIntArray> ids;
  ids->SetName("LightId");
  for (int l = 0; l < 3; ++l)
  {
    for (const auto& polygon : scenes::squareLightFacingDown({ 0.5, 0.5, 0.9 - 0.2 * l }, 0.2))
    {
      polygons.push_back(polygon);
      ids->InsertNextValue(l);
    }
  }
  setup.light = lightPolyData(polygons);
  setup.light->GetCellData()->AddArray(ids);
  setup.trajectory = polylines(
    { { { 0.5, 0.5, 0.9 } }, { { 0.25, 0.3, 0.7 }, { 0.5, 0.5, 0.7 }, { 0.75, 0.7, 0.7 } },
      { { 0.2, 0.3, 0.5 }, { 0.4, 0.3, 0.5 }, { 0.6, 0.3, 0.5 }, { 0.8, 0.3, 0.5 } } });
  expectError(boxFilter(setup), "polyline 2 of the Trajectory has 4 points but polyline 1 has 3");
}

// ------------------------------------------------------------------------ Scene emission

namespace
{
/// The closed box of closedBoxSetup with the top wall (z = 1, facing down into the box)
/// emitting `emission` from the cell array `name`; reflectance 0.5 everywhere.
vtkSmartPointer<vtkPolyData> emissiveBox(
  const std::vector<double>& emission, const char* name = "Emission")
{
  auto scene = closedBoxSetup(1).scene;
  vtkNew<vtkDoubleArray> array;
  array->SetName(name);
  array->SetNumberOfComponents(static_cast<int>(emission.size()));
  for (vtkIdType c = 0; c < scene->GetNumberOfCells(); ++c)
  {
    Vec3 area, centre;
    cellGeometry(scene, c, area, centre);
    const bool top = std::abs(centre.z - 1.0) < 1e-9;
    for (int k = 0; k < array->GetNumberOfComponents(); ++k)
    {
      array->InsertNextValue(top ? emission[static_cast<std::size_t>(k)] : 0.0);
    }
  }
  scene->GetCellData()->AddArray(array);
  return scene;
}

vtkSmartPointer<vtkMovingLightRadiosity> sceneOnlyFilter(vtkPolyData* scene, vtkIdType paths)
{
  auto filter = vtkSmartPointer<vtkMovingLightRadiosity>::New();
  filter->SetSceneData(scene);
  filter->SetNumberOfPaths(paths);
  filter->SetPatchSize(0.25);
  filter->SetNumberOfThreads(2);
  return filter;
}
}

TEST(FilterRigs, EmissiveWallInAClosedBox)
{
  const Rgb emission(2, 4, 6);
  auto filter = sceneOnlyFilter(emissiveBox({ emission.r, emission.g, emission.b }), 200000);
  const FilterRun r = run(filter);
  ASSERT_TRUE(r.succeeded) << r.messages->allErrors();
  vtkPolyData* elements = filter->GetOutput();
  ASSERT_GT(elements->GetNumberOfCells(), 0);
  vtkDataArray* emitted = elements->GetCellData()->GetArray("EmittedRadiosity");
  vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
  vtkDataArray* direct = elements->GetCellData()->GetArray("DirectRadiosity");
  vtkDataArray* indirect = elements->GetCellData()->GetArray("IndirectRadiosity");
  ASSERT_NE(emitted, nullptr);
  ASSERT_NE(radiosity, nullptr);
  double absorbed[3] = { 0, 0, 0 };
  int emitters = 0;
  for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
  {
    Vec3 area, centre;
    cellGeometry(elements, c, area, centre);
    const bool top = std::abs(centre.z - 1.0) < 1e-9;
    emitters += top ? 1 : 0;
    for (int k = 0; k < 3; ++k)
    {
      // The emitter's front faces into the box, where its light goes: that is its lit side.
      EXPECT_FLOAT_EQ(static_cast<float>(emitted->GetComponent(c, k)),
        top ? static_cast<float>(emission[k]) : 0.0f)
        << "cell " << c << " channel " << k;
      EXPECT_NEAR(radiosity->GetComponent(c, k),
        emitted->GetComponent(c, k) + direct->GetComponent(c, k) + indirect->GetComponent(c, k),
        1e-5 * radiosity->GetComponent(c, k));
      // Absorbed = (1 - rho) x irradiance = (1 - rho) / rho x reflected, reflected = B - E.
      absorbed[k] +=
        0.5 * length(area) * (radiosity->GetComponent(c, k) - emitted->GetComponent(c, k));
    }
  }
  EXPECT_GT(emitters, 0);
  // The top wall is 1 m^2: it emits `emission` W, all of which the closed box absorbs.
  for (int k = 0; k < 3; ++k)
  {
    EXPECT_NEAR(absorbed[k] / emission[k], 1.0, 0.02) << "channel " << k;
  }
}

TEST(FilterRigs, EmissiveSceneAloneGivesTheSameResultAtEveryTime)
{
  // Without a light nothing moves: one frame without a Trajectory (NumberOfPositions is
  // the steps of a light's path), and with one, its times, each showing the one static solve.
  auto filter = sceneOnlyFilter(emissiveBox({ 3 }), 20000);
  filter->SetNumberOfPositions(4);
  for (bool trajectory : { false, true })
  {
    SCOPED_TRACE(trajectory ? "with a Trajectory" : "without a Trajectory");
    if (trajectory)
    {
      filter->SetTrajectoryData(closedBoxSetup(3).trajectory);
    }
    const auto frames = everyFrame(filter, "Radiosity");
    ASSERT_EQ(frames.size(), trajectory ? 3u : 1u);
    EXPECT_GT(maxValue(frames[0]), 0.0);
    for (std::size_t f = 1; f < frames.size(); ++f)
    {
      EXPECT_EQ(relativeDifference(frames[f], frames[0]), 0.0) << "frame " << f;
    }
  }
}

TEST(FilterRigs, EmissionAddsToALight)
{
  // A light in an emitting box: absorbed power = emitted power + light power, per channel.
  BoxSetup setup = closedBoxSetup(2);
  setup.scene = emissiveBox({ 1, 2, 3 });
  auto filter = boxFilter(setup, 200000);
  filter->SetLightPower(3, 2, 1);
  for (double t : timeSteps(filter))
  {
    ASSERT_TRUE(filter->UpdateTimeStep(t));
    vtkPolyData* elements = filter->GetOutput();
    vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
    vtkDataArray* emitted = elements->GetCellData()->GetArray("EmittedRadiosity");
    ASSERT_NE(emitted, nullptr);
    double absorbed[3] = { 0, 0, 0 };
    for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
    {
      for (int k = 0; k < 3; ++k)
      {
        absorbed[k] +=
          triangleArea(elements, c) * (radiosity->GetComponent(c, k) - emitted->GetComponent(c, k));
      }
    }
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_NEAR(absorbed[k] / 4.0, 1.0, 0.02) << "time " << t << " channel " << k;
    }
  }
}

TEST(FilterRigs, EmissionAndReflectanceArrayNames)
{
  // The arrays are found by the names given; an Emission array under another name is ignored.
  auto scene = emissiveBox({ 3 }, "Glow");
  scene->GetCellData()->GetArray("Reflectance")->SetName("Albedo");
  auto filter = sceneOnlyFilter(scene, 20000);
  expectError(filter, "nothing emits");
  filter->SetEmissionArrayName("Glow");
  filter->SetReflectanceArrayName("Albedo");
  const FilterRun r = run(filter);
  ASSERT_TRUE(r.succeeded) << r.messages->allErrors();
  EXPECT_EQ(r.messages->allWarnings().find("Reflectance"), std::string::npos)
    << r.messages->allWarnings();
  EXPECT_FLOAT_EQ(
    static_cast<float>(maxValue(cellValues(filter->GetOutput(), "EmittedRadiosity"))), 3.0f);
}

TEST(FilterRigs, NegativeEmissionIsAnError)
{
  auto filter = sceneOnlyFilter(emissiveBox({ 1, -2, 1 }), 20000);
  expectError(filter, "Emission (1, -2, 1)");
}

// ------------------------------------------------------------------------------ The sun

namespace
{
/// The unit ground quad at z = 0, facing up, reflectance 0.5, 4 x 4 cells.
vtkSmartPointer<vtkPolyData> ground()
{
  PatchMesh mesh;
  scenes::addGriddedQuad(mesh, { 0, 0, 0 }, { 1, 0, 0 }, { 0, 1, 0 }, 4, 4, Rgb(0.5));
  return scenePolyData(mesh);
}

/// Directions towards the sun at these elevations and azimuths (degrees, azimuth from +y
/// towards +x), scaled by `lengths`, with the point arrays SunAzimuth and SunElevation.
vtkSmartPointer<vtkPolyData> sunDirections(const std::vector<double>& elevations,
  const std::vector<double>& azimuths, const std::vector<double>& lengths)
{
  std::vector<Vec3> points;
  for (std::size_t i = 0; i < elevations.size(); ++i)
  {
    const double e = elevations[i] * Pi / 180, a = azimuths[i] * Pi / 180;
    points.push_back(
      Vec3(std::cos(e) * std::sin(a), std::cos(e) * std::cos(a), std::sin(e)) * lengths[i]);
  }
  auto data = trajectoryPolyData(points);
  addPointArray(data, "SunAzimuth", 1, azimuths);
  addPointArray(data, "SunElevation", 1, elevations);
  return data;
}

vtkSmartPointer<vtkMovingLightRadiosity> sunFilter(
  vtkPolyData* scene, vtkPolyData* directions, vtkIdType paths)
{
  auto filter = vtkSmartPointer<vtkMovingLightRadiosity>::New();
  filter->SetSceneData(scene);
  filter->SetTrajectoryData(directions);
  filter->SetLightTypeToDirectional();
  filter->SetNumberOfPaths(paths);
  filter->SetPatchSize(0.25);
  filter->SetNumberOfThreads(2);
  return filter;
}
}

TEST(FilterSun, GroundGetsRhoTimesIrradianceTimesSinElevation)
{
  const std::vector<double> elevations = { 30, 60, 90 }, azimuths = { 90, 200, 0 };
  const double irradiance = 800, rho = 0.5;
  const vtkIdType paths = 100000;
  for (bool reuse : { true, false })
  {
    SCOPED_TRACE(reuse ? "reuse" : "classic");
    auto filter = sunFilter(ground(), sunDirections(elevations, azimuths, { 1, 2, 0.5 }), paths);
    filter->SetSunIrradiance(irradiance);
    filter->SetReuseShooting(reuse);
    filter->SetReuseGathering(reuse);
    ASSERT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2 }));
    for (std::size_t f = 0; f < elevations.size(); ++f)
    {
      ASSERT_TRUE(filter->UpdateTimeStep(double(f)));
      vtkPolyData* elements = filter->GetOutput();
      vtkDataArray* direct = elements->GetCellData()->GetArray("DirectRadiosity");
      ASSERT_NE(direct, nullptr);
      ASSERT_GT(elements->GetNumberOfCells(), 0);
      const double s = std::sin(elevations[f] * Pi / 180);
      const double expected = rho * irradiance * s;
      // Paths start uniformly on a disc of the bounding sphere's radius (sqrt(2) / 2 for the
      // unit quad); an element of area a gets paths a s / (pi r^2) of them: its relative
      // standard deviation is 1 / sqrt(hits) (less with reuse). Five of them, and the mean
      // over all elements to five of its own.
      const double disc = Pi * 0.5;
      double weighted = 0, totalArea = 0;
      for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
      {
        const double a = triangleArea(elements, c);
        const double hits = double(paths) * a * s / disc;
        for (int k = 0; k < 3; ++k)
        {
          EXPECT_NEAR(direct->GetComponent(c, k) / expected, 1.0, 5 / std::sqrt(hits))
            << "frame " << f << " cell " << c;
        }
        weighted += a * direct->GetComponent(c, 1);
        totalArea += a;
      }
      const double allHits = double(paths) * totalArea * s / disc;
      EXPECT_NEAR(weighted / totalArea / expected, 1.0, 5 / std::sqrt(allHits)) << "frame " << f;
      // The direction is passed on, normalised, with the angles of its own frame.
      vtkDataArray* sun = elements->GetFieldData()->GetArray("SunDirection");
      ASSERT_NE(sun, nullptr);
      EXPECT_NEAR(sun->GetComponent(0, 2), s, 1e-12);
      EXPECT_NEAR(fieldValue(elements, "SunElevation"), elevations[f], 1e-12);
      EXPECT_NEAR(fieldValue(elements, "SunAzimuth"), azimuths[f], 1e-12);
      EXPECT_NEAR(
        fieldValue(filter->GetOutput(vtkMovingLightRadiosity::PATCHES_PORT), "SunElevation"),
        elevations[f], 1e-12);
    }
  }
}

TEST(FilterSun, TimeStepsArePointsAndPowerScalesIrradiance)
{
  // The same four directions (elevation 40) at times 6, 9, 12 and 18.5, with three Power
  // arrays: none, half at 9, and night (0) at 12.
  auto filterWith = [](const std::vector<double>& power)
  {
    auto directions = sunDirections({ 40, 40, 40, 40 }, { 0, 90, 180, 270 }, { 1, 1, 1, 1 });
    addPointArray(directions, "Time", 1, { 6, 9, 12, 18.5 });
    if (!power.empty())
    {
      addPointArray(directions, "Power", 1, power);
    }
    return sunFilter(ground(), directions, 20000);
  };
  auto full = filterWith({});
  EXPECT_EQ(timeSteps(full), (std::vector<double>{ 6, 9, 12, 18.5 }));
  const auto a = everyFrame(full, "DirectRadiosity");
  const auto b = everyFrame(filterWith({ 1, 0.5, 1, 1 }), "DirectRadiosity");
  const auto c = everyFrame(filterWith({ 1, 1, 0, 1 }), "DirectRadiosity");
  ASSERT_EQ(a.size(), 4u);
  ASSERT_EQ(b.size(), 4u);
  ASSERT_EQ(c.size(), 4u);
  // Power scales its frame's irradiance, on the same paths.
  std::vector<double> half = a[1];
  for (double& v : half)
  {
    v *= 0.5;
  }
  EXPECT_GT(maxValue(a[1]), 0.0);
  EXPECT_LT(relativeDifference(b[1], half), 1e-6);
  EXPECT_EQ(relativeDifference(b[3], a[3]), 0.0);
  EXPECT_GT(maxValue(c[1]), 0.0);
  EXPECT_EQ(maxValue(c[2]), 0.0); // night
  EXPECT_EQ(c[2].size(), a[2].size());
  // An open plane: every direction at one elevation lights it alike, within noise (20,000
  // paths, about 40% of them on the plane: 1% of the mean, four of them).
  double sums[2] = { 0, 0 };
  for (std::size_t i = 0; i < a[0].size(); ++i)
  {
    sums[0] += a[0][i];
    sums[1] += a[3][i];
  }
  EXPECT_NEAR(sums[1] / sums[0], 1.0, 0.04);
  // The Light output is empty (no area light), and no Light input was needed.
  ASSERT_TRUE(full->UpdateTimeStep(9));
  EXPECT_EQ(full->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT)->GetNumberOfCells(), 0);
  EXPECT_NEAR(fieldValue(full->GetOutput(), "SunAzimuth"), 90, 1e-12);
  EXPECT_NEAR(fieldValue(full->GetOutput(), "FrameIndex"), 1, 0);
}

TEST(FilterSun, BadDirectionsOrIrradianceAreErrors)
{
  auto zero = trajectoryPolyData({ { 0, 0, 1 }, { 0, 0, 0 } });
  expectError(sunFilter(ground(), zero, 2000), "direction 1 towards the light is (0, 0, 0)");

  auto directions = trajectoryPolyData({ { 0, 0, 1 }, { 0, 1, 1 } });
  // 0 is no direct sun: the frames stay, dark (a sky may still light them).
  auto dark = sunFilter(ground(), directions, 2000);
  dark->SetSunIrradiance(0);
  ASSERT_TRUE(dark->UpdateTimeStep(1));
  EXPECT_EQ(dark->GetOutput()->GetCellData()->GetArray("Radiosity")->GetRange(0)[1], 0.0);
  auto nan = sunFilter(ground(), directions, 2000);
  nan->SetSunIrradiance(std::numeric_limits<double>::quiet_NaN());
  expectError(nan, "irradiance");
  // A sun below the horizon of a one-sided ground lights nothing, with no error.
}

// ---------------------------------------------------------------- The Light output, aiming

namespace
{
/// The area centroid and unit normal of the Light output's (one, planar) polygon set.
void posedLight(vtkPolyData* light, Vec3& centroid, Vec3& normal)
{
  Vec3 areaSum, weighted;
  double area = 0;
  for (vtkIdType c = 0; c < light->GetNumberOfCells(); ++c)
  {
    Vec3 a, centre;
    cellGeometry(light, c, a, centre);
    areaSum += a;
    area += length(a);
    weighted += centre * length(a); // squares: the mean of the corners is the centroid
  }
  centroid = area > 0 ? weighted / area : Vec3();
  normal = length(areaSum) > 0 ? areaSum / length(areaSum) : Vec3();
}
}

TEST(FilterRigs, LightOutputIsPosedAtTheTrajectory)
{
  BoxSetup setup = closedBoxSetup(3);
  const std::vector<Vec3> normals = { { 0, 0, -1 }, TiltedNormal * 3.0, { 0, -0.6, -0.8 } };
  addPointArray(setup.trajectory, "Normal", 3,
    { normals[0].x, normals[0].y, normals[0].z, normals[1].x, normals[1].y, normals[1].z,
      normals[2].x, normals[2].y, normals[2].z });
  addPointArray(setup.trajectory, "Power", 1, { 1, 0.5, 0.25 });
  auto filter = boxFilter(setup);
  filter->SetLightPower(10, 20, 30);
  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 3u);
  for (std::size_t f = 0; f < 3; ++f)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(times[f]));
    vtkPolyData* light = filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT);
    ASSERT_GT(light->GetNumberOfCells(), 0);
    Vec3 centroid, normal;
    posedLight(light, centroid, normal);
    EXPECT_NEAR(length(centroid - setup.positions[f]), 0.0, 1e-12) << "frame " << f;
    EXPECT_NEAR(length(normal - normals[f] / length(normals[f])), 0.0, 1e-9) << "frame " << f;
    const double factor = std::vector<double>{ 1, 0.5, 0.25 }[f];
    const auto power = cellValues(light, "Power");
    double sums[3] = { 0, 0, 0 };
    for (std::size_t i = 0; i < power.size(); ++i)
    {
      sums[i % 3] += power[i];
    }
    EXPECT_NEAR(sums[0], 10 * factor, 1e-5) << "frame " << f;
    EXPECT_NEAR(sums[2], 30 * factor, 1e-5) << "frame " << f;
    // The field data's LightPosition is the centroid too.
    vtkDataArray* position = filter->GetOutput()->GetFieldData()->GetArray("LightPosition");
    ASSERT_NE(position, nullptr);
    EXPECT_NEAR(position->GetComponent(0, 0), setup.positions[f].x, 1e-12);
    EXPECT_NEAR(position->GetComponent(0, 1), setup.positions[f].y, 1e-12);
  }
}

TEST(FilterRigs, AimAtPointTurnsEveryLightTowardsIt)
{
  BoxSetup setup = closedBoxSetup(4);
  setup.light = twoLights({ 1, 1, 1 }, { 2, 2, 2 });
  setup.trajectory = polylines({ setup.positions,
    { { 0.9, 0.1, 0.5 }, { 0.8, 0.2, 0.5 }, { 0.7, 0.3, 0.5 }, { 0.6, 0.4, 0.5 } } });
  auto filter = boxFilter(setup);
  const Vec3 aim(0.2, 0.7, 0.1);
  filter->AimAtPointOn();
  filter->SetAimPoint(aim.x, aim.y, aim.z);
  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 4u);
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(times[f]));
    vtkPolyData* lights = filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT);
    ASSERT_EQ(lights->GetNumberOfCells(), 2);
    for (vtkIdType c = 0; c < 2; ++c)
    {
      Vec3 area, centre;
      cellGeometry(lights, c, area, centre);
      const Vec3 towards = (aim - centre) / length(aim - centre);
      EXPECT_NEAR(dot(area / length(area), towards), 1.0, 1e-9) << "frame " << f << " light " << c;
    }
  }
  // The wall the lights face gets more direct light than without aiming (they faced down).
  ASSERT_TRUE(filter->UpdateTimeStep(times[3]));
  const double aimed = wallPower(filter->GetOutput(), 0, false, "DirectRadiosity");
  filter->AimAtPointOff();
  ASSERT_TRUE(filter->UpdateTimeStep(times[3]));
  const double down = wallPower(filter->GetOutput(), 0, false, "DirectRadiosity");
  EXPECT_GT(aimed, 1.5 * down);
}

TEST(FilterRigs, OrientationWinsOverAimAtPoint)
{
  BoxSetup setup = turnedBox({ { "Orientation", TiltQuaternion } });
  auto filter = boxFilter(setup);
  filter->AimAtPointOn();
  filter->SetAimPoint(0, 1, 0);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  Vec3 centroid, normal;
  posedLight(filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT), centroid, normal);
  EXPECT_NEAR(length(normal - TiltedNormal), 0.0, 1e-9);
}

TEST(FilterRigs, AimPointAtALightsCentroidIsAnError)
{
  // A light cannot face the point it is at: the error names AimPoint, which is what to fix.
  BoxSetup setup = closedBoxSetup(3);
  auto filter = boxFilter(setup);
  filter->AimAtPointOn();
  filter->SetAimPoint(setup.positions[1].x, setup.positions[1].y, setup.positions[1].z);
  expectError(filter, "AimPoint");
}

TEST(FilterRigs, RigWithoutTrajectoryOrWithMixedLightPowerIsAnError)
{
  BoxSetup setup = closedBoxSetup(3);
  setup.light = twoLights({ 1, 1, 1 }, { 1, 1, 1 });
  auto filter = boxFilter(setup);
  filter->SetTrajectoryConnection(nullptr);
  expectError(filter, "connect a Trajectory with one polyline per light");

  // Light 0 is two triangles with different LightPower.
  setup.light = lightPolyData({ { { 0.4, 0.4, 0.9 }, { 0.4, 0.6, 0.9 }, { 0.6, 0.4, 0.9 } },
    { { 0.6, 0.6, 0.9 }, { 0.6, 0.4, 0.9 }, { 0.4, 0.6, 0.9 } },
    { { 0.4, 0.4, 0.7 }, { 0.4, 0.6, 0.7 }, { 0.6, 0.4, 0.7 } } });
  vtkNew<vtkIntArray> ids;
  ids->SetName("LightId");
  vtkNew<vtkDoubleArray> power;
  power->SetName("LightPower");
  for (int c = 0; c < 3; ++c)
  {
    ids->InsertNextValue(c < 2 ? 0 : 1);
    power->InsertNextValue(c == 0 ? 1 : 2);
  }
  setup.light->GetCellData()->AddArray(ids);
  setup.light->GetCellData()->AddArray(power);
  setup.trajectory = twoLightTrajectory(false);
  expectError(boxFilter(setup), "LightPower differs between the polygons of light 0");
}

TEST(FilterSun, WithoutTrajectoryTheDirectionGoesFromPathStartToPathEnd)
{
  auto filter = sunFilter(ground(), nullptr, 20000);
  filter->SetTrajectoryConnection(nullptr);
  filter->SetPathStart(-1, 0, 1);
  filter->SetPathEnd(1, 0, 1);
  filter->SetNumberOfPositions(3);
  EXPECT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2 }));
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkDataArray* sun = filter->GetOutput()->GetFieldData()->GetArray("SunDirection");
  ASSERT_NE(sun, nullptr);
  EXPECT_NEAR(sun->GetComponent(0, 2), 1.0, 1e-12); // the middle one is straight up
  ASSERT_TRUE(filter->UpdateTimeStep(2));
  EXPECT_NEAR(filter->GetOutput()->GetFieldData()->GetArray("SunDirection")->GetComponent(0, 0),
    std::sqrt(0.5), 1e-12);
  // The defaults start at the origin, which is no direction: an error naming PathStart and
  // PathEnd, not a crash; opposite directions pass through zero half-way.
  filter->SetPathStart(0, 0, 0);
  // Its times are still known, without an error: a script that sets LightType before the
  // directions must not see one.
  {
    vtkNew<MessageRecorder> messages;
    messages->watch(filter);
    EXPECT_EQ(timeSteps(filter), (std::vector<double>{ 0, 1, 2 }));
    EXPECT_EQ(messages->allErrors(), "");
  }
  expectError(filter, "from PathStart to PathEnd, and frame 0's is zero or not a number");
  filter->SetPathStart(1, 0, 1);
  filter->SetPathEnd(-1, 0, -1);
  expectError(filter, "frame 1's is zero");
}

TEST(FilterSun, TheSunAloneHasPerezsDirectEfficacy)
{
  // Sunlight is not white light: without a sky its lux are Perez's direct efficacy (about 100
  // lm/W for a high clear sun), not LuminousEfficacy's 179, in every frame.
  const std::vector<mlr::Vec3> suns = { normalize(mlr::Vec3(0.2, 0.1, 1)),
    normalize(mlr::Vec3(1, 0, 0.3)) };
  auto filter = sunFilter(ground(), trajectoryPolyData(suns), 20000);
  for (std::size_t f = 0; f < suns.size(); ++f)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(static_cast<double>(f)));
    mlr::SkyFrame frame;
    frame.sun = suns[f];
    frame.directNormal = 1000;
    frame.diffuseHorizontal = 100;
    const double expected = mlr::perezEfficacy(frame, { 0, 0, 1 }).direct;
    EXPECT_GT(expected, 60) << "frame " << f;
    EXPECT_LT(expected, 130) << "frame " << f;
    vtkPolyData* out = filter->GetOutput();
    EXPECT_DOUBLE_EQ(fieldValue(out, "LuminousEfficacy"), expected) << "frame " << f;
    auto* model =
      vtkStringArray::SafeDownCast(out->GetFieldData()->GetAbstractArray("LuminousEfficacyModel"));
    ASSERT_NE(model, nullptr);
    EXPECT_EQ(model->GetValue(0), "Perez (1990) efficacy of the direct sun");
    vtkDataArray* irradiance = out->GetCellData()->GetArray("Irradiance");
    vtkDataArray* lux = out->GetCellData()->GetArray("Illuminance");
    const double* e = irradiance->GetTuple3(0);
    EXPECT_NEAR(lux->GetComponent(0, 0), expected * (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]),
      1e-5 * lux->GetComponent(0, 0));
  }
}

TEST(FilterSun, NoSurfaceFacingTheSunIsDarkWithAWarning)
{
  // The sun below a one-sided ground: all zero, with a warning, not an error.
  auto filter = sunFilter(ground(), trajectoryPolyData({ { 0, 0.2, -1 }, { 0.3, 0, -1 } }), 20000);
  filter->TwoSidedOff();
  const FilterRun r = run(filter);
  ASSERT_TRUE(r.succeeded) << r.messages->allErrors();
  EXPECT_NE(r.messages->allWarnings().find("face away"), std::string::npos)
    << r.messages->allWarnings();
  EXPECT_GT(r.cells[0], 0);
  EXPECT_EQ(maxValue(cellValues(filter->GetOutput(), "Radiosity")), 0.0);
}

TEST(FilterRigs, LightOffInEveryFrameIsDarkWithAWarning)
{
  for (bool directional : { false, true })
  {
    SCOPED_TRACE(directional ? "directional" : "area");
    vtkSmartPointer<vtkMovingLightRadiosity> filter;
    if (directional)
    {
      auto directions = trajectoryPolyData({ { 0, 0.2, 1 }, { 0.3, 0, 1 } });
      addPointArray(directions, "Power", 1, { 0, 0 });
      filter = sunFilter(ground(), directions, 20000);
    }
    else
    {
      BoxSetup setup = closedBoxSetup(3);
      addPointArray(setup.trajectory, "Power", 1, { 0, 0, 0 });
      filter = boxFilter(setup);
    }
    const FilterRun r = run(filter);
    ASSERT_TRUE(r.succeeded) << r.messages->allErrors();
    EXPECT_NE(r.messages->allWarnings().find("off in every frame"), std::string::npos)
      << r.messages->allWarnings();
    for (const auto& frame : everyFrame(filter, "Radiosity"))
    {
      ASSERT_FALSE(frame.empty());
      EXPECT_EQ(maxValue(frame), 0.0);
    }
  }
}
