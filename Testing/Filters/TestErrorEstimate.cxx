// The filter's error estimate: RadiosityStdError on cells and points, the per-frame relative
// error in field data, a target reached with StoppedBy, none of it with one batch, and bad
// ErrorBatches, TargetRelativeError and TimeLimit refused by name.
#include "FilterTestSupport.h"
#include "GeneratedScenes.h"

#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace mlr;
using namespace mlr::testing;

namespace
{
constexpr std::size_t Frames = 3;

/// The filter's error in an update that must fail, and that the outputs are empty.
std::string failure(vtkMovingLightRadiosity* filter)
{
  vtkNew<MessageRecorder> messages;
  messages->watch(filter);
  EXPECT_EQ(filter->UpdateTimeStep(0), 0);
  EXPECT_EQ(filter->GetOutput(0)->GetNumberOfCells(), 0);
  filter->RemoveAllObservers();
  return messages->allErrors();
}
}

TEST(FilterErrorEstimate, StandardErrorArraysOnCellsAndPointsAndPerFrameFieldData)
{
  const BoxSetup setup = closedBoxSetup(Frames);
  auto filter = fastFilter(setup);
  EXPECT_EQ(filter->GetErrorBatches(), 16);
  filter->SetErrorBatches(8);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkPolyData* out = filter->GetOutput(0);
  vtkDataArray* cells = out->GetCellData()->GetArray("RadiosityStdError");
  vtkDataArray* points = out->GetPointData()->GetArray("RadiosityStdError");
  vtkDataArray* radiosity = out->GetCellData()->GetArray("Radiosity");
  ASSERT_NE(cells, nullptr);
  ASSERT_NE(points, nullptr);
  EXPECT_EQ(cells->GetNumberOfComponents(), 3);
  EXPECT_EQ(cells->GetNumberOfTuples(), out->GetNumberOfCells());
  EXPECT_EQ(points->GetNumberOfTuples(), out->GetNumberOfPoints());
  // Every lit cell has an error, smaller than its radiosity at 8 batches of 2500 paths, and
  // the point values lie within the cells' range (they are means of them).
  double cellMax = 0, pointMax = 0;
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    for (int k = 0; k < 3; ++k)
    {
      EXPECT_GT(cells->GetComponent(c, k), 0) << "cell " << c;
      EXPECT_LT(cells->GetComponent(c, k), radiosity->GetComponent(c, k)) << "cell " << c;
      cellMax = std::max(cellMax, cells->GetComponent(c, k));
    }
  }
  for (vtkIdType p = 0; p < out->GetNumberOfPoints(); ++p)
  {
    pointMax = std::max(pointMax, points->GetComponent(p, 0));
  }
  EXPECT_LE(pointMax, cellMax * (1 + 1e-6));
  // The same error in the light arriving: the radiosity's is rho times the irradiance's, and
  // the illuminance's is K times the irradiance's luminance.
  for (vtkDataSetAttributes* data : { static_cast<vtkDataSetAttributes*>(out->GetCellData()),
         static_cast<vtkDataSetAttributes*>(out->GetPointData()) })
  {
    vtkDataArray* irradiance = data->GetArray("IrradianceStdError");
    vtkDataArray* lux = data->GetArray("IlluminanceStdError");
    ASSERT_NE(irradiance, nullptr);
    ASSERT_NE(lux, nullptr);
    EXPECT_EQ(irradiance->GetNumberOfComponents(), 3);
    EXPECT_EQ(lux->GetNumberOfComponents(), 1);
    EXPECT_EQ(lux->GetNumberOfTuples(), data->GetArray("RadiosityStdError")->GetNumberOfTuples());
    for (vtkIdType i = 0; i < lux->GetNumberOfTuples(); ++i)
    {
      const double* e = irradiance->GetTuple3(i);
      EXPECT_NEAR(lux->GetComponent(i, 0),
        filter->GetLuminousEfficacy() * (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]),
        1e-5 * lux->GetComponent(i, 0));
    }
  }
  vtkDataArray* reflectance = out->GetCellData()->GetArray("Reflectance");
  vtkDataArray* irradianceCells = out->GetCellData()->GetArray("IrradianceStdError");
  for (vtkIdType c = 0; c < out->GetNumberOfCells(); ++c)
  {
    EXPECT_NEAR(cells->GetComponent(c, 1),
      reflectance->GetComponent(c, 1) * irradianceCells->GetComponent(c, 1),
      1e-5 * cells->GetComponent(c, 1));
  }

  vtkFieldData* field = out->GetFieldData();
  vtkDataArray* median = field->GetArray("RelativeErrorMedian");
  vtkDataArray* p95 = field->GetArray("RelativeErrorP95");
  ASSERT_NE(median, nullptr);
  ASSERT_NE(p95, nullptr);
  ASSERT_EQ(p95->GetNumberOfTuples(), static_cast<vtkIdType>(Frames));
  for (vtkIdType f = 0; f < p95->GetNumberOfTuples(); ++f)
  {
    EXPECT_GT(median->GetComponent(f, 0), 0);
    EXPECT_LE(median->GetComponent(f, 0), p95->GetComponent(f, 0));
    EXPECT_LT(p95->GetComponent(f, 0), 1);
  }
  EXPECT_EQ(fieldValue(out, "ErrorBatches"), 8);
  EXPECT_EQ(fieldValue(out, "PathsPerFrame"), 20000);
  EXPECT_EQ(stringValue(field, "StoppedBy"), "batches");
}

TEST(FilterErrorEstimate, EachSideHasItsOwnStandardError)
{
  // A panel at mid-height in the box: its top lit by the lamp, its underside by the floor's
  // bounce. Each side's value gets each side's error, the lit side's the one of
  // RadiosityStdError.
  BoxSetup setup = closedBoxSetup(Frames);
  PatchMesh mesh = scenes::closedBox(4, true, { Rgb(0.5) });
  scenes::addGriddedQuad(
    mesh, Vec3(0.3, 0.3, 0.5), Vec3(0.4, 0, 0), Vec3(0, 0.4, 0), 2, 2, Rgb(0.6, 0.5, 0.4));
  setup.scene = scenePolyData(mesh);
  auto filter = fastFilter(setup);
  filter->SetErrorBatches(8);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  vtkPolyData* out = filter->GetOutput(0);
  vtkCellData* cells = out->GetCellData();
  vtkDataArray* litError = cells->GetArray("RadiosityStdError");
  vtkDataArray* radiosity = cells->GetArray("Radiosity");
  std::size_t panelCells = 0;
  for (vtkIdType c = 0; c < cells->GetNumberOfTuples(); ++c)
  {
    bool matchesLit = false, allLit = true; // allLit: both sides' errors in (0, value)
    for (const char* side : { "Front", "Back" })
    {
      vtkDataArray* value = cells->GetArray((std::string("Radiosity") + side).c_str());
      vtkDataArray* error = cells->GetArray((std::string("RadiosityStdError") + side).c_str());
      vtkDataArray* arriving = cells->GetArray((std::string("IrradianceStdError") + side).c_str());
      vtkDataArray* lux = cells->GetArray((std::string("IlluminanceStdError") + side).c_str());
      ASSERT_NE(error, nullptr) << side;
      ASSERT_NE(arriving, nullptr) << side;
      ASSERT_NE(lux, nullptr) << side;
      const double* e = arriving->GetTuple3(c);
      EXPECT_NEAR(lux->GetComponent(c, 0),
        filter->GetLuminousEfficacy() * (0.2126 * e[0] + 0.7152 * e[1] + 0.0722 * e[2]),
        1e-5 * lux->GetComponent(c, 0));
      bool same = true;
      for (int k = 0; k < 3; ++k)
      {
        same = same && error->GetComponent(c, k) == litError->GetComponent(c, k) &&
          value->GetComponent(c, k) == radiosity->GetComponent(c, k);
        // Lit by many batches' paths here: an error above 0 and below the value.
        allLit = allLit && error->GetComponent(c, k) > 0 &&
          error->GetComponent(c, k) < value->GetComponent(c, k);
      }
      matchesLit = matchesLit || same;
    }
    EXPECT_TRUE(matchesLit) << "cell " << c << ": neither side's error is the lit side's";
    double bounds[6];
    out->GetCellBounds(c, bounds);
    if (bounds[4] > 0.49 && bounds[5] < 0.51)
    {
      EXPECT_TRUE(allLit) << "panel cell " << c << ": a side without an error below its value";
      ++panelCells;
    }
  }
  EXPECT_GE(panelCells, std::size_t(16));
  // One-sided, the sides' arrays are not there.
  filter->SetTwoSided(false);
  ASSERT_TRUE(filter->UpdateTimeStep(1));
  EXPECT_EQ(filter->GetOutput(0)->GetCellData()->GetArray("RadiosityStdErrorFront"), nullptr);
  EXPECT_NE(filter->GetOutput(0)->GetCellData()->GetArray("RadiosityStdError"), nullptr);
}

TEST(FilterErrorEstimate, OneBatchHasNoErrorArrays)
{
  const BoxSetup setup = closedBoxSetup(Frames);
  auto filter = fastFilter(setup);
  filter->SetErrorBatches(1);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  vtkPolyData* out = filter->GetOutput(0);
  EXPECT_EQ(out->GetCellData()->GetArray("RadiosityStdError"), nullptr);
  EXPECT_EQ(out->GetPointData()->GetArray("RadiosityStdError"), nullptr);
  EXPECT_EQ(out->GetCellData()->GetArray("IlluminanceStdError"), nullptr);
  EXPECT_EQ(out->GetFieldData()->GetArray("RelativeErrorP95"), nullptr);
}

TEST(FilterErrorEstimate, TargetIsReachedInEveryFrame)
{
  const BoxSetup setup = closedBoxSetup(Frames);
  auto filter = fastFilter(setup);
  filter->SetNumberOfPaths(16000);
  filter->SetTargetRelativeError(0.04);
  vtkNew<MessageRecorder> messages;
  messages->watch(filter);
  ASSERT_TRUE(filter->UpdateTimeStep(0));
  EXPECT_TRUE(messages->warnings.empty()) << messages->allWarnings();
  vtkPolyData* out = filter->GetOutput(0);
  EXPECT_EQ(stringValue(out->GetFieldData(), "StoppedBy"), "target");
  EXPECT_GT(fieldValue(out, "ErrorBatches"), 16);
  EXPECT_GT(fieldValue(out, "PathsPerFrame"), 16000);
  vtkDataArray* p95 = out->GetFieldData()->GetArray("RelativeErrorP95");
  ASSERT_NE(p95, nullptr);
  for (vtkIdType f = 0; f < p95->GetNumberOfTuples(); ++f)
  {
    EXPECT_LE(p95->GetComponent(f, 0), 0.04) << "frame " << f;
  }
  // The last progress text is the last round's error.
  ASSERT_NE(filter->GetProgressText(), nullptr);
  EXPECT_NE(std::string(filter->GetProgressText()).find("reached"), std::string::npos)
    << filter->GetProgressText();
}

TEST(FilterErrorEstimate, BadErrorPropertiesAreRefusedByName)
{
  const BoxSetup setup = closedBoxSetup(Frames);
  auto filter = fastFilter(setup);
  filter->SetErrorBatches(0);
  EXPECT_NE(failure(filter).find("ErrorBatches"), std::string::npos);
  filter->SetErrorBatches(-3);
  EXPECT_NE(failure(filter).find("ErrorBatches is -3: give 1"), std::string::npos);
  filter->SetErrorBatches(100000);
  EXPECT_NE(failure(filter).find("ErrorBatches"), std::string::npos);
  filter->SetErrorBatches(16);
  filter->SetTargetRelativeError(-0.02);
  EXPECT_NE(failure(filter).find("TargetRelativeError"), std::string::npos);
  filter->SetTargetRelativeError(std::numeric_limits<double>::quiet_NaN());
  EXPECT_NE(failure(filter).find("TargetRelativeError"), std::string::npos);
  filter->SetTargetRelativeError(0.02);
  filter->SetTimeLimit(-1);
  EXPECT_NE(failure(filter).find("TimeLimit"), std::string::npos);
  // Fixed, the same filter solves.
  filter->SetTimeLimit(0);
  filter->SetTargetRelativeError(0);
  EXPECT_TRUE(filter->UpdateTimeStep(0));
}
