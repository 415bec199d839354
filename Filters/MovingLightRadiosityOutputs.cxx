#include "MovingLightRadiosityOutputs.h"

#include "MovingLightRadiosityDisplay.h"
#include "Plural.h"

#include "vtkAbstractCellLocator.h"
#include "vtkCellArray.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkIdTypeArray.h"
#include "vtkIntArray.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStaticCellLocator.h"
#include "vtkStringArray.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <optional>
#include <string>

namespace mlr::vtkoutputs
{

namespace
{
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
  cells->AllocateExact(
    static_cast<vtkIdType>(triangles.size()), static_cast<vtkIdType>(3 * triangles.size()));
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

const char* reuseMode(bool shooting, bool gathering)
{
  return shooting ? (gathering ? "both" : "shooting") : (gathering ? "gathering" : "none");
}
}

void setRgb(vtkFloatArray* array, std::size_t i, const Rgb& value)
{
  const float v[3] = { static_cast<float>(value.r), static_cast<float>(value.g),
    static_cast<float>(value.b) };
  array->SetTypedTuple(static_cast<vtkIdType>(i), v);
}

std::uint64_t estimateOutputMemory(std::size_t elements, std::size_t points)
{
  // Element mesh: double points, 3 ids + 1 offset (64-bit) per triangle, Reflectance (3
  // floats) and PatchId; the patch mesh is a quarter of it. Smooth shading splits points at
  // creases: taken as a quarter more points than elements, each with 24 bytes of
  // coordinates, a ScenePointId and an inverse area, and 3 corner ids per element. Per
  // frame: Radiosity, Direct, Indirect, Emitted, Front, Back, Irradiance and its Front and
  // Back (3 floats each), Illuminance and its Front and Back (a float each) and Color (3
  // bytes) per element, point Radiosity, Irradiance, Illuminance and Color, and the patches'
  // Radiosity; RadiosityStdError and IrradianceStdError (3 floats) and IlluminanceStdError
  // (a float) on cells and points, and each side's on cells, counted whether or not the
  // solve estimates its error.
  const std::uint64_t e = elements, p = points;
  const std::uint64_t split = p + e / 4;
  const std::uint64_t meshes =
    p * 24 + split * (24 + 4 + 8) + e * (32 + 12 + 8 + 24) + e / 4 * (32 + 12);
  const std::uint64_t frame =
    e * (15 * 12 + 6 * 4 + 3) + split * (12 + 12 + 12 + 12 + 4 + 4 + 3) + e / 4 * 12;
  return meshes + frame;
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

namespace
{
std::vector<vtkIdType> nearestCellsBy(vtkAbstractCellLocator* locator,
  const std::vector<Vec3>& points, const std::vector<Triangle>& triangles)
{
  std::vector<vtkIdType> nearest(triangles.size(), -1);
  vtkNew<vtkGenericCell> cell;
  for (std::size_t t = 0; t < triangles.size(); ++t)
  {
    const Triangle& tri = triangles[t];
    const Vec3 c = (points[tri[0]] + points[tri[1]] + points[tri[2]]) / 3.0;
    const double x[3] = { c.x, c.y, c.z };
    double closest[3];
    int subId = 0;
    double distance2 = 0;
    locator->FindClosestPoint(x, closest, cell, nearest[t], subId, distance2);
  }
  return nearest;
}

vtkSmartPointer<vtkStaticCellLocator> locatorOf(vtkPolyData* scene)
{
  auto locator = vtkSmartPointer<vtkStaticCellLocator>::New();
  locator->SetDataSet(scene);
  locator->BuildLocator();
  return locator;
}
}

std::vector<vtkIdType> nearestCells(
  vtkPolyData* scene, const std::vector<Vec3>& points, const std::vector<Triangle>& triangles)
{
  if (!scene || scene->GetNumberOfCells() == 0)
  {
    return std::vector<vtkIdType>(triangles.size(), -1);
  }
  return nearestCellsBy(locatorOf(scene), points, triangles);
}

std::vector<vtkAbstractArray*> sceneCellArraysToPass(
  vtkPolyData* input, std::vector<std::string>* warnings)
{
  // The meshes' own arrays (patchMesh, smoothElementMesh) and those a frame writes.
  static const char* const OwnArrays[] = { "Reflectance", "PatchId", "Radiosity", "DirectRadiosity",
    "IndirectRadiosity", "EmittedRadiosity", "RadiosityFront", "RadiosityBack", "Color",
    "Irradiance", "Illuminance", "IrradianceFront", "IrradianceBack", "IlluminanceFront",
    "IlluminanceBack", "RadiosityStdError", "IrradianceStdError", "IlluminanceStdError",
    "RadiosityStdErrorFront", "RadiosityStdErrorBack", "IrradianceStdErrorFront",
    "IrradianceStdErrorBack", "IlluminanceStdErrorFront", "IlluminanceStdErrorBack" };
  std::vector<vtkAbstractArray*> passed;
  std::string named; // arrays with an output's name, as the warning lists them
  std::size_t namedCount = 0;
  vtkCellData* from = input ? input->GetCellData() : nullptr;
  for (int a = 0; from && a < from->GetNumberOfArrays(); ++a)
  {
    vtkAbstractArray* array = from->GetAbstractArray(a);
    const std::string name = array && array->GetName() ? array->GetName() : "";
    if (name.empty() || name.rfind("MovingLightRadiosity", 0) == 0 || name.rfind("vtk", 0) == 0 ||
      name == "Reflectance")
    {
      continue;
    }
    if (std::find(std::begin(OwnArrays), std::end(OwnArrays), name) != std::end(OwnArrays))
    {
      named += (named.empty() ? "'" : ", '") + name + "'";
      ++namedCount;
      continue;
    }
    if (array->GetNumberOfTuples() != input->GetNumberOfCells())
    {
      if (warnings)
      {
        warnings->push_back("the Scene's cell array '" + name + "' has " +
          std::to_string(array->GetNumberOfTuples()) + " values for " +
          countOf(static_cast<std::size_t>(input->GetNumberOfCells()), "cell") +
          ": it is not passed to the outputs");
      }
      continue;
    }
    passed.push_back(array);
  }
  if (warnings && namedCount > 0)
  {
    // One warning: a scene that is an earlier output carries a dozen of them.
    warnings->push_back(std::string("the Scene's cell ") +
      (namedCount == 1 ? "array " : "arrays ") + named + (namedCount == 1 ? " has" : " have") +
      " the name of an output array: the outputs carry their own, not the Scene's (rename " +
      (namedCount == 1 ? "it" : "them") + " to keep " + (namedCount == 1 ? "it" : "them") + ")");
  }
  return passed;
}

std::uint64_t bytesPerCell(const std::vector<vtkAbstractArray*>& arrays)
{
  std::uint64_t bytes = 0;
  for (vtkAbstractArray* array : arrays)
  {
    // A string array's values are strings of their own: taken at 32 bytes each.
    const auto value = static_cast<std::uint64_t>(
      array->IsA("vtkStringArray") ? 32 : std::max(array->GetDataTypeSize(), 1));
    bytes += value * static_cast<std::uint64_t>(std::max(array->GetNumberOfComponents(), 1));
  }
  return bytes;
}

void passSceneCellArrays(vtkPolyData* input, const std::vector<vtkAbstractArray*>& passed,
  const Scene& scene, vtkPolyData* elements, vtkPolyData* patches)
{
  if (passed.empty() || !input || input->GetNumberOfCells() == 0)
  {
    return;
  }
  const vtkSmartPointer<vtkStaticCellLocator> locator = locatorOf(input);
  for (auto [mesh, triangles] : { std::make_pair(elements, &scene.elementTriangles()),
         std::make_pair(patches, &scene.patchTriangles()) })
  {
    const std::vector<vtkIdType> nearest = nearestCellsBy(locator, scene.points(), *triangles);
    vtkNew<vtkIdList> sourceIds;
    vtkNew<vtkIdList> targetIds;
    for (std::size_t t = 0; t < nearest.size(); ++t)
    {
      if (nearest[t] >= 0)
      {
        sourceIds->InsertNextId(nearest[t]);
        targetIds->InsertNextId(static_cast<vtkIdType>(t));
      }
    }
    for (vtkAbstractArray* array : passed)
    {
      vtkSmartPointer<vtkAbstractArray> copy;
      copy.TakeReference(array->NewInstance());
      copy->SetName(array->GetName());
      copy->SetNumberOfComponents(array->GetNumberOfComponents());
      copy->SetNumberOfTuples(static_cast<vtkIdType>(triangles->size()));
      copy->InsertTuples(targetIds, sourceIds, array);
      mesh->GetCellData()->AddArray(copy);
    }
    vtkAbstractArray* names = input->GetFieldData()->GetAbstractArray("MaterialNames");
    if (names && mesh->GetCellData()->HasArray("MaterialId"))
    {
      mesh->GetFieldData()->AddArray(names);
    }
  }
}

void addElementRadiosity(
  const Solution& solution, std::size_t frame, bool twoSided, vtkCellData* cellData)
{
  const std::size_t n = solution.elementCount();
  auto total = rgbArray("Radiosity", n);
  auto direct = rgbArray("DirectRadiosity", n);
  auto indirect = rgbArray("IndirectRadiosity", n);
  auto emitted = rgbArray("EmittedRadiosity", n);
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
    setRgb(emitted, e, solution.emitted(e, lit));
    if (twoSided)
    {
      setRgb(front, e, solution.total(frame, e, Side::Front));
      setRgb(back, e, solution.total(frame, e, Side::Back));
    }
  }
  cellData->AddArray(total);
  cellData->AddArray(direct);
  cellData->AddArray(indirect);
  cellData->AddArray(emitted);
  if (twoSided)
  {
    cellData->AddArray(front);
    cellData->AddArray(back);
  }
}

void addStdErrorArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double luminousEfficacy, bool twoSided, vtkPointData* pointData, vtkCellData* cellData)
{
  if (!solution.hasErrorEstimate())
  {
    return;
  }
  const std::size_t n = solution.elementCount();
  auto add = [&](const std::vector<Rgb>& radiosityValues, const std::vector<Rgb>& irradianceValues,
               vtkDataSetAttributes* data, const std::string& suffix)
  {
    const std::size_t count = radiosityValues.size();
    auto radiosityArray = rgbArray(("RadiosityStdError" + suffix).c_str(), count);
    auto irradianceArray = rgbArray(("IrradianceStdError" + suffix).c_str(), count);
    vtkNew<vtkFloatArray> lux;
    lux->SetName(("IlluminanceStdError" + suffix).c_str());
    lux->SetNumberOfValues(static_cast<vtkIdType>(count));
    for (std::size_t i = 0; i < count; ++i)
    {
      setRgb(radiosityArray, i, radiosityValues[i]);
      setRgb(irradianceArray, i, irradianceValues[i]);
      // The channels' errors come from the same paths, so they move together: the luminance
      // of the channels' errors is the error of the luminance when they are fully correlated,
      // and bounds it otherwise.
      lux->SetValue(static_cast<vtkIdType>(i),
        static_cast<float>(luminousEfficacy * luminance(irradianceValues[i])));
    }
    data->AddArray(radiosityArray);
    data->AddArray(irradianceArray);
    data->AddArray(lux);
  };
  // The side each element shows (or the side `only`, when given).
  std::vector<Rgb> radiosity(n), irradiance(n);
  auto fill = [&](const std::optional<Side>& only)
  {
    for (std::size_t e = 0; e < n; ++e)
    {
      const Side side = only ? *only : solution.litSide(e);
      radiosity[e] = solution.radiosityStdError(frame, e, side);
      irradiance[e] = solution.irradianceStdError(frame, e, side);
    }
  };
  fill(std::nullopt);
  add(radiosity, irradiance, cellData, "");
  add(pointMeans(shading, radiosity), pointMeans(shading, irradiance), pointData, "");
  if (twoSided)
  {
    // Each side's, as RadiosityFront and IrradianceFront have: a side lit in some frames only
    // (a panel's back in the evening) has a value the lit side's error does not cover.
    for (const auto& [side, name] :
      { std::make_pair(Side::Front, "Front"), std::make_pair(Side::Back, "Back") })
    {
      fill(side);
      add(radiosity, irradiance, cellData, name);
    }
  }
}

void addErrorFieldData(vtkFieldData* fieldData, const Solution& solution)
{
  if (solution.errorEstimate.batches == 0)
  {
    return;
  }
  const ErrorEstimateSummary& summary = solution.errorEstimate;
  for (const auto& [name, values] :
    { std::make_pair("RelativeErrorMedian", &summary.relativeErrorMedian),
      std::make_pair("RelativeErrorP95", &summary.relativeErrorP95) })
  {
    vtkNew<vtkDoubleArray> array;
    array->SetName(name);
    for (double v : *values)
    {
      array->InsertNextValue(v);
    }
    fieldData->AddArray(array);
  }
  vtkNew<vtkIdTypeArray> lit;
  lit->SetName("LitElements");
  for (std::uint64_t v : summary.litElements)
  {
    lit->InsertNextValue(static_cast<vtkIdType>(v));
  }
  fieldData->AddArray(lit);
  addValue<vtkIdTypeArray>(fieldData, "ErrorBatches", static_cast<vtkIdType>(summary.batches));
  addValue<vtkIdTypeArray>(fieldData, "ErrorRounds", static_cast<vtkIdType>(summary.rounds));
  addValue<vtkDoubleArray>(fieldData, "TargetRelativeError", summary.target);
  addValue<vtkStringArray>(fieldData, "StoppedBy", summary.stoppedBy);
}

std::vector<Side> patchLitSides(const Solution& solution)
{
  std::vector<Side> sides(solution.patchCount(), Side::Front);
  for (std::size_t p = 0; p < solution.patchCount(); ++p)
  {
    sides[p] = solution.patchLitSide(p);
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
  auto count = [&](const char* name, std::uint64_t value)
  { addValue<vtkIdTypeArray>(fieldData, name, static_cast<vtkIdType>(value)); };
  auto real = [&](const char* name, double value)
  { addValue<vtkDoubleArray>(fieldData, name, value); };
  count("Frames", statistics.frames);
  count("Chunks", statistics.chunks);
  count("FramesPerChunk", statistics.framesPerChunk);
  count("ChunkOverlap", statistics.chunkOverlap);
  if (statistics.chunk >= 0)
  {
    // A streamed chunk's frame: the figures below are that chunk's solve.
    count("Chunk", static_cast<std::uint64_t>(statistics.chunk));
  }
  count("Patches", statistics.patches);
  count("Elements", statistics.elements);
  real("PatchEdgeLength", statistics.patchEdgeLength);
  count("PathsPerFrame", statistics.effectivePathsPerFrame);
  count("PathsCast", statistics.pathsCast);
  count("ShootingRays", statistics.shootingRays);
  count("ShadowRays", statistics.shadowRays);
  count("ShadowRaysBlocked", statistics.shadowRaysBlocked);
  count("GatheringRays", statistics.gatheringRays);
  count("MissedRays", statistics.missedRays);
  count("GatheringSides", statistics.gatheringSides);
  count("PilotRays", statistics.pilotRays);
  count("ReachabilityRays", statistics.reachabilityRays);
  real("SmallestPositionShare", statistics.smallestPositionShare);
  real("LargestPositionShare", statistics.largestPositionShare);
  count("Threads", static_cast<std::uint64_t>(statistics.threads));
  count("MemoryEstimateBytes", statistics.memoryEstimateBytes);
  // The cost that limits users: bytes per element and frame (MemoryPlan).
  real("MemoryEstimateBytesPerElementFrame",
    static_cast<double>(statistics.memoryEstimateBytes) /
      std::max(
        1.0, static_cast<double>(statistics.elements) * static_cast<double>(statistics.frames)));
  if (statistics.memoryCheckedBytes > 0)
  {
    count("MemoryCheckedBytes", statistics.memoryCheckedBytes);
  }
  count("AccumulatorCopyPerWorker", statistics.accumulatorCopyPerWorker ? 1 : 0);
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
  // The solver has no length unit of its own: power is in watts, and radiosity (power per
  // area) per square unit of the scene's coordinates: W/m^2 for a scene in metres, W/mm^2 for
  // one in millimetres.
  addValue<vtkStringArray>(fieldData, "PowerUnits", std::string("W"));
  addValue<vtkStringArray>(fieldData, "RadiosityUnits", std::string("W/(scene unit)^2"));
  // Irradiance is per area as radiosity is; illuminance in lumens per square unit: lx for a
  // scene in metres.
  addValue<vtkStringArray>(fieldData, "IrradianceUnits", std::string("W/(scene unit)^2"));
  addValue<vtkStringArray>(fieldData, "IlluminanceUnits", std::string("lm/(scene unit)^2"));
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

vtkSmartPointer<vtkPolyData> posedLight(
  const std::vector<std::vector<Vec3>>& polygons, const LightTransform& transform, const Rgb& power)
{
  const auto& r = transform.rotation;
  auto pose = [&](const Vec3& x)
  {
    return Vec3(r[0][0] * x.x + r[0][1] * x.y + r[0][2] * x.z,
             r[1][0] * x.x + r[1][1] * x.y + r[1][2] * x.z,
             r[2][0] * x.x + r[2][1] * x.y + r[2][2] * x.z) +
      transform.translation;
  };
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> cells;
  std::vector<double> areas;
  for (const std::vector<Vec3>& polygon : polygons)
  {
    // Area of a planar polygon: half the length of its Newell normal.
    Vec3 newell;
    cells->InsertNextCell(static_cast<vtkIdType>(polygon.size()));
    for (std::size_t i = 0; i < polygon.size(); ++i)
    {
      newell += cross(polygon[i], polygon[(i + 1) % polygon.size()]);
      const Vec3 p = pose(polygon[i]);
      cells->InsertCellPoint(points->InsertNextPoint(p.x, p.y, p.z));
    }
    areas.push_back(0.5 * length(newell));
  }
  const double totalArea = std::accumulate(areas.begin(), areas.end(), 0.0);
  // Doubles: the command line's --stats reports the power solved from this array.
  auto powerArray = rgbArray<vtkDoubleArray>("Power", polygons.size());
  for (std::size_t i = 0; i < polygons.size(); ++i)
  {
    const Rgb share = totalArea > 0 ? power * (areas[i] / totalArea) : Rgb();
    powerArray->SetTuple3(static_cast<vtkIdType>(i), share.r, share.g, share.b);
  }
  auto light = vtkSmartPointer<vtkPolyData>::New();
  light->SetPoints(points);
  light->SetPolys(cells);
  light->GetCellData()->AddArray(powerArray);
  return light;
}

vtkSmartPointer<vtkPolyData> posedPointLight(const Vec3& position, const Rgb& power)
{
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->InsertNextPoint(position.x, position.y, position.z);
  vtkNew<vtkCellArray> vertices;
  vertices->InsertNextCell(1);
  vertices->InsertCellPoint(0);
  auto powerArray = rgbArray<vtkDoubleArray>("Power", 1);
  powerArray->SetTuple3(0, power.r, power.g, power.b);
  auto light = vtkSmartPointer<vtkPolyData>::New();
  light->SetPoints(points);
  light->SetVerts(vertices);
  light->GetCellData()->AddArray(powerArray);
  return light;
}

void addLuminousFlux(vtkPolyData* light, double efficacy)
{
  vtkDataArray* power = light->GetCellData()->GetArray("Power");
  if (!power || power->GetNumberOfComponents() != 3)
  {
    return;
  }
  vtkNew<vtkDoubleArray> flux;
  flux->SetName("LuminousFlux");
  flux->SetNumberOfTuples(power->GetNumberOfTuples());
  for (vtkIdType c = 0; c < power->GetNumberOfTuples(); ++c)
  {
    const double* p = power->GetTuple3(c);
    flux->SetValue(c, efficacy * luminance(Rgb(p[0], p[1], p[2])));
  }
  light->GetCellData()->AddArray(flux);
}

} // namespace mlr::vtkoutputs
