#include "Sensors.h"

#include "DisjointSets.h"
#include "Error.h"
#include "InputFiles.h"
#include "MemoryBudget.h"
#include "Messages.h"
#include "SeriesWriter.h"

#include "vtkCellArray.h"
#include "vtkFieldData.h"
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
#include <map>
#include <numeric>
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

/// Twice the area times the unit normal (Newell's method) of a polygon's corners.
V areaVector(const std::vector<V>& corners)
{
  V sum{ 0, 0, 0 };
  for (std::size_t i = 0; i < corners.size(); ++i)
  {
    sum = sum + cross(corners[i], corners[(i + 1) % corners.size()]);
  }
  return sum;
}

/// Horizontal rays from a point that tell a room from the outdoors.
constexpr int WallDirections = 16;

/// A polygon of the scene across up, seen along up: its corners (u along t, v along b).
struct Face
{
  std::vector<double> us, vs;
  V origin, normal;
  double level = 0; ///< the mean height of its corners along up
  double area = 0;
  vtkIdType cell = -1; ///< in the scene
};

/// Bounds across up (u along t, v along b).
struct Extent
{
  double uLo, uHi, vLo, vHi;
};

/// The bounds of `faces` across up, widened by `margin` on every side.
Extent extentOf(const std::vector<Face>& faces, double margin)
{
  Extent e{ std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
    std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity() };
  for (const Face& face : faces)
  {
    const auto [uLo, uHi] = std::minmax_element(face.us.begin(), face.us.end());
    const auto [vLo, vHi] = std::minmax_element(face.vs.begin(), face.vs.end());
    e = { std::min(e.uLo, *uLo - margin), std::max(e.uHi, *uHi + margin),
      std::min(e.vLo, *vLo - margin), std::max(e.vHi, *vHi + margin) };
  }
  return e;
}

/// Bytes one work-plane sensor takes before the solve checks its own memory: the lattice
/// (with the set that finds a point in several faces) and the sensors' VTK points, normals
/// and vertices. Measured at 1.21 million sensors: 135 bytes each over the run without them
/// (the solve refusing), rounded up.
constexpr std::uint64_t WorkPlaneBytesPerSensor = 160;

/// UsageError when a lattice of `spacing` over `area` would have more sensors than a solve
/// accepts, or than building them and their results over `frames` frames fits in the memory
/// limit (`memoryLimit` bytes, 0 for the default): checked before anything is built.
void checkSensorCount(double area, double spacing, std::size_t frames, std::uint64_t memoryLimit)
{
  const double count = area / (spacing * spacing);
  std::ostringstream s;
  s << "--work-plane spacing " << mlr::formatNumber(spacing) << " gives about "
    << static_cast<std::uint64_t>(std::ceil(std::min(count, 1e19))) << " sensors over "
    << mlr::formatNumber(area) << " square units of floor";
  if (count > MaximumSensors)
  {
    s << ", over the maximum of 1e8: give a larger spacing";
    throw UsageError(s.str());
  }
  const auto sensors = static_cast<std::uint64_t>(std::ceil(count));
  // With three RGB results in single precision per sensor and frame; the solve then checks
  // what its rays need beside them.
  const std::uint64_t bytes =
    mlr::saturatingSum(mlr::saturatingProduct(sensors, WorkPlaneBytesPerSensor),
      mlr::saturatingProduct({ sensors, std::max<std::uint64_t>(frames, 1), 36 }));
  const mlr::MemoryBudget budget(memoryLimit);
  if (!budget.fits(bytes))
  {
    throw UsageError(budget.overLimitMessage(
      bytes, "the work plane", s.str(), "give a larger spacing, or raise --memory-limit"));
  }
}

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

/// The faces of one level in groups whose extents across up overlap or touch (within
/// `tolerance`), directly or through others: a floor with its parts and what stands on it,
/// apart from the next building's.
std::vector<std::vector<Face>> touchingGroups(const std::vector<Face>& level, double tolerance)
{
  std::vector<Extent> extents;
  for (const Face& face : level)
  {
    extents.push_back(extentOf({ face }, tolerance));
  }
  mlr::DisjointSets touching(level.size());
  // A sweep along u: each face meets the faces whose u extent still reaches it.
  std::vector<std::size_t> order(level.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(),
    [&](std::size_t i, std::size_t j) { return extents[i].uLo < extents[j].uLo; });
  std::vector<std::size_t> reaching;
  for (const std::size_t i : order)
  {
    const Extent& e = extents[i];
    reaching.erase(std::remove_if(reaching.begin(), reaching.end(),
                     [&](std::size_t j) { return extents[j].uHi < e.uLo; }),
      reaching.end());
    for (const std::size_t j : reaching)
    {
      if (extents[j].vLo <= e.vHi && e.vLo <= extents[j].vHi)
      {
        touching.join(i, j);
      }
    }
    reaching.push_back(i);
  }
  std::vector<std::vector<Face>> groups;
  std::vector<std::size_t> groupOfRoot(level.size(), level.size());
  for (std::size_t i = 0; i < level.size(); ++i)
  {
    std::size_t& group = groupOfRoot[touching.find(i)];
    if (group == level.size())
    {
      group = groups.size();
      groups.emplace_back();
    }
    groups[group].push_back(level[i]);
  }
  return groups;
}

/**
 * What rays through the scene say of a horizontal polygon's upper side: whether it sees one of
 * the lights (at most 16 of their positions, spread over the frames) or the sky, what lies
 * straight below and above it, whether the work plane over it is in a room (walled in) or
 * outdoors, and whether it is a roof.
 */
class FloorFinder
{
public:
  /// `t` and `b`: two axes across `up`, for the sky's directions; `height`: the work plane's.
  FloorFinder(vtkPolyData* scene, const std::vector<Triple>& lights, bool daylight, const V& up,
    const V& t, const V& b, double height)
    : Up(up)
    , T(t)
    , B(b)
    , Daylight(daylight)
    , Height(height)
    , Scene(scene)
  {
    double bounds[6];
    scene->GetBounds(bounds);
    this->Size = std::sqrt((bounds[1] - bounds[0]) * (bounds[1] - bounds[0]) +
      (bounds[3] - bounds[2]) * (bounds[3] - bounds[2]) +
      (bounds[5] - bounds[4]) * (bounds[5] - bounds[4]));
    this->Offset = 1e-6 * this->Size;
    // VTK's polygons meet a line only where the intersection lies within this distance of
    // them: at 0 a rounding error loses about one hit in twenty, and light leaks through
    // closed walls.
    this->Tolerance = 1e-9 * this->Size;
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
    V hit;
    return this->firstBelow(point, hit) >= 0 && this->seesALight(hit);
  }

  /// Whether `point`, on a polygon facing down of a group within `extent`, is on a correctly
  /// oriented room's ceiling over its floor, where the sky seen from above the ceiling says
  /// nothing. Seen from `point` alone, such a ceiling and the floor of a room modelled with
  /// outward normals standing on a ground (or on the roof below, or on stilts over the ground)
  /// look alike: a polygon facing down over one facing up at it. They differ in which side of
  /// the polygon is a room: a space that holds the work plane and is walled in. The space
  /// between the two polygons is a room when it is higher than the work plane (the floor's
  /// work plane lies under the ceiling) and its work plane is walled in; lower, it is a gap
  /// (under an outward room's floor on a ground), never a room. When it is high but open,
  /// the space above `point` decides: walled in, it is the room of a floor raised over open
  /// ground; open too, neither side is a room (a canopy, a pavilion's ceiling) and the normals
  /// are taken as given: a ceiling.
  bool ceilingOverItsFloor(const V& point, const Extent& extent) const
  {
    V hit;
    const vtkIdType cell = this->firstBelow(point, hit);
    if (cell < 0 || dot(this->normalOf(cell), this->Up) <= 0 ||
      dot(point - hit, this->Up) <= this->Height)
    {
      return false;
    }
    return this->walledIn(hit + scaled(this->Up, this->Height), extent) ||
      !this->walledIn(point + scaled(this->Up, this->Height), extent);
  }

  /// The nearest of `cells` straight below `point` (-1 when none), and its height along up.
  vtkIdType nearestBelow(const V& point, const std::set<vtkIdType>& cells, double& level) const
  {
    const V from = point - scaled(this->Up, this->Offset);
    const V to = from - scaled(this->Up, 2 * this->Size + 1);
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    vtkNew<vtkPoints> points;
    vtkNew<vtkIdList> hits;
    vtkNew<vtkGenericCell> cell;
    this->Locator->IntersectWithLine(a, z, this->Tolerance, points, hits, cell);
    vtkIdType nearest = -1;
    level = -std::numeric_limits<double>::infinity();
    for (vtkIdType i = 0; i < hits->GetNumberOfIds(); ++i)
    {
      double x[3];
      points->GetPoint(i, x);
      const double h = dot({ x[0], x[1], x[2] }, this->Up);
      if (cells.count(hits->GetId(i)) && h > level)
      {
        nearest = hits->GetId(i);
        level = h;
      }
    }
    return nearest;
  }

  /// Whether `point` is walled in: more than half of WallDirections horizontal rays from it
  /// meet a polygon before they leave `extent`, the bounds of the floor or ceiling in question
  /// (with `fromInside`, a polygon seen from behind, its normal pointing away). A room's walls
  /// stand at the edges of its floor and ceiling, within their bounds; a neighbour's wall
  /// across the street lies beyond them and walls in no room of theirs. More than half: a
  /// room's windows and doors let some rays out.
  bool walledIn(const V& point, const Extent& extent, bool fromInside = false) const
  {
    const double u = dot(point, this->T), v = dot(point, this->B);
    // The answer is known once more than half of the rays meet a wall, or half do not.
    int walls = 0, open = 0;
    for (int k = 0; 2 * walls <= WallDirections && 2 * open < WallDirections; ++k)
    {
      // Half a step off the axes: no ray runs along a wall.
      const double phi = 2 * M_PI * (k + 0.5) / WallDirections;
      const double cu = std::cos(phi), cv = std::sin(phi);
      const double reach = std::min((cu > 0 ? extent.uHi - u : extent.uLo - u) / cu,
        (cv > 0 ? extent.vHi - v : extent.vLo - v) / cv);
      const V direction = scaled(this->T, cu) + scaled(this->B, cv);
      const vtkIdType cell =
        reach > 0 ? this->firstHit(point, point + scaled(direction, reach)) : vtkIdType(-1);
      const bool wall = cell >= 0 && (!fromInside || dot(this->normalOf(cell), direction) > 0);
      (wall ? walls : open) += 1;
    }
    return 2 * walls > WallDirections;
  }

  /// Whether the sky is in sight from just above `point`, along one of SkyDirections
  /// directions spread evenly over the hemisphere (a spiral of equal solid angles, from the
  /// horizon to the zenith). The spiral of turn k is turned by k golden angles and its
  /// heights shifted by k golden ratios: probes of one floor, with turns 0, 1, 2..., look
  /// between one another's directions, towards an opening that one alone could miss.
  bool seesTheSky(const V& point, std::size_t turn) const
  {
    const double goldenRatio = (std::sqrt(5.0) - 1) / 2;
    const double goldenAngle = 2 * M_PI * (1 - goldenRatio);
    const double shift = std::fmod(0.5 + goldenRatio * static_cast<double>(turn), 1.0);
    const V from = this->above(point);
    for (int i = 0; i < SkyDirections; ++i)
    {
      const double z = (i + shift) / SkyDirections;
      const double r = std::sqrt(1 - z * z);
      const double phi = goldenAngle * static_cast<double>(static_cast<std::size_t>(i) + turn);
      const V direction = scaled(this->T, r * std::cos(phi)) + scaled(this->B, r * std::sin(phi)) +
        scaled(this->Up, z);
      if (!this->blocked(from, from + scaled(direction, 2 * this->Size + 1)))
      {
        return true;
      }
    }
    return false;
  }

  /// Whether nothing lies less than the work plane's height straight above `point`.
  bool roomAbove(const V& point) const
  {
    const V from = this->above(point);
    return !this->blocked(from, from + scaled(this->Up, this->Height));
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

  /// Whether `point`, on a polygon facing up over a floor found facing down (within
  /// `floorExtent`), is that room's roof: nothing above it; under lights, no light in sight
  /// (daylight reaches a roof; a room's lamps light its floor and what stands on it); and its
  /// work plane not walled in by the room's walls. A roof stands on the walls, with the
  /// outdoors around; a table under an opening in the roof, with nothing above it either,
  /// stands within them, and sees them from inside: from behind, as the room's normals point
  /// outward. A parapet or a taller part of the building around a roof shows it its front.
  bool isRoof(const V& point, const Extent& floorExtent) const
  {
    const V from = this->above(point);
    return !this->blocked(from, from + scaled(this->Up, 2 * this->Size + 1)) &&
      (this->Daylight || !this->seesALight(point)) &&
      !this->walledIn(point + scaled(this->Up, this->Height), floorExtent, true);
  }

private:
  V above(const V& point) const { return point + scaled(this->Up, this->Offset); }

  /// The first cell straight below `point` and where the line meets it; -1 when none.
  vtkIdType firstBelow(const V& point, V& hit) const
  {
    const V from = point - scaled(this->Up, this->Offset);
    const V to = from - scaled(this->Up, 2 * this->Size + 1);
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    double t = 0, x[3], pcoords[3];
    int subId = 0;
    vtkIdType cell = -1;
    if (this->Locator->IntersectWithLine(a, z, this->Tolerance, t, x, pcoords, subId, cell) == 0)
    {
      return -1;
    }
    hit = { x[0], x[1], x[2] };
    return cell;
  }

  /// The first cell between `from` and `to`; -1 when none.
  vtkIdType firstHit(const V& from, const V& to) const
  {
    double a[3] = { from.x, from.y, from.z }, z[3] = { to.x, to.y, to.z };
    double t = 0, x[3], pcoords[3];
    int subId = 0;
    vtkIdType cell = -1;
    return this->Locator->IntersectWithLine(a, z, this->Tolerance, t, x, pcoords, subId, cell) != 0
      ? cell
      : -1;
  }

  bool blocked(const V& from, const V& to) const { return this->firstHit(from, to) >= 0; }

  /// Twice the area times the unit normal of a cell of the scene.
  V normalOf(vtkIdType cell) const
  {
    vtkNew<vtkIdList> ids;
    this->Scene->GetCellPoints(cell, ids);
    std::vector<V> corners;
    for (vtkIdType i = 0; i < ids->GetNumberOfIds(); ++i)
    {
      double p[3];
      this->Scene->GetPoint(ids->GetId(i), p);
      corners.push_back({ p[0], p[1], p[2] });
    }
    return areaVector(corners);
  }

  V Up, T, B;
  bool Daylight;
  double Height;
  double Size = 0, Offset = 0, Tolerance = 0;
  std::vector<V> Lights;
  vtkPolyData* Scene;
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
  double height, double spacing, const std::vector<Triple>& lights, bool daylight,
  std::size_t frames, std::uint64_t memoryLimit)
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
  bool floorsFacingDown = false;
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
    const V newell = areaVector(corners);
    const double twiceArea = std::sqrt(dot(newell, newell));
    const bool facesUp = twiceArea > 0 && dot(newell, up) >= minimumCosine * twiceArea;
    const bool facesDown = twiceArea > 0 && -dot(newell, up) >= minimumCosine * twiceArea;
    anyFacingDown = anyFacingDown || facesDown;
    if (!facesUp && !(facesDown && (daylight || !lights.empty())))
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
      << (facingDown.empty() ? ""
                             : (daylight ? ", nor one facing down that sees the sky from above"
                                         : ", nor one facing down that sees a light from above"))
      << ": give a scene with floors whose normals point up, or --sensors";
    return InputError(s.str());
  };
  if (faces.empty() && facingDown.empty())
  {
    throw noFloor();
  }
  checkSensorCount(area, spacing, frames, memoryLimit);

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
    // the light it sees: its upper side, where the sensors go, sees a light or the sky. A
    // correctly oriented room's ceilings and undersides see no light from above; the sky
    // they may see, but they lie over the room's floor, which faces up at them across the
    // room (ceilingOverItsFloor).
    const FloorFinder finder(scene, lights, daylight, up, t, b, height);
    // Faces that touch at one height are one floor: a part in shadow goes with the parts
    // that see the light, and a windowless unit of a terrace with its neighbour's (its floor
    // is a floor with inward normals too, dark); another building's floor at that height is
    // decided by its own.
    std::sort(facingDown.begin(), facingDown.end(),
      [](const Face& f, const Face& g) { return f.level < g.level; });
    std::vector<Face> floors;
    std::map<vtkIdType, Extent> floorExtents; ///< of each floor's cell: its group's bounds
    std::vector<std::vector<Face>> groups;
    for (const std::vector<Face>& level : levelsOf(facingDown, finder.levelTolerance()))
    {
      for (std::vector<Face>& group : touchingGroups(level, finder.levelTolerance()))
      {
        groups.push_back(std::move(group));
      }
    }
    for (const std::vector<Face>& group : groups)
    {
      double groupArea = 0;
      for (const Face& face : group)
      {
        groupArea += face.area;
      }
      // At most about 64 probes a group, and at least its lattice's points.
      const double probeStep = std::max(spacing, std::sqrt(groupArea / 64));
      const std::vector<Sensor> probes = lattice(group, probeStep);
      const Extent extent = extentOf(group, finder.levelTolerance());
      bool floor = false;
      if (daylight)
      {
        floor = std::none_of(probes.begin(), probes.end(),
          [&](const Sensor& probe) { return finder.ceilingOverItsFloor(probe.point, extent); });
        const std::size_t stride = (probes.size() + SkyProbes - 1) / SkyProbes;
        bool sky = false;
        for (std::size_t k = 0; floor && !sky && k < probes.size(); k += stride)
        {
          sky = finder.seesTheSky(probes[k].point, k / stride);
        }
        floor = floor && sky;
      }
      else
      {
        floor = std::any_of(probes.begin(), probes.end(),
          [&](const Sensor& probe)
          { return finder.seesALight(probe.point) && !finder.litBelow(probe.point); });
      }
      if (floor)
      {
        // A face with no room for the work plane over any of its points is the bottom of a
        // solid lower than it (a block, a bench, a step) that touches the floor or the
        // building: no room's floor, as a room lower than the work plane holds none. It is
        // left as the polygons facing up leave it, its top's sensors kept.
        std::vector<Face> kept;
        for (const Face& face : group)
        {
          const std::vector<Sensor> points = lattice({ face }, spacing);
          if (points.empty() ||
            std::any_of(points.begin(), points.end(),
              [&](const Sensor& point) { return finder.roomAbove(point.point); }))
          {
            kept.push_back(face);
          }
        }
        const Extent keptExtent = extentOf(kept, finder.levelTolerance());
        for (const Face& face : kept)
        {
          floors.push_back(face);
          floorExtents[face.cell] = keptExtent;
        }
      }
    }
    floorsFacingDown = !floors.empty();
    if (floorsFacingDown)
    {
      double floorArea = 0;
      for (const Face& face : floors)
      {
        floorArea += face.area;
      }
      checkSensorCount(area + floorArea, spacing, frames, memoryLimit);
      std::set<vtkIdType> floorCells;
      for (const Face& face : floors)
      {
        floorCells.insert(face.cell);
      }
      for (Sensor& sensor : sensors)
      {
        double level = 0;
        const vtkIdType floor =
          finder.nearestBelow(sensor.point + scaled(up, height), floorCells, level);
        // A floor between a face and its sensor's point, or at the face's level, puts the
        // point in that floor's room, whose own lattice covers it: the ground's under a room
        // standing on it, a lower roof's under the next storey's floor. Under a floor
        // standing higher (on stilts) the point is outdoors and stays. Otherwise the face
        // may be that room's roof.
        sensor.keep = floor < 0 ||
          (level < sensor.w - finder.levelTolerance() &&
            !finder.isRoof(sensor.point, floorExtents.at(floor)));
      }
      std::vector<Sensor> more;
      std::stable_sort(floors.begin(), floors.end(),
        [](const Face& f, const Face& g) { return f.level < g.level; });
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
  // faces down and was not found, its roof's do.
  if (anyFacingDown && !floorsFacingDown && points->GetNumberOfPoints() > 0 &&
    above == static_cast<std::size_t>(points->GetNumberOfPoints()))
  {
    std::ostringstream s;
    s << "--work-plane: every sensor lies above the scene, " << height
      << " above its polygons facing up (roofs?), while polygons facing down may be its floors: "
      << (daylight            ? "none of them sees the sky from above: give --sensors"
             : lights.empty() ? "the floors are the polygons facing up: turn the floors' "
                                "normals up, or give --sensors"
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
  vtkNew<vtkPolyData> frame;
  frame->ShallowCopy(sensors);
  vtkNew<vtkFieldData> fieldData;
  fieldData->ShallowCopy(sensors->GetFieldData());
  keepOwnFrameFigures(fieldData);
  frame->SetFieldData(fieldData);
  vtkNew<vtkXMLPolyDataWriter> writer;
  writer->SetInputData(frame);
  writer->SetDataModeToAppended();
  writer->SetCompressorTypeToLZ4();
  writeXml(writer, path, "the sensors");
}

} // namespace mlr::cli
