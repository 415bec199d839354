// The filter's Sensors input and output: the output follows the time step, the lamp's
// direct light on a sensor below it is Lambert's form factor plus the room's light, the
// standard errors come as the elements' do, the metrics stay constant over time and follow
// DaylightAutonomyThreshold without solving again, and bad sensors are refused with empty
// outputs.
#include "FilterTestSupport.h"

#include "FormFactor.h"
#include "GeneratedScenes.h"

#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

using namespace mlr;
using namespace mlr::testing;

namespace
{
vtkSmartPointer<vtkPolyData> sensorData(
  const std::vector<Vec3>& points, const std::vector<Vec3>& normals, int components = 3)
{
  auto data = vtkSmartPointer<vtkPolyData>::New();
  vtkNew<vtkPoints> pts;
  for (const Vec3& p : points)
  {
    pts->InsertNextPoint(p.x, p.y, p.z);
  }
  data->SetPoints(pts);
  if (!normals.empty())
  {
    vtkNew<vtkFloatArray> array;
    array->SetName("Normals");
    array->SetNumberOfComponents(components);
    for (const Vec3& n : normals)
    {
      const double v[3] = { n.x, n.y, n.z };
      array->InsertNextTuple(v);
    }
    data->GetPointData()->AddArray(array);
  }
  return data;
}

double value(vtkPolyData* data, const char* name, vtkIdType i, int component = 0)
{
  vtkDataArray* array = data->GetPointData()->GetArray(name);
  return array ? array->GetComponent(i, component) : -1;
}
}

TEST(FilterSensors, TheSensorsFollowTheTimeStepAndReadTheLamp)
{
  const BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  const std::vector<Vec3> points = { { 0.5, 0.5, 0.3 }, { 0.2, 0.8, 0.5 } };
  filter->SetInputData(
    vtkMovingLightRadiosity::SENSORS_PORT, sensorData(points, { { 0, 0, 1 }, { 0, 0, 3 } }));
  filter->SetDaylightAutonomyThreshold(0);
  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 3u);
  double autonomy = -1;
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    filter->UpdateTimeStep(times[f]);
    vtkPolyData* sensors = filter->GetOutput(vtkMovingLightRadiosity::SENSORS_OUTPUT_PORT);
    ASSERT_EQ(sensors->GetNumberOfPoints(), 2);
    EXPECT_EQ(sensors->GetNumberOfVerts(), 2);
    EXPECT_EQ(sensors->GetInformation()->Get(vtkDataObject::DATA_TIME_STEP()), times[f]);
    EXPECT_EQ(value(sensors, "Normals", 1, 2), 1.0f) << "normals come out unit";
    // The lamp's direct light (100 W over 0.04 m^2, Lambert's formula) and the grey room's:
    // at least the direct part, and not many times it.
    std::vector<Vec3> lamp = scenes::squareLightFacingDown(setup.positions[f], 0.2)[0];
    const double direct = 100 / 0.04 * pointToPolygonFormFactor(points[0], { 0, 0, 1 }, lamp);
    const double e = value(sensors, "Irradiance", 0, 1);
    EXPECT_GT(e, direct) << "frame " << f;
    EXPECT_LT(e, 2.5 * direct) << "frame " << f;
    const double lux = value(sensors, "Illuminance", 0);
    EXPECT_NEAR(lux, 179 * e, 1e-4 * lux) << "white light: the luminance is the green channel";
    if (f == 0)
    {
      autonomy = value(sensors, "DaylightAutonomy", 0);
    }
    EXPECT_EQ(value(sensors, "DaylightAutonomy", 0), autonomy) << "constant over time";
  }
  EXPECT_EQ(autonomy, 1.0) << "a threshold of 0 lx";
  EXPECT_EQ(filter->GetSolveCount(), 1);
  filter->SetDaylightAutonomyThreshold(1e9);
  filter->UpdateTimeStep(times[1]);
  EXPECT_EQ(value(filter->GetOutput(3), "DaylightAutonomy", 0), 0.0);
  EXPECT_EQ(filter->GetSolveCount(), 1) << "a new threshold only recomputes the metrics";
  std::ostringstream print;
  filter->Print(print);
  EXPECT_NE(print.str().find("DaylightAutonomyThreshold: 1e+09 lx"), std::string::npos);
  EXPECT_NE(print.str().find("SensorRays: 512"), std::string::npos);
}

TEST(FilterSensors, StandardErrorsComeWithBatchesAsTheElementsDo)
{
  // With ErrorBatches (16 by default) every frame's sensors carry IrradianceStdError (RGB) and
  // IlluminanceStdError (the efficacy times its luminance), as the elements; the field data
  // has the lit sensors' relative error per frame. With one batch neither is there.
  const BoxSetup setup = closedBoxSetup(3);
  auto filter = fastFilter(setup);
  const std::vector<Vec3> points = { { 0.5, 0.5, 0.3 }, { 0.2, 0.8, 0.5 }, { 0.9, 0.1, 0.1 } };
  filter->SetInputData(vtkMovingLightRadiosity::SENSORS_PORT,
    sensorData(points, { { 0, 0, 1 }, { 1, 0, 0 }, { -1, 1, 1 } }));
  const std::vector<double> times = timeSteps(filter);
  ASSERT_EQ(times.size(), 3u);
  EXPECT_EQ(filter->GetErrorBatches(), 16);
  for (std::size_t f = 0; f < times.size(); ++f)
  {
    filter->UpdateTimeStep(times[f]);
    vtkPolyData* sensors = filter->GetOutput(vtkMovingLightRadiosity::SENSORS_OUTPUT_PORT);
    vtkDataArray* irradiance = sensors->GetPointData()->GetArray("IrradianceStdError");
    vtkDataArray* lux = sensors->GetPointData()->GetArray("IlluminanceStdError");
    ASSERT_NE(irradiance, nullptr);
    ASSERT_NE(lux, nullptr);
    EXPECT_EQ(irradiance->GetNumberOfComponents(), 3);
    EXPECT_EQ(lux->GetNumberOfComponents(), 1);
    ASSERT_EQ(irradiance->GetNumberOfTuples(), 3);
    ASSERT_EQ(lux->GetNumberOfTuples(), 3);
    EXPECT_STREQ(sensors->GetPointData()->GetScalars()->GetName(), "Illuminance");
    for (vtkIdType i = 0; i < 3; ++i)
    {
      for (int c = 0; c < 3; ++c)
      {
        const double e = irradiance->GetComponent(i, c);
        EXPECT_TRUE(std::isfinite(e) && e > 0) << "sensor " << i << ", frame " << f;
        // A noisy estimate's error, not a second irradiance.
        EXPECT_LT(e, 0.5 * value(sensors, "Irradiance", i, c));
      }
      EXPECT_NEAR(lux->GetComponent(i, 0), 179 * irradiance->GetComponent(i, 1),
        1e-4 * lux->GetComponent(i, 0))
        << "white light: the luminance of the error is the green channel's";
    }
    vtkFieldData* field = sensors->GetFieldData();
    for (const char* name : { "SensorRelativeErrorMedian", "SensorRelativeErrorP95", "LitSensors" })
    {
      ASSERT_NE(field->GetArray(name), nullptr) << name;
      EXPECT_EQ(field->GetArray(name)->GetNumberOfTuples(), 3) << name;
    }
    EXPECT_GT(field->GetArray("SensorRelativeErrorMedian")->GetComponent(f, 0), 0.0);
    EXPECT_LE(field->GetArray("SensorRelativeErrorMedian")->GetComponent(f, 0),
      field->GetArray("SensorRelativeErrorP95")->GetComponent(f, 0));
    EXPECT_EQ(field->GetArray("LitSensors")->GetComponent(f, 0), 3);
  }
  filter->SetErrorBatches(1);
  filter->UpdateTimeStep(times[0]);
  vtkPolyData* sensors = filter->GetOutput(vtkMovingLightRadiosity::SENSORS_OUTPUT_PORT);
  EXPECT_EQ(sensors->GetNumberOfPoints(), 3);
  EXPECT_EQ(sensors->GetPointData()->GetArray("IrradianceStdError"), nullptr);
  EXPECT_EQ(sensors->GetPointData()->GetArray("IlluminanceStdError"), nullptr);
  EXPECT_EQ(sensors->GetFieldData()->GetArray("SensorRelativeErrorP95"), nullptr);
}

TEST(FilterSensors, BadSensorsAreRefusedWithEmptyOutputs)
{
  const BoxSetup setup = closedBoxSetup(2);
  struct Case
  {
    vtkSmartPointer<vtkPolyData> sensors;
    const char* words;
  };
  const std::vector<Case> cases = {
    { sensorData({ { 0.5, 0.5, 0.5 } }, {}), "no point array Normals" },
    { sensorData({ { 0.5, 0.5, 0.5 } }, { { 0, 0, 1 } }, 2), "has 2 components" },
    { sensorData({ { 0.5, 0.5, 0.5 }, { 0.5, 0.5, 0.5 } }, { { 0, 0, 1 }, { 0, 0, 0 } }),
      "sensor 1 has a zero" },
  };
  for (const Case& c : cases)
  {
    auto filter = fastFilter(setup);
    filter->SetInputData(vtkMovingLightRadiosity::SENSORS_PORT, c.sensors);
    vtkNew<MessageRecorder> recorder;
    recorder->watch(filter);
    filter->Update();
    EXPECT_NE(recorder->allErrors().find(c.words), std::string::npos) << recorder->allErrors();
    EXPECT_NE(recorder->allErrors().find("Sensors"), std::string::npos);
    EXPECT_EQ(filter->GetOutput(0)->GetNumberOfCells(), 0);
    EXPECT_EQ(filter->GetOutput(3)->GetNumberOfPoints(), 0);
  }
}
