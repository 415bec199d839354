#include "FilterTestSupport.h"

#include "GeneratedScenes.h"

#include "vtkAlgorithm.h"
#include "vtkCallbackCommand.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkMovingLightRadiosity.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <cmath>
#include <limits>

namespace mlr::testing
{

namespace
{
vtkSmartPointer<vtkPolyData> polygons(
  const std::vector<Vec3>& points, const std::vector<std::vector<vtkIdType>>& cells)
{
  vtkNew<vtkPoints> vtkPoints;
  vtkPoints->SetDataTypeToDouble();
  for (const Vec3& p : points)
  {
    vtkPoints->InsertNextPoint(p.x, p.y, p.z);
  }
  vtkNew<vtkCellArray> polys;
  for (const auto& cell : cells)
  {
    polys->InsertNextCell(static_cast<vtkIdType>(cell.size()), cell.data());
  }
  auto data = vtkSmartPointer<vtkPolyData>::New();
  data->SetPoints(vtkPoints);
  data->SetPolys(polys);
  return data;
}
}

vtkSmartPointer<vtkPolyData> scenePolyData(const PatchMesh& mesh)
{
  std::vector<std::vector<vtkIdType>> cells;
  for (const Triangle& t : mesh.triangles)
  {
    cells.push_back({ t[0], t[1], t[2] });
  }
  auto data = polygons(mesh.points, cells);
  vtkNew<vtkFloatArray> reflectance;
  reflectance->SetName("Reflectance");
  reflectance->SetNumberOfComponents(3);
  for (const Rgb& rho : mesh.reflectance)
  {
    reflectance->InsertNextTuple3(rho.r, rho.g, rho.b);
  }
  data->GetCellData()->AddArray(reflectance);
  return data;
}

vtkSmartPointer<vtkPolyData> lightPolyData(const std::vector<std::vector<Vec3>>& polygonList)
{
  std::vector<Vec3> points;
  std::vector<std::vector<vtkIdType>> cells;
  for (const auto& polygon : polygonList)
  {
    cells.emplace_back();
    for (const Vec3& p : polygon)
    {
      cells.back().push_back(static_cast<vtkIdType>(points.size()));
      points.push_back(p);
    }
  }
  return polygons(points, cells);
}

vtkSmartPointer<vtkPolyData> trajectoryPolyData(
  const std::vector<Vec3>& positions, const std::vector<double>& times)
{
  auto data = polygons(positions, {});
  if (!times.empty())
  {
    vtkNew<vtkDoubleArray> time;
    time->SetName("Time");
    for (double t : times)
    {
      time->InsertNextValue(t);
    }
    data->GetPointData()->AddArray(time);
  }
  return data;
}

BoxSetup closedBoxSetup(std::size_t frames)
{
  BoxSetup setup;
  setup.scene = scenePolyData(scenes::closedBox(4, true, { Rgb(0.5) }));
  const Vec3 centre(0.5, 0.5, 0.9);
  setup.light = lightPolyData(scenes::squareLightFacingDown(centre, 0.2));
  const Vec3 from(0.25, 0.3, 0.9), to(0.75, 0.7, 0.9);
  for (std::size_t i = 0; i < frames; ++i)
  {
    const double s = frames > 1 ? double(i) / double(frames - 1) : 0.0;
    setup.positions.push_back(from + (to - from) * s);
  }
  setup.trajectory = trajectoryPolyData(setup.positions);
  return setup;
}

vtkSmartPointer<vtkMovingLightRadiosity> fastFilter(const BoxSetup& setup)
{
  auto filter = vtkSmartPointer<vtkMovingLightRadiosity>::New();
  filter->SetInputData(vtkMovingLightRadiosity::SCENE_PORT, setup.scene);
  filter->SetInputData(vtkMovingLightRadiosity::LIGHT_PORT, setup.light);
  filter->SetInputData(vtkMovingLightRadiosity::TRAJECTORY_PORT, setup.trajectory);
  filter->SetNumberOfPaths(20000);
  filter->SetPatchSize(0.25);
  return filter;
}

std::vector<double> timeSteps(vtkAlgorithm* algorithm)
{
  algorithm->UpdateInformation();
  vtkInformation* info = algorithm->GetOutputInformation(0);
  vtkInformationDoubleVectorKey* key = vtkStreamingDemandDrivenPipeline::TIME_STEPS();
  if (!info->Has(key))
  {
    return {};
  }
  return std::vector<double>(info->Get(key), info->Get(key) + info->Length(key));
}

double fieldValue(vtkDataObject* data, const char* name)
{
  vtkDataArray* array =
    data && data->GetFieldData() ? data->GetFieldData()->GetArray(name) : nullptr;
  return array && array->GetNumberOfTuples() > 0 ? array->GetComponent(0, 0)
                                                 : std::numeric_limits<double>::quiet_NaN();
}

std::string stringValue(vtkFieldData* data, const char* name)
{
  auto* strings = vtkStringArray::SafeDownCast(data->GetAbstractArray(name));
  return strings && strings->GetNumberOfValues() > 0 ? strings->GetValue(0) : std::string();
}

Vec3 triangleAreaVector(vtkPolyData* mesh, vtkIdType cell)
{
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  mesh->GetCellPoints(cell, count, ids);
  double a[3], b[3], c[3];
  mesh->GetPoint(ids[0], a);
  mesh->GetPoint(ids[1], b);
  mesh->GetPoint(ids[2], c);
  return mlr::triangleAreaVector({ a[0], a[1], a[2] }, { b[0], b[1], b[2] }, { c[0], c[1], c[2] });
}

double triangleArea(vtkPolyData* mesh, vtkIdType cell)
{
  return 0.5 * length(triangleAreaVector(mesh, cell));
}

void MessageRecorder::Execute(vtkObject*, unsigned long event, void* data)
{
  const std::string text = data ? static_cast<const char*>(data) : "";
  (event == vtkCommand::ErrorEvent ? this->errors : this->warnings).push_back(text);
}

void MessageRecorder::watch(vtkObject* object)
{
  object->AddObserver(vtkCommand::ErrorEvent, this);
  object->AddObserver(vtkCommand::WarningEvent, this);
}

std::string MessageRecorder::allErrors() const
{
  std::string all;
  for (const std::string& e : this->errors)
  {
    all += e + "\n";
  }
  return all;
}

std::string MessageRecorder::allWarnings() const
{
  std::string all;
  for (const std::string& w : this->warnings)
  {
    all += w + "\n";
  }
  return all;
}

void logProgress(vtkAlgorithm* algorithm, ProgressLog& log, vtkCallbackCommand* command)
{
  command->SetClientData(&log);
  command->SetCallback(
    [](vtkObject* caller, unsigned long, void* data, void* amount)
    {
      auto* self = static_cast<ProgressLog*>(data);
      self->values.push_back(*static_cast<double*>(amount));
      if (!self->aborted && self->values.back() > self->threshold)
      {
        self->aborted = true;
        self->abortedAfter = self->values.size();
        static_cast<vtkAlgorithm*>(caller)->AbortExecuteOn();
      }
    });
  algorithm->AddObserver(vtkCommand::ProgressEvent, command);
}

std::string listed(const std::vector<double>& values, std::size_t from)
{
  std::string text;
  for (std::size_t i = from; i < values.size(); ++i)
  {
    text += (i > from ? ", " : "") + std::to_string(values[i]);
  }
  return text;
}

} // namespace mlr::testing
