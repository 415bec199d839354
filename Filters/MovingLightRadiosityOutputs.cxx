#include "MovingLightRadiosityOutputs.h"

#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStringArray.h"

#include <string>

namespace mlr::vtkoutputs
{

namespace
{
vtkSmartPointer<vtkFloatArray> rgbArray(const char* name, std::size_t tuples)
{
  auto array = vtkSmartPointer<vtkFloatArray>::New();
  array->SetName(name);
  array->SetNumberOfComponents(3);
  array->SetComponentName(0, "R");
  array->SetComponentName(1, "G");
  array->SetComponentName(2, "B");
  array->SetNumberOfTuples(static_cast<vtkIdType>(tuples));
  return array;
}

void setRgb(vtkFloatArray* array, std::size_t i, const Rgb& value)
{
  const float v[3] = { static_cast<float>(value.r), static_cast<float>(value.g),
    static_cast<float>(value.b) };
  array->SetTypedTuple(static_cast<vtkIdType>(i), v);
}

vtkSmartPointer<vtkPolyData> triangleMesh(
  const std::vector<Vec3>& points, std::size_t pointCount, const std::vector<Triangle>& triangles)
{
  vtkNew<vtkPoints> vtkPoints;
  vtkPoints->SetDataTypeToDouble();
  vtkPoints->SetNumberOfPoints(static_cast<vtkIdType>(pointCount));
  for (std::size_t i = 0; i < pointCount; ++i)
  {
    vtkPoints->SetPoint(static_cast<vtkIdType>(i), points[i].x, points[i].y, points[i].z);
  }
  vtkNew<vtkCellArray> cells;
  cells->AllocateExact(static_cast<vtkIdType>(triangles.size()),
    static_cast<vtkIdType>(3 * triangles.size()));
  for (const Triangle& t : triangles)
  {
    const vtkIdType ids[3] = { t[0], t[1], t[2] };
    cells->InsertNextCell(3, ids);
  }
  auto mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(vtkPoints);
  mesh->SetPolys(cells);
  return mesh;
}

template <typename ArrayType, typename Value>
void addValue(vtkFieldData* fieldData, const char* name, Value value)
{
  vtkNew<ArrayType> array;
  array->SetName(name);
  array->InsertNextValue(value);
  fieldData->AddArray(array);
}

const char* reuseMode(bool shooting, bool gathering)
{
  return shooting ? (gathering ? "both" : "shooting") : (gathering ? "gathering" : "none");
}
}

std::uint64_t estimateOutputMemory(std::size_t elements, std::size_t points)
{
  // Element mesh: double points, 3 ids + 1 offset (64-bit) per triangle, Reflectance (3
  // floats) and PatchId; the patch mesh is a quarter of it. Per frame: Radiosity, Direct,
  // Indirect, Front and Back (3 floats each) per element, and the patches' Radiosity.
  const std::uint64_t e = elements, p = points;
  const std::uint64_t meshes = p * 24 + e * (32 + 12 + 8) + e / 4 * (32 + 12);
  const std::uint64_t frame = e * 5 * 12 + e / 4 * 12;
  return meshes + frame;
}

vtkSmartPointer<vtkPolyData> elementMesh(const Scene& scene)
{
  auto mesh = triangleMesh(scene.points(), scene.points().size(), scene.elementTriangles());
  auto reflectance = rgbArray("Reflectance", scene.elementCount());
  vtkNew<vtkIntArray> patchId;
  patchId->SetName("PatchId");
  patchId->SetNumberOfTuples(static_cast<vtkIdType>(scene.elementCount()));
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    setRgb(reflectance, e, scene.elementReflectance(e));
    patchId->SetValue(static_cast<vtkIdType>(e), static_cast<int>(Scene::patchOfElement(e)));
  }
  mesh->GetCellData()->AddArray(reflectance);
  mesh->GetCellData()->AddArray(patchId);
  return mesh;
}

vtkSmartPointer<vtkPolyData> patchMesh(const Scene& scene, std::size_t cornerCount)
{
  auto mesh = triangleMesh(scene.points(), cornerCount, scene.patchTriangles());
  auto reflectance = rgbArray("Reflectance", scene.patchCount());
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    setRgb(reflectance, p, scene.patchReflectance(p));
  }
  mesh->GetCellData()->AddArray(reflectance);
  return mesh;
}

void addElementRadiosity(
  const Solution& solution, std::size_t frame, bool twoSided, vtkCellData* cellData)
{
  const std::size_t n = solution.elementCount();
  auto total = rgbArray("Radiosity", n);
  auto direct = rgbArray("DirectRadiosity", n);
  auto indirect = rgbArray("IndirectRadiosity", n);
  vtkSmartPointer<vtkFloatArray> front, back;
  if (twoSided)
  {
    front = rgbArray("RadiosityFront", n);
    back = rgbArray("RadiosityBack", n);
  }
  for (std::size_t e = 0; e < n; ++e)
  {
    const Side lit = solution.litSide(e);
    setRgb(total, e, solution.total(frame, e, lit));
    setRgb(direct, e, solution.direct(frame, e, lit));
    setRgb(indirect, e, solution.indirect(frame, e, lit));
    if (twoSided)
    {
      setRgb(front, e, solution.total(frame, e, Side::Front));
      setRgb(back, e, solution.total(frame, e, Side::Back));
    }
  }
  cellData->AddArray(total);
  cellData->AddArray(direct);
  cellData->AddArray(indirect);
  if (twoSided)
  {
    cellData->AddArray(front);
    cellData->AddArray(back);
  }
  // Colour by total radiosity unless told otherwise.
  cellData->SetActiveScalars("Radiosity");
}

std::vector<Side> patchLitSides(const Solution& solution)
{
  // The patch radiosity is rho/A times the power a side received, so the side with the
  // larger sum over frames and channels is the one that received more power.
  std::vector<Side> sides(solution.patchCount(), Side::Front);
  for (std::size_t p = 0; p < solution.patchCount(); ++p)
  {
    double front = 0, back = 0;
    for (std::size_t f = 0; f < solution.frameCount(); ++f)
    {
      front += solution.patchRadiosity(f, p, Side::Front).sum();
      back += solution.patchRadiosity(f, p, Side::Back).sum();
    }
    sides[p] = back > front ? Side::Back : Side::Front;
  }
  return sides;
}

void addPatchRadiosity(const Solution& solution, const std::vector<Side>& litSides,
  std::size_t frame, vtkCellData* cellData)
{
  auto radiosity = rgbArray("Radiosity", solution.patchCount());
  for (std::size_t p = 0; p < solution.patchCount(); ++p)
  {
    setRgb(radiosity, p, solution.patchRadiosity(frame, p, litSides[p]));
  }
  cellData->AddArray(radiosity);
  cellData->SetActiveScalars("Radiosity");
}

vtkSmartPointer<vtkFieldData> statisticsFieldData(
  const SolverStatistics& statistics, const SolverOptions& options)
{
  auto fieldData = vtkSmartPointer<vtkFieldData>::New();
  auto count = [&](const char* name, std::uint64_t value) {
    addValue<vtkIdTypeArray>(fieldData, name, static_cast<vtkIdType>(value));
  };
  auto real = [&](const char* name, double value) {
    addValue<vtkDoubleArray>(fieldData, name, value);
  };
  count("Frames", statistics.frames);
  count("Patches", statistics.patches);
  count("Elements", statistics.elements);
  count("PathsPerFrame", statistics.effectivePathsPerFrame);
  count("PathsCast", statistics.pathsCast);
  count("ShootingRays", statistics.shootingRays);
  count("ShadowRays", statistics.shadowRays);
  count("GatheringRays", statistics.gatheringRays);
  count("MissedRays", statistics.missedRays);
  count("GatheringSides", statistics.gatheringSides);
  count("Threads", static_cast<std::uint64_t>(statistics.threads));
  count("MemoryEstimateBytes", statistics.memoryEstimateBytes);
  count("ReuseShooting", statistics.reuseShooting ? 1 : 0);
  count("ReuseGathering", statistics.reuseGathering ? 1 : 0);
  count("TwoSided", statistics.twoSided ? 1 : 0);
  addValue<vtkStringArray>(fieldData, "ReuseMode",
    std::string(reuseMode(statistics.reuseShooting, statistics.reuseGathering)));
  real("MeanPathLength", statistics.meanPathLength);
  real("SecondsRemeshing", statistics.secondsRemeshing);
  real("SecondsSetup", statistics.secondsSetup);
  real("SecondsShooting", statistics.secondsShooting);
  real("SecondsGathering", statistics.secondsGathering);
  real("SecondsSolve", statistics.secondsTotal);
  real("SecondsTotal", statistics.secondsRemeshing + statistics.secondsTotal);
  real("PredictedSpeedup",
    predictedSpeedup(statistics.frames, options.gatheringRatio, options.firstBounceSurvival,
      statistics.meanPathLength));
  return fieldData;
}

void addFrameFieldData(vtkFieldData* fieldData, std::size_t frame, const Vec3& lightPosition,
  const Vec3& lightTranslation, std::int64_t solveCount)
{
  addValue<vtkIdTypeArray>(fieldData, "FrameIndex", static_cast<vtkIdType>(frame));
  for (const auto& vector : { std::make_pair("LightPosition", lightPosition),
         std::make_pair("LightTranslation", lightTranslation) })
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName(vector.first);
    array->SetNumberOfComponents(3);
    array->InsertNextTuple3(vector.second.x, vector.second.y, vector.second.z);
    fieldData->AddArray(array);
  }
  addValue<vtkIdTypeArray>(fieldData, "SolveCount", static_cast<vtkIdType>(solveCount));
}

} // namespace mlr::vtkoutputs
