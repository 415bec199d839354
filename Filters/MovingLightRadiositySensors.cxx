#include "MovingLightRadiositySensors.h"

#include "MovingLightRadiosityDisplay.h"
#include "MovingLightRadiosityOutputs.h"

#include "Error.h"

#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <string>

namespace mlr::vtksensors
{

SensorSet sensorsFromPoints(vtkPointSet* input)
{
  SensorSet sensors;
  const vtkIdType n = input ? input->GetNumberOfPoints() : 0;
  if (n == 0)
  {
    return sensors;
  }
  vtkDataArray* normals = input->GetPointData()->GetArray("Normals");
  if (!normals)
  {
    normals = input->GetPointData()->GetNormals();
  }
  if (!normals)
  {
    throw Error("the Sensors input has no point array Normals: give every sensor point the "
                "direction its measuring side faces (3 components; 0,0,1 for a work plane)");
  }
  if (normals->GetNumberOfComponents() != 3)
  {
    const int components = normals->GetNumberOfComponents();
    throw Error("the Sensors input's Normals has " + std::to_string(components) +
      (components == 1 ? " component" : " components") + ": give 3 (x, y, z)");
  }
  if (normals->GetNumberOfTuples() != n)
  {
    // Fewer would be read past their end; more belong to no sensor.
    throw Error("the Sensors input's Normals has " + std::to_string(normals->GetNumberOfTuples()) +
      " tuples for " + std::to_string(n) + " points: give one normal per sensor point");
  }
  sensors.points.resize(static_cast<std::size_t>(n));
  sensors.normals.resize(static_cast<std::size_t>(n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    double p[3], d[3];
    input->GetPoint(i, p);
    normals->GetTuple(i, d);
    sensors.points[static_cast<std::size_t>(i)] = Vec3(p[0], p[1], p[2]);
    sensors.normals[static_cast<std::size_t>(i)] = Vec3(d[0], d[1], d[2]);
  }
  try
  {
    checkSensors(sensors);
  }
  catch (const Error& e)
  {
    throw Error(std::string("the Sensors input: ") + e.what());
  }
  return sensors;
}

vtkSmartPointer<vtkPolyData> sensorMesh(
  const SensorSet& given, const SensorSolution& solution, const MetricSteps& steps)
{
  const SensorSet sensors = normalizedSensors(given);
  const std::size_t n = sensors.size();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(n));
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  normals->SetNumberOfTuples(static_cast<vtkIdType>(n));
  for (std::size_t i = 0; i < n; ++i)
  {
    const Vec3& p = sensors.points[i];
    const Vec3& d = sensors.normals[i];
    points->SetPoint(static_cast<vtkIdType>(i), p.x, p.y, p.z);
    normals->SetTuple3(static_cast<vtkIdType>(i), d.x, d.y, d.z);
    const vtkIdType id = static_cast<vtkIdType>(i);
    vertices->InsertNextCell(1, &id);
  }
  auto mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(points);
  mesh->SetVerts(vertices);
  mesh->GetPointData()->SetNormals(normals);

  const char* names[5] = { "DaylightAutonomy", "UDILow", "UDIUseful", "UDIHigh", "DirectSunHours" };
  vtkSmartPointer<vtkFloatArray> metrics[5];
  for (int k = 0; k < 5; ++k)
  {
    metrics[k] = vtkSmartPointer<vtkFloatArray>::New();
    metrics[k]->SetName(names[k]);
    metrics[k]->SetNumberOfTuples(static_cast<vtkIdType>(n));
    mesh->GetPointData()->AddArray(metrics[k]);
  }
  const std::size_t count = steps.frame.size();
  std::vector<double> illuminance(count), sun(count);
  for (std::size_t i = 0; i < n && solution.sensorCount() == n; ++i)
  {
    for (std::size_t t = 0; t < count; ++t)
    {
      illuminance[t] = steps.efficacy[t] * luminance(solution.irradiance(steps.frame[t], i));
      sun[t] = steps.sunEfficacy[t] * luminance(solution.sunIrradiance(steps.frame[t], i));
    }
    const DaylightMetrics m = daylightMetrics(
      illuminance.data(), sun.data(), count, steps.autonomyThreshold, steps.hoursPerStep);
    const double values[5] = { m.autonomy, m.udiLow, m.udiUseful, m.udiHigh, m.directSunHours };
    for (int k = 0; k < 5; ++k)
    {
      metrics[k]->SetValue(static_cast<vtkIdType>(i), static_cast<float>(values[k]));
    }
  }
  return mesh;
}

void addSensorArrays(
  const SensorSolution& solution, std::size_t frame, double efficacy, vtkPointData* pointData)
{
  const std::size_t n = solution.sensorCount();
  // An RGB irradiance per sensor and its illuminance: the values, then their standard errors.
  // The channels' errors come from the same rays and paths: the luminance of the channels'
  // errors is the luminance's error when they move together, and bounds it otherwise.
  auto addPair = [&](const char* rgbName, const char* luxName,
                   Rgb (SensorSolution::*value)(std::size_t, std::size_t) const)
  {
    auto rgb = vtkoutputs::rgbArray(rgbName, n);
    vtkNew<vtkFloatArray> lux;
    lux->SetName(luxName);
    lux->SetNumberOfTuples(static_cast<vtkIdType>(n));
    for (std::size_t i = 0; i < n; ++i)
    {
      const Rgb e = (solution.*value)(frame, i);
      vtkoutputs::setRgb(rgb, i, e);
      lux->SetValue(static_cast<vtkIdType>(i), static_cast<float>(efficacy * luminance(e)));
    }
    pointData->AddArray(rgb);
    pointData->AddArray(lux);
  };
  addPair("Irradiance", "Illuminance", &SensorSolution::irradiance);
  pointData->SetActiveScalars("Illuminance");
  // As the elements', only from a solve in batches: without them the solution's noise, which
  // the sensors read, is unknown.
  if (solution.solutionBatches() >= 2)
  {
    addPair("IrradianceStdError", "IlluminanceStdError", &SensorSolution::irradianceStdError);
  }
}

void addSensorStatistics(vtkFieldData* fieldData, const SensorSolution& solution)
{
  const SensorStatistics& statistics = solution.statistics();
  vtkoutputs::addValue<vtkIdTypeArray>(
    fieldData, "SensorShadowRays", static_cast<vtkIdType>(statistics.shadowRays));
  vtkoutputs::addValue<vtkIdTypeArray>(
    fieldData, "SensorGatheringRays", static_cast<vtkIdType>(statistics.gatheringRays));
  vtkoutputs::addValue<vtkDoubleArray>(fieldData, "SecondsSensors", statistics.seconds);
  if (solution.solutionBatches() < 2)
  {
    return;
  }
  vtkNew<vtkDoubleArray> median, p95;
  median->SetName("SensorRelativeErrorMedian");
  p95->SetName("SensorRelativeErrorP95");
  vtkNew<vtkIdTypeArray> lit;
  lit->SetName("LitSensors");
  for (std::size_t f = 0; f < solution.frameCount(); ++f)
  {
    const FrameError e = sensorFrameError(solution, f);
    median->InsertNextValue(e.median);
    p95->InsertNextValue(e.p95);
    lit->InsertNextValue(static_cast<vtkIdType>(e.litElements));
  }
  fieldData->AddArray(median);
  fieldData->AddArray(p95);
  fieldData->AddArray(lit);
}

} // namespace mlr::vtksensors
