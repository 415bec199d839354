#include "MovingLightRadiosityInputs.h"

#include "Error.h"
#include "Solver.h"

#include "vtkCellArray.h"
#include "vtkCellArrayIterator.h"
#include "vtkCellData.h"
#include "vtkDataArray.h"
#include "vtkPointData.h"
#include "vtkPointSet.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <sstream>

namespace mlr::vtkinputs
{

namespace
{
/// Calls visit(cellId, pointIds) for every polygon of `data`, then for every triangle of its
/// strips, with the cell ids vtkPolyData gives them (vertices, lines, polygons, strips).
void forEachSurfaceCell(vtkPolyData* data,
  const std::function<void(vtkIdType, const std::vector<std::uint32_t>&)>& visit)
{
  vtkIdType cellId = data->GetNumberOfVerts() + data->GetNumberOfLines();
  std::vector<std::uint32_t> ids;
  vtkIdType count = 0;
  const vtkIdType* points = nullptr;

  auto polys = vtkSmartPointer<vtkCellArrayIterator>::Take(data->GetPolys()->NewIterator());
  for (polys->GoToFirstCell(); !polys->IsDoneWithTraversal(); polys->GoToNextCell(), ++cellId)
  {
    polys->GetCurrentCell(count, points);
    ids.assign(points, points + count);
    visit(cellId, ids);
  }

  auto strips = vtkSmartPointer<vtkCellArrayIterator>::Take(data->GetStrips()->NewIterator());
  for (strips->GoToFirstCell(); !strips->IsDoneWithTraversal(); strips->GoToNextCell(), ++cellId)
  {
    strips->GetCurrentCell(count, points);
    for (vtkIdType j = 0; j + 2 < count; ++j)
    {
      // Every other triangle of a strip runs backwards: swap its first two points so that
      // all of them face the strip's way.
      const vtkIdType a = points[j + (j % 2)], b = points[j + 1 - (j % 2)], c = points[j + 2];
      if (a == b || b == c || a == c)
      {
        continue; // the degenerate triangles that stitch strips together
      }
      ids.assign({ static_cast<std::uint32_t>(a), static_cast<std::uint32_t>(b),
        static_cast<std::uint32_t>(c) });
      visit(cellId, ids);
    }
  }
}

std::vector<Vec3> pointsOf(vtkPointSet* data)
{
  std::vector<Vec3> result;
  vtkPoints* points = data->GetPoints();
  const vtkIdType n = points ? points->GetNumberOfPoints() : 0;
  result.resize(static_cast<std::size_t>(n));
  double p[3];
  for (vtkIdType i = 0; i < n; ++i)
  {
    points->GetPoint(i, p);
    result[static_cast<std::size_t>(i)] = { p[0], p[1], p[2] };
  }
  return result;
}

/// The Scene's cell array Reflectance (numeric, 1 or 3 components), or nullptr when absent.
vtkDataArray* reflectanceArray(vtkPolyData* scene)
{
  vtkAbstractArray* array = scene->GetCellData()->GetAbstractArray("Reflectance");
  if (!array)
  {
    return nullptr;
  }
  auto* numbers = vtkDataArray::SafeDownCast(array);
  if (!numbers)
  {
    throw Error(std::string("the Scene's cell array Reflectance is a ") + array->GetClassName() +
      ": give a numeric array (float or double) with values in [0, 1)");
  }
  const int components = numbers->GetNumberOfComponents();
  if (components != 1 && components != 3)
  {
    throw Error("the Scene's cell array Reflectance has " + std::to_string(components) +
      " components: give 3 (red, green, blue) or 1 (grey)");
  }
  if (numbers->GetNumberOfTuples() < scene->GetNumberOfCells())
  {
    throw Error("the Scene's cell array Reflectance has " +
      std::to_string(numbers->GetNumberOfTuples()) + " values for " +
      std::to_string(scene->GetNumberOfCells()) + " cells: give one per cell");
  }
  return numbers;
}

Rgb reflectanceOfCell(vtkDataArray* array, vtkIdType cellId)
{
  Rgb rho;
  if (array->GetNumberOfComponents() == 1)
  {
    rho = Rgb(array->GetComponent(cellId, 0));
  }
  else
  {
    rho = Rgb(array->GetComponent(cellId, 0), array->GetComponent(cellId, 1),
      array->GetComponent(cellId, 2));
  }
  for (int c = 0; c < 3; ++c)
  {
    if (!(rho[c] >= 0.0 && rho[c] < 1.0))
    {
      std::ostringstream s;
      s << "Scene cell " << cellId << " has Reflectance (" << rho.r << ", " << rho.g << ", "
        << rho.b << "): every value must be >= 0 and < 1";
      throw Error(s.str());
    }
  }
  return rho;
}
}

PolygonSoup sceneSoup(vtkPolyData* scene, std::vector<std::string>& warnings,
  std::uint64_t memoryLimitBytes)
{
  PolygonSoup soup;
  if (!scene || scene->GetNumberOfCells() == 0)
  {
    return soup;
  }
  {
    // Per point 24 bytes; per polygon its index vector (~56 bytes with the allocator's
    // overhead) and material (24), and 4 bytes per index. Strips become one polygon per
    // triangle.
    const double cells = static_cast<double>(scene->GetNumberOfPolys()) +
      static_cast<double>(scene->GetStrips()->GetNumberOfConnectivityIds());
    const double ids = static_cast<double>(scene->GetPolys()->GetNumberOfConnectivityIds()) +
      3.0 * static_cast<double>(scene->GetStrips()->GetNumberOfConnectivityIds());
    const double estimate = 24.0 * static_cast<double>(scene->GetNumberOfPoints()) + 80.0 * cells + 4.0 * ids;
    const double limit =
      static_cast<double>(memoryLimitBytes > 0 ? memoryLimitBytes : defaultMemoryLimitBytes());
    if (estimate > limit)
    {
      std::ostringstream s;
      s.precision(3);
      s << "the Scene has " << scene->GetNumberOfCells() << " cells on "
        << scene->GetNumberOfPoints() << " points: taking them for remeshing needs an estimated "
        << estimate / (1024.0 * 1024.0 * 1024.0) << " GiB, over the memory limit of "
        << limit / (1024.0 * 1024.0 * 1024.0)
        << " GiB: simplify the scene or raise MemoryLimit";
      throw Error(s.str());
    }
  }
  const vtkIdType ignored = scene->GetNumberOfVerts() + scene->GetNumberOfLines();
  if (ignored > 0)
  {
    warnings.push_back("ignored " + std::to_string(scene->GetNumberOfVerts()) +
      " vertices and " + std::to_string(scene->GetNumberOfLines()) +
      " lines of the Scene: only polygons and triangle strips are surfaces");
  }
  if (scene->GetNumberOfPolys() + scene->GetNumberOfStrips() == 0)
  {
    return soup;
  }

  vtkDataArray* reflectance = reflectanceArray(scene);
  if (!reflectance)
  {
    std::ostringstream s;
    s << "the Scene has no cell array Reflectance: every surface is grey "
      << Material{}.reflectance.g;
    warnings.push_back(s.str());
  }
  soup.points = pointsOf(scene);
  forEachSurfaceCell(scene, [&](vtkIdType cellId, const std::vector<std::uint32_t>& ids) {
    soup.polygons.push_back(ids);
    Material material;
    if (reflectance)
    {
      material.reflectance = reflectanceOfCell(reflectance, cellId);
    }
    soup.materials.push_back(material);
  });
  return soup;
}

std::vector<std::vector<Vec3>> lightPolygons(vtkPolyData* light)
{
  std::vector<std::vector<Vec3>> polygons;
  if (!light)
  {
    return polygons;
  }
  const std::vector<Vec3> points = pointsOf(light);
  forEachSurfaceCell(light, [&](vtkIdType, const std::vector<std::uint32_t>& ids) {
    std::vector<Vec3> polygon;
    polygon.reserve(ids.size());
    for (std::uint32_t id : ids)
    {
      if (id >= points.size())
      {
        throw Error("a Light polygon uses point " + std::to_string(id) + " but the Light has " +
          std::to_string(points.size()) + " points: fix its connectivity");
      }
      polygon.push_back(points[id]);
    }
    polygons.push_back(std::move(polygon));
  });
  return polygons;
}

Trajectory trajectoryFromPoints(vtkPointSet* trajectory)
{
  Trajectory result;
  if (trajectory)
  {
    result.positions = pointsOf(trajectory);
  }
  const std::size_t n = result.positions.size();
  if (n == 0)
  {
    throw Error("the Trajectory has no points: give one point per light position, or "
                "disconnect it to move the light from PathStart to PathEnd");
  }

  vtkAbstractArray* array = trajectory->GetPointData()->GetAbstractArray("Time");
  if (!array)
  {
    result.times.resize(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      result.times[i] = static_cast<double>(i);
    }
    return result;
  }
  auto* times = vtkDataArray::SafeDownCast(array);
  if (!times || times->GetNumberOfComponents() != 1 ||
    times->GetNumberOfTuples() != static_cast<vtkIdType>(n))
  {
    throw Error("the Trajectory's point array Time must be numeric with one value per point (" +
      std::to_string(n) + "): fix it or remove it to number the frames 0, 1, ...");
  }
  result.times.resize(n);
  for (std::size_t i = 0; i < n; ++i)
  {
    const double t = times->GetComponent(static_cast<vtkIdType>(i), 0);
    if (!std::isfinite(t) || (i > 0 && !(t > result.times[i - 1])))
    {
      std::ostringstream s;
      s << "the Trajectory's point array Time must increase strictly with finite values: "
        << "point " << i << " has time " << t;
      if (i > 0)
      {
        s << " after " << result.times[i - 1];
      }
      throw Error(s.str());
    }
    result.times[i] = t;
  }
  return result;
}

Trajectory straightTrajectory(const Vec3& start, const Vec3& end, int count)
{
  Trajectory result;
  const int n = std::max(count, 1);
  for (int i = 0; i < n; ++i)
  {
    const double s = n > 1 ? static_cast<double>(i) / (n - 1) : 0.0;
    result.positions.push_back(start + (end - start) * s);
    result.times.push_back(static_cast<double>(i));
  }
  return result;
}

std::size_t frameAtOrBelow(const std::vector<double>& times, double time)
{
  if (times.empty())
  {
    return 0;
  }
  // Requests that differ from a step only by rounding (e.g. a time keeper's arithmetic) still
  // land on that step.
  const double tolerance = 1e-9 * std::max(1.0, std::abs(times.back() - times.front()));
  const auto above = std::upper_bound(times.begin(), times.end(), time + tolerance);
  return above == times.begin() ? 0 : static_cast<std::size_t>(above - times.begin()) - 1;
}

} // namespace mlr::vtkinputs
