#include "Sensors.h"

#include "InputFiles.h"

#include "vtkCellArray.h"
#include "vtkFloatArray.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkXMLPolyDataWriter.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>
#include <vector>

namespace mlr::cli
{

namespace
{
/// The most sensors a solve accepts (Core's MaximumSensors).
constexpr double MaximumSensors = 1e8;

struct V
{
  double x, y, z;
};
V operator-(const V& a, const V& b)
{
  return { a.x - b.x, a.y - b.y, a.z - b.z };
}
double dot(const V& a, const V& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}
V cross(const V& a, const V& b)
{
  return { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}
V scaled(const V& a, double s)
{
  return { a.x * s, a.y * s, a.z * s };
}
V unit(const V& a)
{
  return scaled(a, 1 / std::sqrt(dot(a, a)));
}

/// Even-odd test of (u, v) against the polygon (us, vs).
bool inside(const std::vector<double>& us, const std::vector<double>& vs, double u, double v)
{
  bool in = false;
  for (std::size_t i = 0, j = us.size() - 1; i < us.size(); j = i++)
  {
    if ((vs[i] > v) != (vs[j] > v) && u < (us[j] - us[i]) * (v - vs[i]) / (vs[j] - vs[i]) + us[i])
    {
      in = !in;
    }
  }
  return in;
}
}

vtkSmartPointer<vtkPolyData> workPlaneSensors(
  vtkPolyData* scene, const Triple& upGiven, double height, double spacing)
{
  const V up = unit({ upGiven[0], upGiven[1], upGiven[2] });
  // The lattice's axes: the world axis least along up, made orthogonal to it, and up x it.
  const double a[3] = { std::abs(up.x), std::abs(up.y), std::abs(up.z) };
  const int axis = a[0] <= a[1] && a[0] <= a[2] ? 0 : (a[1] <= a[2] ? 1 : 2);
  V e{ 0, 0, 0 };
  (axis == 0 ? e.x : axis == 1 ? e.y : e.z) = 1;
  const V t = unit(e - scaled(up, dot(e, up)));
  const V b = cross(up, t);
  const double minimumCosine = std::cos(WorkPlaneToleranceDegrees * M_PI / 180);

  struct Face
  {
    std::vector<double> us, vs;
    V origin, normal;
  };
  std::vector<Face> faces;
  double area = 0;
  vtkCellArray* polys = scene->GetPolys();
  vtkNew<vtkIdList> ids;
  for (polys->InitTraversal(); polys->GetNextCell(ids);)
  {
    const vtkIdType n = ids->GetNumberOfIds();
    if (n < 3)
    {
      continue;
    }
    std::vector<V> corners;
    for (vtkIdType i = 0; i < n; ++i)
    {
      double p[3];
      scene->GetPoint(ids->GetId(i), p);
      corners.push_back({ p[0], p[1], p[2] });
    }
    V newell{ 0, 0, 0 };
    for (std::size_t i = 0; i < corners.size(); ++i)
    {
      const V c = cross(corners[i], corners[(i + 1) % corners.size()]);
      newell = { newell.x + c.x, newell.y + c.y, newell.z + c.z };
    }
    const double twiceArea = std::sqrt(dot(newell, newell));
    if (!(twiceArea > 0) || dot(newell, up) < minimumCosine * twiceArea)
    {
      continue;
    }
    Face face;
    face.origin = corners[0];
    face.normal = scaled(newell, 1 / twiceArea);
    for (const V& c : corners)
    {
      face.us.push_back(dot(c, t));
      face.vs.push_back(dot(c, b));
    }
    area += 0.5 * twiceArea;
    faces.push_back(std::move(face));
  }
  if (faces.empty())
  {
    std::ostringstream s;
    s << "--work-plane: the scene has no polygon facing up (within " << WorkPlaneToleranceDegrees
      << " degrees of --up " << upGiven[0] << "," << upGiven[1] << "," << upGiven[2]
      << "): give a scene with floors whose normals point up, or --sensors";
    throw InputError(s.str());
  }
  if (area / (spacing * spacing) > MaximumSensors)
  {
    std::ostringstream s;
    s << "--work-plane spacing " << spacing << " gives about " << area / (spacing * spacing)
      << " sensors over " << area << " square units of floor, over the maximum of 1e8: give a "
      << "larger spacing";
    throw UsageError(s.str());
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  for (const Face& face : faces)
  {
    const auto [uLo, uHi] = std::minmax_element(face.us.begin(), face.us.end());
    const auto [vLo, vHi] = std::minmax_element(face.vs.begin(), face.vs.end());
    const double c = dot(face.normal, face.origin);
    const double nu = dot(face.normal, t), nv = dot(face.normal, b), nz = dot(face.normal, up);
    for (long long i = static_cast<long long>(std::ceil(*uLo / spacing - 0.5));
         (i + 0.5) * spacing <= *uHi; ++i)
    {
      const double u = (static_cast<double>(i) + 0.5) * spacing;
      for (long long j = static_cast<long long>(std::ceil(*vLo / spacing - 0.5));
           (j + 0.5) * spacing <= *vHi; ++j)
      {
        const double v = (static_cast<double>(j) + 0.5) * spacing;
        if (!inside(face.us, face.vs, u, v))
        {
          continue;
        }
        // On the face's plane above (u, v), then `height` up.
        const double w = (c - u * nu - v * nv) / nz + height;
        const V p{ t.x * u + b.x * v + up.x * w, t.y * u + b.y * v + up.y * w,
          t.z * u + b.z * v + up.z * w };
        const vtkIdType id = points->InsertNextPoint(p.x, p.y, p.z);
        vertices->InsertNextCell(1, &id);
        normals->InsertNextTuple3(up.x, up.y, up.z);
      }
    }
  }
  auto sensors = vtkSmartPointer<vtkPolyData>::New();
  sensors->SetPoints(points);
  sensors->SetVerts(vertices);
  sensors->GetPointData()->AddArray(normals);
  return sensors;
}

void writeSensorFrame(vtkPolyData* sensors, const std::filesystem::path& path)
{
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(sensors);
  writer->SetFileName(path.c_str());
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToLZ4();
  if (!writer->Write())
  {
    throw std::runtime_error("could not write the sensors to " + path.string());
  }
}

} // namespace mlr::cli
