// What a viewer sees: display colours, smooth-shading points and the light itself.
#include "FilterTestSupport.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <vector>

using namespace mlr;
using namespace mlr::testing;

namespace
{
// The tone map as the documentation states it, written out again here so that the filter is
// held to the documented curve, not to its own code.
double aces(double x)
{
  x = std::max(x, 0.0);
  return std::min(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 1.0);
}

double srgb(double c)
{
  c = std::clamp(c, 0.0, 1.0);
  return 255.0 * (c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055);
}

/// The linear value before the tone map that an 8-bit sRGB value shows (bisection on the
/// monotonic curve); only meaningful away from 0 and 255.
double exposedValue(int byte)
{
  double lo = 0, hi = 64;
  for (int i = 0; i < 80; ++i)
  {
    const double mid = 0.5 * (lo + hi);
    (srgb(aces(mid)) < byte ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

double luminance(const double rgb[3])
{
  return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2];
}

Vec3 cellNormal(vtkPolyData* mesh, vtkIdType cell)
{
  return normalize(triangleAreaVector(mesh, cell));
}

/// The cells around each point.
std::vector<std::vector<vtkIdType>> cellsAroundPoints(vtkPolyData* mesh)
{
  std::vector<std::vector<vtkIdType>> around(static_cast<std::size_t>(mesh->GetNumberOfPoints()));
  for (vtkIdType c = 0; c < mesh->GetNumberOfCells(); ++c)
  {
    vtkIdType count = 0;
    const vtkIdType* ids = nullptr;
    mesh->GetCellPoints(c, count, ids);
    for (vtkIdType k = 0; k < count; ++k)
    {
      around[static_cast<std::size_t>(ids[k])].push_back(c);
    }
  }
  return around;
}

/// The box of the filter tests with the floor's half x < 0.5 in a darker material: one flat
/// surface with a material boundary across it.
BoxSetup twoMaterialFloorSetup(std::size_t frames)
{
  BoxSetup setup = closedBoxSetup(frames);
  vtkDataArray* reflectance = setup.scene->GetCellData()->GetArray("Reflectance");
  for (vtkIdType c = 0; c < setup.scene->GetNumberOfCells(); ++c)
  {
    double bounds[6];
    setup.scene->GetCellBounds(c, bounds);
    if (bounds[5] < 1e-9 && bounds[1] <= 0.5 + 1e-9)
    {
      reflectance->SetTuple3(c, 0.2, 0.2, 0.2);
    }
  }
  return setup;
}
}

TEST(FilterDisplay, ColorIsTheNamedToneMapOfTheExposedRadiosity)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkPolyData* elements = filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
  const double scale = fieldValue(elements, "ExposureScale");
  EXPECT_DOUBLE_EQ(scale, std::exp2(fieldValue(elements, "AutoExposure")));
  EXPECT_EQ(fieldValue(elements, "Exposure"), 0.0);

  for (vtkDataSetAttributes* data : { static_cast<vtkDataSetAttributes*>(elements->GetCellData()),
         static_cast<vtkDataSetAttributes*>(elements->GetPointData()) })
  {
    auto* color = vtkUnsignedCharArray::SafeDownCast(data->GetArray("Color"));
    vtkDataArray* radiosity = data->GetArray("Radiosity");
    ASSERT_NE(color, nullptr);
    ASSERT_NE(radiosity, nullptr);
    EXPECT_EQ(color->GetNumberOfComponents(), 3);
    EXPECT_EQ(data->GetScalars(), color) << "Color is not the active scalars";
    int worst = 0;
    for (vtkIdType i = 0; i < color->GetNumberOfTuples(); ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        const double expected = srgb(aces(scale * radiosity->GetComponent(i, c)));
        worst = std::max(worst,
          static_cast<int>(std::ceil(std::abs(expected - color->GetTypedComponent(i, c)) - 0.5)));
      }
    }
    EXPECT_EQ(worst, 0) << "Color differs from round(sRGB(ACES(ExposureScale x Radiosity)))";
  }
  // The physical arrays stay.
  for (const char* name : { "Radiosity", "DirectRadiosity", "IndirectRadiosity", "Reflectance" })
  {
    EXPECT_NE(elements->GetCellData()->GetArray(name), nullptr) << name;
  }
}

TEST(FilterDisplay, ExposurePlusOneDoublesTheValueBeforeTheToneMapWithoutSolving)
{
  BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkPolyData* elements = filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
  const double scale0 = fieldValue(elements, "ExposureScale");
  vtkNew<vtkUnsignedCharArray> before;
  before->DeepCopy(elements->GetCellData()->GetArray("Color"));
  vtkNew<vtkFloatArray> radiosity;
  radiosity->DeepCopy(elements->GetCellData()->GetArray("Radiosity"));

  filter->SetExposure(1);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  EXPECT_EQ(filter->GetSolveCount(), 1) << "a new exposure solved again";
  elements = filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
  EXPECT_DOUBLE_EQ(fieldValue(elements, "ExposureScale"), 2 * scale0);
  auto* after = vtkUnsignedCharArray::SafeDownCast(elements->GetCellData()->GetArray("Color"));
  ASSERT_NE(after, nullptr);

  // On the floor, a flat region lit smoothly, the value under each colour doubles: read back
  // through the inverse tone map where 8 bits resolve it (away from black and white).
  std::vector<double> ratios;
  for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
  {
    double bounds[6];
    elements->GetCellBounds(c, bounds);
    const int b0 = before->GetTypedComponent(c, 1), b1 = after->GetTypedComponent(c, 1);
    if (bounds[5] < 1e-6 && b0 > 40 && b1 < 230)
    {
      ratios.push_back(exposedValue(b1) / exposedValue(b0));
    }
  }
  ASSERT_GT(ratios.size(), 10u);
  std::sort(ratios.begin(), ratios.end());
  // One step of 8 bits moves the read-back value by at most 2.5% in this range.
  EXPECT_NEAR(ratios[ratios.size() / 2], 2.0, 0.05);
  EXPECT_GT(ratios.front(), 2.0 * 0.9);
  EXPECT_LT(ratios.back(), 2.0 * 1.1);
  // And exactly: the colours are those of twice the radiosity at the old exposure.
  for (vtkIdType c = 0; c < elements->GetNumberOfCells(); ++c)
  {
    const double expected = srgb(aces(2 * scale0 * radiosity->GetComponent(c, 0)));
    ASSERT_LE(std::abs(expected - after->GetTypedComponent(c, 0)), 0.5 + 1e-9) << "cell " << c;
  }

  filter->SetExposure(-1);
  ASSERT_TRUE(filter->UpdateTimeStep(2));
  EXPECT_EQ(filter->GetSolveCount(), 1);
  EXPECT_DOUBLE_EQ(fieldValue(filter->GetOutput(), "ExposureScale"), 0.5 * scale0);
  filter->SetSeed(3); // any other property still solves again
  ASSERT_TRUE(filter->UpdateTimeStep(2));
  EXPECT_EQ(filter->GetSolveCount(), 2);
}

TEST(FilterDisplay, AutomaticExposureIsOneForTheWholeAnimation)
{
  BoxSetup setup = closedBoxSetup(4);
  auto filter = fastFilter(setup);
  std::vector<double> luminances;
  std::set<double> exposures;
  for (int frame = 0; frame < 4; ++frame)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(frame));
    vtkPolyData* elements = filter->GetOutput();
    exposures.insert(fieldValue(elements, "AutoExposure"));
    vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
    for (vtkIdType c = 0; c < radiosity->GetNumberOfTuples(); ++c)
    {
      double rgb[3];
      radiosity->GetTuple(c, rgb);
      luminances.push_back(luminance(rgb));
    }
  }
  ASSERT_EQ(exposures.size(), 1u) << "frames got different automatic exposures";
  // The 99th percentile of every frame's lit-side luminance maps to 1 (the histogram's
  // steps are 1/64 EV, the float arrays add a little).
  const auto rank = static_cast<std::size_t>(std::ceil(0.99 * luminances.size())) - 1;
  std::nth_element(luminances.begin(), luminances.begin() + rank, luminances.end());
  EXPECT_NEAR(*exposures.begin(), -std::log2(luminances[rank]), 1.0 / 64);
}

TEST(FilterDisplay, SmoothShadingAveragesOnlyAcrossSmoothEdgesOfOneMaterial)
{
  BoxSetup setup = twoMaterialFloorSetup(2);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  vtkPolyData* elements = filter->GetOutput();
  vtkDataArray* cellRadiosity = elements->GetCellData()->GetArray("Radiosity");
  vtkDataArray* pointRadiosity = elements->GetPointData()->GetArray("Radiosity");
  vtkDataArray* reflectance = elements->GetCellData()->GetArray("Reflectance");
  vtkDataArray* scenePoint = elements->GetPointData()->GetArray("ScenePointId");
  ASSERT_NE(pointRadiosity, nullptr);
  ASSERT_NE(scenePoint, nullptr);
  ASSERT_EQ(pointRadiosity->GetNumberOfTuples(), elements->GetNumberOfPoints());

  const auto around = cellsAroundPoints(elements);
  // Per scene point, the (normal, material) groups of its output points.
  std::map<vtkIdType, std::vector<std::pair<Vec3, double>>> splits;
  for (vtkIdType p = 0; p < elements->GetNumberOfPoints(); ++p)
  {
    const auto& cells = around[static_cast<std::size_t>(p)];
    ASSERT_FALSE(cells.empty()) << "point " << p << " belongs to no cell";
    const Vec3 normal = cellNormal(elements, cells[0]);
    const double material = reflectance->GetComponent(cells[0], 0);
    double sum[3] = { 0, 0, 0 }, area = 0;
    for (vtkIdType c : cells)
    {
      ASSERT_GT(dot(cellNormal(elements, c), normal), 0.999)
        << "point " << p << " blends cells across a crease";
      ASSERT_EQ(reflectance->GetComponent(c, 0), material)
        << "point " << p << " blends two materials";
      const double a = triangleArea(elements, c);
      for (int k = 0; k < 3; ++k)
      {
        sum[k] += a * cellRadiosity->GetComponent(c, k);
      }
      area += a;
    }
    for (int k = 0; k < 3; ++k)
    {
      ASSERT_NEAR(pointRadiosity->GetComponent(p, k), sum[k] / area, 1e-4 * (1 + sum[k] / area))
        << "point " << p << " is not the area-weighted mean of its cells";
    }
    splits[static_cast<vtkIdType>(scenePoint->GetComponent(p, 0))].emplace_back(normal, material);
  }
  // Splits only where needed: the copies of one scene point differ in normal or material.
  std::size_t split = 0, materialOnly = 0;
  for (const auto& entry : splits)
  {
    const auto& groups = entry.second;
    split += groups.size() > 1;
    for (std::size_t i = 0; i < groups.size(); ++i)
    {
      for (std::size_t j = i + 1; j < groups.size(); ++j)
      {
        const bool sameNormal = dot(groups[i].first, groups[j].first) > 0.999;
        ASSERT_FALSE(sameNormal && groups[i].second == groups[j].second)
          << "scene point " << entry.first << " was split without a crease or a material edge";
        materialOnly += sameNormal;
      }
    }
  }
  EXPECT_GT(split, 0u);
  EXPECT_GT(materialOnly, 0u) << "the floor's material boundary split no point";
}

TEST(FilterDisplay, LightOutputIsTheLampWhereTheTrajectoryPutsIt)
{
  BoxSetup setup = closedBoxSetup(5);
  auto filter = fastFilter(setup);
  filter->SetLightPower(30, 60, 90);
  for (int frame : { 0, 3, 4 })
  {
    ASSERT_TRUE(filter->UpdateTimeStep(frame));
    vtkPolyData* light = filter->GetOutput(vtkMovingLightRadiosity::LIGHT_OUTPUT_PORT);
    ASSERT_GT(light->GetNumberOfCells(), 0) << "frame " << frame;
    EXPECT_EQ(light->GetNumberOfCells(), setup.light->GetNumberOfCells());
    vtkDataArray* power = light->GetCellData()->GetArray("Power");
    ASSERT_NE(power, nullptr);
    // The area centroid of the posed polygons (fan triangles) is the frame's position.
    Vec3 centroid;
    double area = 0, total[3] = { 0, 0, 0 };
    for (vtkIdType c = 0; c < light->GetNumberOfCells(); ++c)
    {
      vtkIdType count = 0;
      const vtkIdType* ids = nullptr;
      light->GetCellPoints(c, count, ids);
      double p0[3], p1[3], p2[3];
      light->GetPoint(ids[0], p0);
      for (vtkIdType k = 1; k + 1 < count; ++k)
      {
        light->GetPoint(ids[k], p1);
        light->GetPoint(ids[k + 1], p2);
        const Vec3 a(p0[0], p0[1], p0[2]), b(p1[0], p1[1], p1[2]), d(p2[0], p2[1], p2[2]);
        const double t = 0.5 * length(triangleAreaVector(a, b, d));
        centroid += (a + b + d) * (t / 3);
        area += t;
      }
      for (int k = 0; k < 3; ++k)
      {
        total[k] += power->GetComponent(c, k);
      }
    }
    centroid = centroid / area;
    const Vec3& expected = setup.positions[static_cast<std::size_t>(frame)];
    EXPECT_NEAR(centroid.x, expected.x, 1e-9) << "frame " << frame;
    EXPECT_NEAR(centroid.y, expected.y, 1e-9) << "frame " << frame;
    EXPECT_NEAR(centroid.z, expected.z, 1e-9) << "frame " << frame;
    EXPECT_NEAR(total[0], 30, 1e-4);
    EXPECT_NEAR(total[1], 60, 1e-4);
    EXPECT_NEAR(total[2], 90, 1e-4);
    EXPECT_EQ(fieldValue(light, "FrameIndex"), frame);
  }
  EXPECT_EQ(filter->GetSolveCount(), 1);
}
