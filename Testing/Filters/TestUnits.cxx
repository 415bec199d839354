// Units: the outputs say what their numbers are, and a scene in
// millimetres gives what the same scene in metres gives, with radiosity in
// W/mm^2 instead of W/m^2.
#include "FilterTestSupport.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

using namespace mlr;
using namespace mlr::testing;

namespace
{
std::string fieldString(vtkDataObject* data, const char* name)
{
  auto* array = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray(name));
  return array && array->GetNumberOfValues() == 1 ? array->GetValue(0) : "(missing)";
}

/// A deep copy of `data` with every point multiplied by `factor`.
vtkSmartPointer<vtkPolyData> scaled(vtkPolyData* data, double factor)
{
  auto copy = vtkSmartPointer<vtkPolyData>::New();
  copy->DeepCopy(data);
  for (vtkIdType i = 0; i < copy->GetNumberOfPoints(); ++i)
  {
    double p[3];
    copy->GetPoint(i, p);
    copy->GetPoints()->SetPoint(i, factor * p[0], factor * p[1], factor * p[2]);
  }
  return copy;
}

/// The face of the closed box of side `side` that element `e`'s centroid lies
/// on: 0 to 5 for x = 0, x = side, y = 0, y = side, z = 0, z = side.
std::size_t boxFace(vtkPolyData* elements, vtkIdType e, double side)
{
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  elements->GetCellPoints(e, count, ids);
  double centroid[3] = { 0, 0, 0 };
  for (vtkIdType k = 0; k < count; ++k)
  {
    double p[3];
    elements->GetPoint(ids[k], p);
    for (int i = 0; i < 3; ++i)
    {
      centroid[i] += p[i] / static_cast<double>(count);
    }
  }
  std::size_t face = 0;
  double nearest = side;
  for (int axis = 0; axis < 3; ++axis)
  {
    for (int end = 0; end < 2; ++end)
    {
      const double distance = std::abs(centroid[axis] - end * side);
      if (distance < nearest)
      {
        nearest = distance;
        face = static_cast<std::size_t>(2 * axis + end);
      }
    }
  }
  return face;
}

/// The power (W) each face of the box receives: its elements' Radiosity times
/// area.
std::vector<Rgb> facePower(vtkPolyData* elements, double side)
{
  std::vector<Rgb> faces(6);
  vtkDataArray* radiosity = elements->GetCellData()->GetArray("Radiosity");
  for (vtkIdType e = 0; radiosity && e < elements->GetNumberOfCells(); ++e)
  {
    faces[boxFace(elements, e, side)] +=
      Rgb(radiosity->GetComponent(e, 0), radiosity->GetComponent(e, 1),
        radiosity->GetComponent(e, 2)) *
      triangleArea(elements, e);
  }
  return faces;
}

/// The area of each face of the box, from its elements.
std::vector<double> faceArea(vtkPolyData* elements, double side)
{
  std::vector<double> faces(6, 0.0);
  for (vtkIdType e = 0; e < elements->GetNumberOfCells(); ++e)
  {
    faces[boxFace(elements, e, side)] += triangleArea(elements, e);
  }
  return faces;
}

/// The filter on `setup` with its default patch size (0: about 3000 patches),
/// fixed seed.
vtkSmartPointer<vtkMovingLightRadiosity> defaultPatchFilter(const BoxSetup& setup)
{
  auto filter = fastFilter(setup);
  filter->SetPatchSize(0);
  filter->SetNumberOfPaths(50000);
  filter->SetSeed(11);
  filter->SetNumberOfThreads(2);
  filter->SetLightPower(30, 20, 10);
  return filter;
}
} // namespace

TEST(FilterUnits, OutputsStateTheUnitsOfPowerAndRadiosity)
{
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  for (int port = 0; port < 3; ++port)
  {
    vtkPolyData* output = filter->GetOutput(port);
    EXPECT_EQ(fieldString(output, "PowerUnits"), "W") << "output " << port;
    EXPECT_EQ(fieldString(output, "RadiosityUnits"), "W/(scene unit)^2") << "output " << port;
  }
}

TEST(FilterUnits, MillimetresGiveTheSamePatchesAndRadiosityTimesOneMillionth)
{
  // The closed unit box (metres) and the same box in millimetres, with the same
  // light power in watts: the same power spreads over 10^6 times the area.
  const BoxSetup metres = closedBoxSetup(3);
  BoxSetup millimetres;
  millimetres.scene = scaled(metres.scene, 1000);
  millimetres.light = scaled(metres.light, 1000);
  millimetres.trajectory = scaled(metres.trajectory, 1000);

  auto inMetres = defaultPatchFilter(metres);
  auto inMillimetres = defaultPatchFilter(millimetres);
  for (int frame = 0; frame < 3; ++frame)
  {
    ASSERT_TRUE(inMetres->UpdateTimeStep(frame));
    ASSERT_TRUE(inMillimetres->UpdateTimeStep(frame));
    vtkPolyData* m = inMetres->GetOutput(0);
    vtkPolyData* mm = inMillimetres->GetOutput(0);
    // PatchSize 0 aims at a patch count, not a length: the same patches in
    // both.
    const double patches = fieldValue(m, "Patches");
    EXPECT_GT(patches, 1000);
    EXPECT_EQ(fieldValue(mm, "Patches"), patches);
    ASSERT_EQ(mm->GetNumberOfCells(), m->GetNumberOfCells());

    // Scaling by 1000 is not exact in floating point: the two element meshes can be split
    // differently on some faces (same counts) and a few paths take other turns. So each face
    // of the box is compared as a whole: the watts it receives, and its mean radiosity,
    // W/mm^2 against W/m^2. The same seed casts the same paths in both, so the faces agree
    // far better than two independent runs would: each face receives about a tenth or more
    // of the 50,000 paths, a noise of 1/sqrt(5000) = 1.4% between independent runs; 0.5%
    // still tells a wrong scale (a factor 10^3 or 10^6) from a right one.
    const std::vector<Rgb> powerM = facePower(m, 1.0), powerMm = facePower(mm, 1000.0);
    const std::vector<double> areaM = faceArea(m, 1.0), areaMm = faceArea(mm, 1000.0);
    for (std::size_t f = 0; f < 6; ++f)
    {
      EXPECT_NEAR(areaMm[f], 1e6 * areaM[f], 1e-9 * areaMm[f]) << "face " << f;
      for (int c = 0; c < 3; ++c)
      {
        ASSERT_GT(powerM[f][c], 0) << "face " << f;
        EXPECT_NEAR(powerMm[f][c], powerM[f][c], 5e-3 * powerM[f][c])
          << "frame " << frame << ", face " << f << ", channel " << c << ": watts differ";
        const double radiosityM = powerM[f][c] / areaM[f];    // W/m^2
        const double radiosityMm = powerMm[f][c] / areaMm[f]; // W/mm^2
        EXPECT_NEAR(radiosityMm / radiosityM, 1e-6, 5e-3 * 1e-6)
          << "frame " << frame << ", face " << f << ", channel " << c;
      }
    }
  }
}

TEST(FilterUnits, APowerOfTwoScaleGivesTheSameSolutionBitForBit)
{
  // Scaling by 2^10 changes no rounding anywhere: the remesher, the paths and the estimates
  // are scale-invariant, so every element is the same triangle times 1024 with the radiosity
  // times 2^-20, exactly. (Scaling by 1000 rounds differently: a few paths out of many
  // thousands take other turns, hence the face totals above.)
  const BoxSetup metres = closedBoxSetup(2);
  BoxSetup scaledUp;
  scaledUp.scene = scaled(metres.scene, 1024);
  scaledUp.light = scaled(metres.light, 1024);
  scaledUp.trajectory = scaled(metres.trajectory, 1024);
  auto reference = defaultPatchFilter(metres);
  auto large = defaultPatchFilter(scaledUp);
  for (int frame = 0; frame < 2; ++frame)
  {
    ASSERT_TRUE(reference->UpdateTimeStep(frame));
    ASSERT_TRUE(large->UpdateTimeStep(frame));
    vtkPolyData* a = reference->GetOutput(0);
    vtkPolyData* b = large->GetOutput(0);
    ASSERT_EQ(b->GetNumberOfCells(), a->GetNumberOfCells());
    ASSERT_EQ(b->GetNumberOfPoints(), a->GetNumberOfPoints());
    std::size_t differentPoints = 0, differentValues = 0;
    for (vtkIdType p = 0; p < a->GetNumberOfPoints(); ++p)
    {
      double pa[3], pb[3];
      a->GetPoint(p, pa);
      b->GetPoint(p, pb);
      differentPoints += (pb[0] != 1024 * pa[0] || pb[1] != 1024 * pa[1] || pb[2] != 1024 * pa[2]);
    }
    vtkDataArray* ra = a->GetCellData()->GetArray("Radiosity");
    vtkDataArray* rb = b->GetCellData()->GetArray("Radiosity");
    ASSERT_NE(ra, nullptr);
    ASSERT_NE(rb, nullptr);
    for (vtkIdType e = 0; e < a->GetNumberOfCells(); ++e)
    {
      for (int c = 0; c < 3; ++c)
      {
        differentValues += (rb->GetComponent(e, c) * 1048576.0 != ra->GetComponent(e, c));
      }
    }
    EXPECT_EQ(differentPoints, 0u) << "frame " << frame;
    EXPECT_EQ(differentValues, 0u) << "frame " << frame;
    EXPECT_GT(ra->GetRange(0)[1], 0) << "frame " << frame;
  }
}
