// The Elements output's Irradiance (W/m^2) and Illuminance (lx): their arrays and units,
// Illuminance = LuminousEfficacy x luminance(Irradiance), and black surfaces have them.
#include "FilterTestSupport.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStringArray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

using namespace mlr;
using namespace mlr::testing;

namespace
{
std::string fieldString(vtkDataObject* data, const char* name)
{
  auto* array = vtkStringArray::SafeDownCast(data->GetFieldData()->GetAbstractArray(name));
  return array && array->GetNumberOfValues() == 1 ? array->GetValue(0) : "(missing)";
}

Rgb tuple(vtkDataArray* array, vtkIdType i)
{
  return { array->GetComponent(i, 0), array->GetComponent(i, 1), array->GetComponent(i, 2) };
}

/// The illuminance the outputs must hold, in the outputs' single precision.
float expectedLux(double efficacy, const Rgb& irradiance)
{
  return static_cast<float>(
    efficacy * (0.2126 * irradiance.r + 0.7152 * irradiance.g + 0.0722 * irradiance.b));
}

/// Checks that `data` has Irradiance (RGB floats) and Illuminance (one float) for each of its
/// `count` tuples, the second `efficacy` times the luminance of the first, exactly.
void expectIlluminanceOfIrradiance(vtkDataSetAttributes* data, vtkIdType count, double efficacy)
{
  auto* irradiance = vtkFloatArray::SafeDownCast(data->GetArray("Irradiance"));
  auto* illuminance = vtkFloatArray::SafeDownCast(data->GetArray("Illuminance"));
  ASSERT_TRUE(irradiance && illuminance);
  ASSERT_EQ(irradiance->GetNumberOfComponents(), 3);
  EXPECT_STREQ(irradiance->GetComponentName(0), "R");
  ASSERT_EQ(illuminance->GetNumberOfComponents(), 1);
  ASSERT_EQ(irradiance->GetNumberOfTuples(), count);
  ASSERT_EQ(illuminance->GetNumberOfTuples(), count);
  for (vtkIdType i = 0; i < count; ++i)
  {
    ASSERT_EQ(illuminance->GetValue(i), expectedLux(efficacy, tuple(irradiance, i))) << i;
  }
}

double sumOf(vtkDataArray* array)
{
  double sum = 0;
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < array->GetNumberOfComponents(); ++c)
    {
      sum += array->GetComponent(i, c);
    }
  }
  return sum;
}
}

TEST(FilterIrradiance, ArraysUnitsAndIlluminanceOfEveryFrame)
{
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  EXPECT_EQ(filter->GetLuminousEfficacy(), 179.0);
  for (int frame = 0; frame < 2; ++frame)
  {
    ASSERT_TRUE(filter->UpdateTimeStep(frame));
    vtkPolyData* elements = filter->GetOutput(vtkMovingLightRadiosity::ELEMENTS_PORT);
    ASSERT_GT(elements->GetNumberOfCells(), 0);
    expectIlluminanceOfIrradiance(elements->GetCellData(), elements->GetNumberOfCells(), 179.0);
    expectIlluminanceOfIrradiance(elements->GetPointData(), elements->GetNumberOfPoints(), 179.0);
    EXPECT_EQ(fieldValue(elements, "LuminousEfficacy"), 179.0);
    for (int port = 0; port < 3; ++port)
    {
      vtkPolyData* output = filter->GetOutput(port);
      EXPECT_EQ(fieldString(output, "IrradianceUnits"), "W/(scene unit)^2") << port;
      EXPECT_EQ(fieldString(output, "IlluminanceUnits"), "lm/(scene unit)^2") << port;
    }
    // Irradiance is what arrives: times the reflectance it is what leaves, minus emission.
    vtkCellData* cells = elements->GetCellData();
    vtkDataArray* irradiance = cells->GetArray("Irradiance");
    vtkDataArray* radiosity = cells->GetArray("Radiosity");
    vtkDataArray* emitted = cells->GetArray("EmittedRadiosity");
    vtkDataArray* reflectance = cells->GetArray("Reflectance");
    ASSERT_TRUE(radiosity && emitted && reflectance);
    double lit = 0;
    for (vtkIdType e = 0; e < elements->GetNumberOfCells(); ++e)
    {
      const Rgb E = tuple(irradiance, e), B = tuple(radiosity, e) - tuple(emitted, e);
      const Rgb rho = tuple(reflectance, e);
      for (int c = 0; c < 3; ++c)
      {
        ASSERT_NEAR(rho[c] * E[c], B[c], 1e-5 * std::max(1.0, B[c])) << "cell " << e;
      }
      lit += E.sum();
    }
    EXPECT_GT(lit, 0);
  }
}

TEST(FilterIrradiance, LuminousEfficacyScalesIlluminanceAndNotIrradiance)
{
  BoxSetup setup = closedBoxSetup(2);
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkNew<vtkPolyData> before;
  before->DeepCopy(filter->GetOutput(0));
  filter->SetLuminousEfficacy(2 * 179.0);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkPolyData* after = filter->GetOutput(0);
  EXPECT_EQ(fieldValue(after, "LuminousEfficacy"), 358.0);
  for (auto [b, a] : { std::make_pair(static_cast<vtkDataSetAttributes*>(before->GetCellData()),
                         static_cast<vtkDataSetAttributes*>(after->GetCellData())),
         std::make_pair(static_cast<vtkDataSetAttributes*>(before->GetPointData()),
           static_cast<vtkDataSetAttributes*>(after->GetPointData())) })
  {
    vtkDataArray* irradianceBefore = b->GetArray("Irradiance");
    vtkDataArray* irradianceAfter = a->GetArray("Irradiance");
    vtkDataArray* luxBefore = b->GetArray("Illuminance");
    vtkDataArray* luxAfter = a->GetArray("Illuminance");
    ASSERT_TRUE(irradianceBefore && irradianceAfter && luxBefore && luxAfter);
    ASSERT_EQ(irradianceAfter->GetNumberOfTuples(), irradianceBefore->GetNumberOfTuples());
    for (vtkIdType i = 0; i < irradianceAfter->GetNumberOfTuples(); ++i)
    {
      ASSERT_EQ(tuple(irradianceAfter, i), tuple(irradianceBefore, i)) << i;
      ASSERT_EQ(luxAfter->GetComponent(i, 0), expectedLux(358.0, tuple(irradianceAfter, i)));
      ASSERT_NEAR(luxAfter->GetComponent(i, 0), 2 * luxBefore->GetComponent(i, 0),
        1e-6 * luxAfter->GetComponent(i, 0));
    }
    EXPECT_GT(sumOf(luxAfter), 0);
  }
}

TEST(FilterIrradiance, ABlackSceneHasIrradianceAndIlluminanceButNoRadiosity)
{
  BoxSetup setup = closedBoxSetup(1);
  vtkDataArray* rho = setup.scene->GetCellData()->GetArray("Reflectance");
  ASSERT_TRUE(rho);
  for (vtkIdType i = 0; i < rho->GetNumberOfTuples(); ++i)
  {
    for (int c = 0; c < rho->GetNumberOfComponents(); ++c)
    {
      rho->SetComponent(i, c, 0.0);
    }
  }
  auto filter = fastFilter(setup);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  vtkPolyData* elements = filter->GetOutput(0);
  EXPECT_EQ(sumOf(elements->GetCellData()->GetArray("Radiosity")), 0.0);
  EXPECT_EQ(sumOf(elements->GetPointData()->GetArray("Radiosity")), 0.0);
  EXPECT_GT(sumOf(elements->GetCellData()->GetArray("Irradiance")), 0.0);
  EXPECT_GT(sumOf(elements->GetCellData()->GetArray("Illuminance")), 0.0);
  EXPECT_GT(sumOf(elements->GetPointData()->GetArray("Illuminance")), 0.0);
}

TEST(FilterIrradiance, BadLuminousEfficacyIsRefusedByName)
{
  BoxSetup setup = closedBoxSetup(1);
  for (double bad : { 0.0, -1.0, 684.0, std::numeric_limits<double>::quiet_NaN() })
  {
    auto filter = fastFilter(setup);
    filter->SetLuminousEfficacy(bad);
    vtkNew<MessageRecorder> messages;
    messages->watch(filter);
    EXPECT_FALSE(filter->UpdateTimeStep(0)) << bad;
    EXPECT_NE(messages->allErrors().find("LuminousEfficacy"), std::string::npos)
      << bad << ": " << messages->allErrors();
    EXPECT_EQ(filter->GetOutput(0)->GetNumberOfCells(), 0) << bad;
    filter->RemoveAllObservers();
  }
  // The limits themselves are fine.
  auto filter = fastFilter(setup);
  filter->SetLuminousEfficacy(683.0);
  EXPECT_TRUE(filter->UpdateTimeStep(0));
}
