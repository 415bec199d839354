#include "MovingLightRadiosityDisplay.h"

#include "DisjointSets.h"
#include "SurfaceRegions.h"

#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <tuple>
#include <utility>

namespace mlr::vtkoutputs
{

double acesFilmic(double x)
{
  if (!(x > 0))
  {
    return 0; // also NaN
  }
  const double mapped = x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14);
  return std::min(mapped, 1.0);
}

unsigned char srgbByte(double linear)
{
  const double c = std::clamp(std::isnan(linear) ? 0.0 : linear, 0.0, 1.0);
  const double encoded = c <= 0.0031308 ? 12.92 * c : 1.055 * std::pow(c, 1.0 / 2.4) - 0.055;
  return static_cast<unsigned char>(std::lround(255.0 * encoded));
}

std::array<unsigned char, 3> displayColor(const Rgb& radiosity, double exposureScale)
{
  return { srgbByte(acesFilmic(exposureScale * radiosity.r)),
    srgbByte(acesFilmic(exposureScale * radiosity.g)),
    srgbByte(acesFilmic(exposureScale * radiosity.b)) };
}

namespace
{
// A histogram of log2 luminance rather than a sort: frames x elements values may not fit in
// memory twice, and 1/64 EV is far below what the eye can tell.
constexpr int StepsPerEV = 64;
constexpr int LowestEV = -100, HighestEV = 100;
constexpr std::size_t ExposureBins = static_cast<std::size_t>((HighestEV - LowestEV) * StepsPerEV);
}

std::vector<std::uint64_t> exposureHistogram(const Solution& solution)
{
  std::vector<std::uint64_t> histogram(ExposureBins + 2, 0);
  std::uint64_t& unlit = histogram[ExposureBins];
  std::uint64_t& total = histogram[ExposureBins + 1];
  for (std::size_t e = 0; e < solution.elementCount(); ++e)
  {
    const Side lit = solution.litSide(e);
    for (std::size_t f = 0; f < solution.frameCount(); ++f)
    {
      const double l = luminance(solution.total(f, e, lit));
      ++total;
      if (!(l > 0) || !std::isfinite(l))
      {
        ++unlit;
        continue;
      }
      const double bin = std::floor((std::log2(l) - LowestEV) * StepsPerEV);
      const auto index =
        static_cast<std::size_t>(std::clamp(bin, 0.0, static_cast<double>(ExposureBins - 1)));
      ++histogram[index];
    }
  }
  return histogram;
}

double exposureOf(const std::vector<std::uint64_t>& histogram)
{
  const std::uint64_t unlit = histogram[ExposureBins], total = histogram[ExposureBins + 1];
  if (total == unlit)
  {
    return 0;
  }
  // The 99th percentile of all values, dark ones included; when more than 99% are dark, the
  // brightest lit value instead, so that a small lit spot still gets a usable exposure.
  const auto rank = static_cast<std::uint64_t>(std::ceil(0.99 * static_cast<double>(total)));
  std::uint64_t seen = unlit;
  std::size_t index = 0;
  for (std::size_t i = 0; i < ExposureBins; ++i)
  {
    if (histogram[i] == 0)
    {
      continue;
    }
    index = i;
    seen += histogram[i];
    if (seen >= rank)
    {
      break;
    }
  }
  const double log2Level = LowestEV + (static_cast<double>(index) + 0.5) / StepsPerEV;
  return std::log2(AutoExposureTarget) - log2Level;
}

double autoExposure(const Solution& solution)
{
  return exposureOf(exposureHistogram(solution));
}

SmoothShading smoothShading(const Scene& scene, const Solution& solution)
{
  const std::vector<Triangle>& triangles = scene.elementTriangles();
  const std::size_t corners = 3 * triangles.size();

  // Union-find over element corners: two corners at the same scene point join when their
  // elements share an edge through that point and meet smoothly there.
  DisjointSets corner(corners);

  std::vector<Vec3> litNormals(triangles.size());
  for (std::size_t e = 0; e < triangles.size(); ++e)
  {
    litNormals[e] = scene.elementSideNormal(e, solution.litSide(e));
  }
  const double cosFeature = std::cos(FeatureAngle * M_PI / 180.0);
  auto smooth = [&](std::size_t a, std::size_t b)
  {
    return scene.elementReflectance(a) == scene.elementReflectance(b) &&
      dot(litNormals[a], litNormals[b]) >= cosFeature;
  };

  // The corners of an element at the lower and the higher point of its edge.
  const auto lowAndHigh = [&triangles](const EdgeUse& u)
  {
    std::size_t low = 3 * u.triangle + u.corner, high = 3 * u.triangle + (u.corner + 1) % 3;
    if (triangles[u.triangle][u.corner] > triangles[u.triangle][(u.corner + 1) % 3])
    {
      std::swap(low, high);
    }
    return std::make_pair(low, high);
  };
  // Usually 2 uses of an edge; more only at non-manifold edges, where every smooth pair joins.
  forEachSharedEdge(triangles,
    [&](const EdgeUse& u, const EdgeUse& v)
    {
      if (smooth(u.triangle, v.triangle))
      {
        const auto [uLow, uHigh] = lowAndHigh(u);
        const auto [vLow, vHigh] = lowAndHigh(v);
        corner.join(uLow, vLow);
        corner.join(uHigh, vHigh);
      }
    });

  SmoothShading shading;
  shading.elementAreas.resize(triangles.size());
  for (std::size_t e = 0; e < triangles.size(); ++e)
  {
    shading.elementAreas[e] = scene.elementArea(e);
  }
  shading.cornerPoints.assign(corners, -1);
  std::vector<double> area;
  for (std::size_t c = 0; c < corners; ++c)
  {
    const std::size_t root = corner.find(c);
    if (shading.cornerPoints[root] < 0)
    {
      shading.cornerPoints[root] = static_cast<vtkIdType>(shading.scenePoints.size());
      shading.scenePoints.push_back(triangles[c / 3][c % 3]);
      area.push_back(0.0);
    }
    shading.cornerPoints[c] = shading.cornerPoints[root];
    area[static_cast<std::size_t>(shading.cornerPoints[c])] += scene.elementArea(c / 3);
  }
  shading.inverseArea.resize(area.size());
  for (std::size_t p = 0; p < area.size(); ++p)
  {
    shading.inverseArea[p] = area[p] > 0 ? 1.0 / area[p] : 0.0;
  }
  return shading;
}

vtkSmartPointer<vtkPolyData> smoothElementMesh(const Scene& scene, const SmoothShading& shading)
{
  const std::size_t pointCount = shading.scenePoints.size();
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(static_cast<vtkIdType>(pointCount));
  vtkNew<vtkIdTypeArray> scenePointIds;
  scenePointIds->SetName("ScenePointId");
  scenePointIds->SetNumberOfTuples(static_cast<vtkIdType>(pointCount));
  for (std::size_t i = 0; i < pointCount; ++i)
  {
    const Vec3& p = scene.points()[shading.scenePoints[i]];
    points->SetPoint(static_cast<vtkIdType>(i), p.x, p.y, p.z);
    scenePointIds->SetValue(static_cast<vtkIdType>(i), shading.scenePoints[i]);
  }
  vtkNew<vtkCellArray> cells;
  const std::size_t n = scene.elementCount();
  cells->AllocateExact(static_cast<vtkIdType>(n), static_cast<vtkIdType>(3 * n));
  for (std::size_t e = 0; e < n; ++e)
  {
    cells->InsertNextCell(3, shading.cornerPoints.data() + 3 * e);
  }
  auto mesh = vtkSmartPointer<vtkPolyData>::New();
  mesh->SetPoints(points);
  mesh->SetPolys(cells);
  mesh->GetPointData()->AddArray(scenePointIds);

  auto reflectance = rgbArray("Reflectance", n);
  vtkNew<vtkIntArray> patchId;
  patchId->SetName("PatchId");
  patchId->SetNumberOfTuples(static_cast<vtkIdType>(n));
  for (std::size_t e = 0; e < n; ++e)
  {
    setRgb(reflectance, e, scene.elementReflectance(e));
    patchId->SetValue(static_cast<vtkIdType>(e), static_cast<int>(Scene::patchOfElement(e)));
  }
  mesh->GetCellData()->AddArray(reflectance);
  mesh->GetCellData()->AddArray(patchId);
  return mesh;
}

namespace
{
void setColor(vtkUnsignedCharArray* array, std::size_t i, const Rgb& radiosity, double scale)
{
  const std::array<unsigned char, 3> color = displayColor(radiosity, scale);
  array->SetTypedTuple(static_cast<vtkIdType>(i), color.data());
}
}

std::vector<Rgb> pointMeans(const SmoothShading& shading, const std::vector<Rgb>& elementValues)
{
  std::vector<Rgb> pointSum(shading.scenePoints.size());
  for (std::size_t e = 0; e < elementValues.size(); ++e)
  {
    const Rgb weighted = elementValues[e] * shading.elementAreas[e];
    for (std::size_t k = 0; k < 3; ++k)
    {
      pointSum[static_cast<std::size_t>(shading.cornerPoints[3 * e + k])] += weighted;
    }
  }
  for (std::size_t p = 0; p < pointSum.size(); ++p)
  {
    pointSum[p] = pointSum[p] * shading.inverseArea[p];
  }
  return pointSum;
}

void addDisplayArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double exposureScale, vtkPointData* pointData, vtkCellData* cellData)
{
  const std::size_t n = solution.elementCount();
  const std::size_t pointCount = shading.scenePoints.size();
  auto cellColor = rgbArray<vtkUnsignedCharArray>("Color", n);
  std::vector<Rgb> radiosity(n);
  for (std::size_t e = 0; e < n; ++e)
  {
    radiosity[e] = solution.total(frame, e, solution.litSide(e));
    setColor(cellColor, e, radiosity[e], exposureScale);
  }
  const std::vector<Rgb> pointRadiosity = pointMeans(shading, radiosity);
  auto pointRadiosityArray = rgbArray("Radiosity", pointCount);
  auto pointColor = rgbArray<vtkUnsignedCharArray>("Color", pointCount);
  for (std::size_t p = 0; p < pointCount; ++p)
  {
    setRgb(pointRadiosityArray, p, pointRadiosity[p]);
    setColor(pointColor, p, pointRadiosity[p], exposureScale);
  }
  cellData->AddArray(cellColor);
  cellData->SetActiveScalars("Color");
  pointData->AddArray(pointRadiosityArray);
  pointData->AddArray(pointColor);
  pointData->SetActiveScalars("Color");
}

void addIrradianceArrays(const Solution& solution, const SmoothShading& shading, std::size_t frame,
  double luminousEfficacy, bool twoSided, vtkPointData* pointData, vtkCellData* cellData)
{
  const std::size_t n = solution.elementCount();
  // Irradiance and Illuminance of `values` into `data`, under the names given.
  auto add = [&](const std::vector<Rgb>& values, vtkDataSetAttributes* data, const char* rgbName,
               const char* luxName)
  {
    auto rgb = rgbArray(rgbName, values.size());
    vtkNew<vtkFloatArray> lux;
    lux->SetName(luxName);
    lux->SetNumberOfValues(static_cast<vtkIdType>(values.size()));
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      // From the array's single-precision values, so that the two arrays agree exactly.
      setRgb(rgb, i, values[i]);
      float stored[3];
      rgb->GetTypedTuple(static_cast<vtkIdType>(i), stored);
      lux->SetValue(static_cast<vtkIdType>(i),
        static_cast<float>(luminousEfficacy * luminance(Rgb(stored[0], stored[1], stored[2]))));
    }
    data->AddArray(rgb);
    data->AddArray(lux);
  };
  std::vector<Rgb> irradiance(n);
  for (std::size_t e = 0; e < n; ++e)
  {
    irradiance[e] = solution.irradiance(frame, e, solution.litSide(e));
  }
  add(irradiance, cellData, "Irradiance", "Illuminance");
  add(pointMeans(shading, irradiance), pointData, "Irradiance", "Illuminance");
  if (twoSided)
  {
    for (const auto& [side, rgbName, luxName] :
      { std::make_tuple(Side::Front, "IrradianceFront", "IlluminanceFront"),
        std::make_tuple(Side::Back, "IrradianceBack", "IlluminanceBack") })
    {
      for (std::size_t e = 0; e < n; ++e)
      {
        irradiance[e] = solution.irradiance(frame, e, side);
      }
      add(irradiance, cellData, rgbName, luxName);
    }
  }
}

void addExposureFieldData(vtkFieldData* fieldData, double autoExposure, double exposure)
{
  addValue<vtkDoubleArray>(fieldData, "AutoExposure", autoExposure);
  addValue<vtkDoubleArray>(fieldData, "Exposure", exposure);
  addValue<vtkDoubleArray>(fieldData, "ExposureScale", std::exp2(autoExposure + exposure));
}

} // namespace mlr::vtkoutputs
