#include "Sensors.h"

#include "InputFiles.h"
#include "Messages.h"

#include "vtkCellArray.h"
#include "vtkFloatArray.h"
#include "vtkGenericCell.h"
#include "vtkIdList.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkStaticCellLocator.h"
#include "vtkXMLPolyDataWriter.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>
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
V operator+(const V& a, const V& b)
{
  return { a.x + b.x, a.y + b.y, a.z + b.z };
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

/// A polygon of the scene across up, seen along up: its corners (u along t, v along b).
struct Face
{
  std::vector<double> us, vs;
  V origin, normal;
  double level = 0; ///< the mean height of its corners along up
  double area = 0;
  vtkIdType cell = -1; ///< in the scene
};

/// UsageError when a lattice of `spacing` over `area` would have more sensors than a solve
/// accepts.
void checkSensorCount(double area, double spacing)
{
  if (area / (spacing * spacing) > MaximumSensors)
  {
    std::ostringstream s;
    s << "--work-plane spacing " << spacing << " gives about " << area / (spacing * spacing)
      << " sensors over " << area << " square units of floor, over the maximum of 1e8: give a "
      << "larger spacing";
    throw UsageError(s.str());
  }
}

/**
 * What rays through the scene say of a horizontal polygon's upper side: whether it sees one of
 * the lights (at most 16 of their positions, spread over the frames), and whether it is a roof
 * in the dark (nothing above it and no light in sight).
 */
/// Faces sorted by level, grouped where consecutive levels are within `tolerance`: one floor
/// each.
std::vector<std::vector<Face>> levelsOf(const std::vector<Face>& sorted, double tolerance)
{
  std::vector<std::vector<Face>> levels;
  for (std::size_t i = 0; i < sorted.size(); ++i)
  {
    if (i == 0 || sorted[i].level - sorted[i - 1].level > tolerance)
    {
      levels.emplace_back();
    }
    levels.back().push_back(sorted[i]);
  }
  return levels;
}

class FloorFinder
{
public:
  FloorFinder(vtkPolyData* scene, const std::vector<Triple>& lights, const V& up)
    : Up(up)
  {
    double bounds[6];
    scene->GetBounds(bounds);
    this->Size = std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
      (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) +
      (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
    this->Offset = 1e-6 * this->Size;
    const std::size_t count = std::min<std::size_t>(lights.size(), 16);
    for (std::size_t k = 0; k < count; ++k)
    {
      const Triple& l = lights[k * lights.size() / count];
      this->Lights.push_back({ l[0], l[1], l[2] });
    }
    this->Locator->SetDataSet(scene);
    this->Locator->BuildLocator();
  }

  /// Heights of polygons closer than this are one level.
  double levelTolerance() const { return 1e-4 * this->Size; }

  /// Whether the first polygon below `point` sees a light from above: then something lit
  /// lies under a polygon facing down at `point` (a shelf over the floor), which is no floor.
  bool litBelow(const V& point) const
  {
    const V from = point - scaled(this->Up, this->Offset);
    const V to = from - scaled(this->Up, 2 * this->Size + 1);
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    double t = 0, x[3], pcoords[3];
    int subId = 0;
    vtkIdType cell = -1;
    return this->Locator->IntersectWithLine(a, z, 0.0, t, x, pcoords, subId, cell) != 0 &&
      this->seesALight({ x[0], x[1], x[2] });
  }

  /// Whether one of `cells` lies straight below `point`.
  bool standsOver(const V& point, const std::set<vtkIdType>& cells) const
  {
    const V from = point - scaled(this->Up, this->Offset);
    const V to = from - scaled(this->Up, 2 * this->Size + 1);
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    vtkNew<vtkIdList> hits;
    vtkNew<vtkGenericCell> cell;
    this->Locator->IntersectWithLine(a, z, 0.0, nullptr, hits, cell);
    for (vtkIdType i = 0; i < hits->GetNumberOfIds(); ++i)
    {
      if (cells.count(hits->GetId(i)))
      {
        return true;
      }
    }
    return false;
  }

  /// Whether a light above `point`'s level is in sight from just above it.
  bool seesALight(const V& point) const
  {
    const V from = this->above(point);
    for (const V& light : this->Lights)
    {
      const V towards = light - from;
      const double distance = std::sqrt(dot(towards, towards));
      if (dot(towards, this->Up) > 0 && distance > 2 * this->Offset &&
        !this->blocked(from, from + scaled(towards, 1 - 2 * this->Offset / distance)))
      {
        return true;
      }
    }
    return false;
  }

  /// Nothing above `point`, and no light in sight from it.
  bool isDarkRoof(const V& point) const
  {
    const V from = this->above(point);
    return !this->blocked(from, from + scaled(this->Up, 2 * this->Size + 1)) &&
      !this->seesALight(point);
  }

private:
  V above(const V& point) const { return point + scaled(this->Up, this->Offset); }

  bool blocked(const V& from, const V& to) const
  {
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    double t = 0, x[3], pcoords[3];
    int subId = 0;
    vtkIdType cell = -1;
    return this->Locator->IntersectWithLine(a, z, 0.0, t, x, pcoords, subId, cell) != 0;
  }

  V Up;
  double Size = 0, Offset = 0;
  std::vector<V> Lights;
  vtkNew<vtkStaticCellLocator> Locator;
};

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

vtkSmartPointer<vtkPolyData> workPlaneSensors(vtkPolyData* scene, const Triple& upGiven,
  double height, double spacing, const std::vector<Triple>& lights)
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

  std::vector<Face> faces, facingDown;
  double area = 0;
  bool anyFacingDown = false;
  vtkCellArray* polys = scene->GetPolys();
  vtkNew<vtkIdList> ids;
  // Polygons come after the vertices and lines in a polydata's cell ids.
  vtkIdType cell = scene->GetNumberOfVerts() + scene->GetNumberOfLines() - 1;
  for (polys->InitTraversal(); polys->GetNextCell(ids);)
  {
    ++cell;
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
    const bool facesUp = twiceArea > 0 && dot(newell, up) >= minimumCosine * twiceArea;
    const bool facesDown = twiceArea > 0 && -dot(newell, up) >= minimumCosine * twiceArea;
    anyFacingDown = anyFacingDown || facesDown;
    if (!facesUp && !(facesDown && !lights.empty()))
    {
      continue;
    }
    Face face;
    face.cell = cell;
    face.origin = corners[0];
    face.normal = scaled(newell, 1 / twiceArea);
    for (const V& c : corners)
    {
      face.us.push_back(dot(c, t));
      face.vs.push_back(dot(c, b));
      face.level += dot(c, up) / static_cast<double>(corners.size());
    }
    face.area = 0.5 * twiceArea;
    area += facesUp ? face.area : 0;
    (facesUp ? faces : facingDown).push_back(std::move(face));
  }
  const auto noFloor = [&]
  {
    std::ostringstream s;
    s << "--work-plane: the scene has no polygon facing up (within " << WorkPlaneToleranceDegrees
      << " degrees of --up " << upGiven[0] << "," << upGiven[1] << "," << upGiven[2] << ")"
      << (facingDown.empty() ? "" : ", nor one facing down that sees a light from above")
      << ": give a scene with floors whose normals point up, or --sensors";
    return InputError(s.str());
  };
  if (faces.empty() && facingDown.empty())
  {
    throw noFloor();
  }
  checkSensorCount(area, spacing);

  struct Sensor
  {
    double u, v, w; ///< along t, b and up: on the face below it
    V point;        ///< (u, v, w)
    bool keep;
  };
  // `once`: a lattice point inside several of the faces (lying on one another) only once.
  auto lattice = [&](const std::vector<Face>& of, double step, bool once = false)
  {
    std::vector<Sensor> sensors;
    std::set<std::pair<long long, long long>> seen;
    for (const Face& face : of)
    {
      const auto [uLo, uHi] = std::minmax_element(face.us.begin(), face.us.end());
      const auto [vLo, vHi] = std::minmax_element(face.vs.begin(), face.vs.end());
      const double c = dot(face.normal, face.origin);
      const double nu = dot(face.normal, t), nv = dot(face.normal, b), nz = dot(face.normal, up);
      for (long long i = static_cast<long long>(std::ceil(*uLo / step - 0.5));
           (i + 0.5) * step <= *uHi; ++i)
      {
        const double u = (static_cast<double>(i) + 0.5) * step;
        for (long long j = static_cast<long long>(std::ceil(*vLo / step - 0.5));
             (j + 0.5) * step <= *vHi; ++j)
        {
          const double v = (static_cast<double>(j) + 0.5) * step;
          if (!inside(face.us, face.vs, u, v) || (once && !seen.insert({ i, j }).second))
          {
            continue;
          }
          // On the face's plane above (u, v).
          const double w = (c - u * nu - v * nv) / nz;
          const V p{ t.x * u + b.x * v + up.x * w, t.y * u + b.y * v + up.y * w,
            t.z * u + b.z * v + up.z * w };
          sensors.push_back({ u, v, w, p, true });
        }
      }
    }
    return sensors;
  };
  std::vector<Sensor> sensors = lattice(faces, spacing);

  if (!facingDown.empty())
  {
    // A floor whose normal points down (a room modelled with outward normals) is found by
    // the lights it sees: its upper side, where the sensors go, sees a light; a correctly
    // oriented room's ceilings and undersides see none from above.
    const FloorFinder finder(scene, lights, up);
    // Faces at one height are one floor: a part in shadow goes with the parts that see the
    // light.
    std::sort(facingDown.begin(), facingDown.end(),
      [](const Face& f, const Face& g) { return f.level < g.level; });
    std::vector<Face> floors;
    for (const std::vector<Face>& level : levelsOf(facingDown, finder.levelTolerance()))
    {
      double levelArea = 0;
      for (const Face& face : level)
      {
        levelArea += face.area;
      }
      // At most about 64 probes a level, and at least its lattice's points.
      const double probeStep = std::max(spacing, std::sqrt(levelArea / 64));
      const std::vector<Sensor> probes = lattice(level, probeStep);
      if (std::any_of(probes.begin(), probes.end(),
            [&](const Sensor& probe)
            { return finder.seesALight(probe.point) && !finder.litBelow(probe.point); }))
      {
        floors.insert(floors.end(), level.begin(), level.end());
      }
    }
    if (!floors.empty())
    {
      double floorArea = 0;
      for (const Face& face : floors)
      {
        floorArea += face.area;
      }
      checkSensorCount(area + floorArea, spacing);
      // Such a room's roof faces up: above it nothing, below it its floor, and no light
      // reaches it.
      std::set<vtkIdType> floorCells;
      for (const Face& face : floors)
      {
        floorCells.insert(face.cell);
      }
      for (Sensor& sensor : sensors)
      {
        sensor.keep =
          !(finder.isDarkRoof(sensor.point) && finder.standsOver(sensor.point, floorCells));
      }
      std::vector<Sensor> more;
      for (const std::vector<Face>& level : levelsOf(floors, finder.levelTolerance()))
      {
        // An object's underside on the floor adds nothing to the floor's lattice.
        const std::vector<Sensor> onLevel = lattice(level, spacing, true);
        more.insert(more.end(), onLevel.begin(), onLevel.end());
      }
      sensors.insert(sensors.end(), more.begin(), more.end());
    }
    else if (faces.empty())
    {
      throw noFloor();
    }
  }

  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  vtkNew<vtkCellArray> vertices;
  vtkNew<vtkFloatArray> normals;
  normals->SetName("Normals");
  normals->SetNumberOfComponents(3);
  double top = -std::numeric_limits<double>::infinity();
  for (vtkIdType i = 0; i < scene->GetNumberOfPoints(); ++i)
  {
    double p[3];
    scene->GetPoint(i, p);
    top = std::max(top, dot({ p[0], p[1], p[2] }, up));
  }
  std::size_t above = 0;
  for (const Sensor& sensor : sensors)
  {
    if (!sensor.keep)
    {
      continue;
    }
    const double u = sensor.u, v = sensor.v;
    const double w = sensor.w + height;
    const V p{ t.x * u + b.x * v + up.x * w, t.y * u + b.y * v + up.y * w,
      t.z * u + b.z * v + up.z * w };
    const vtkIdType id = points->InsertNextPoint(p.x, p.y, p.z);
    vertices->InsertNextCell(1, &id);
    normals->InsertNextTuple3(up.x, up.y, up.z);
    above += w > top ? 1 : 0;
  }
  // Above a flat ground every sensor lies above the scene; over a closed room whose floor
  // faces down, its roof's do.
  if (anyFacingDown && points->GetNumberOfPoints() > 0 &&
    above == static_cast<std::size_t>(points->GetNumberOfPoints()))
  {
    std::ostringstream s;
    s << "--work-plane: every sensor lies above the scene, " << height
      << " above its polygons facing up (roofs?), while polygons facing down may be its floors: "
      << (lights.empty() ? "under the sun or a sky the floors are the polygons facing up: turn "
                           "the floors' normals up, or give --sensors"
                         : "none of them sees a light from above: give --sensors");
    printWarning(s.str());
  }
  auto result = vtkSmartPointer<vtkPolyData>::New();
  result->SetPoints(points);
  result->SetVerts(vertices);
  result->GetPointData()->AddArray(normals);
  return result;
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
