// Soup repair. repair_polygon_soup() would reorder the triangles and lose their materials,
// so its steps run one by one, keeping track of where every triangle came from.
#include "CgalRemeshingInternal.h"

#include "Error.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <array>

namespace mlr::detail
{
namespace cgal
{
namespace
{

/// The kernel's lexicographic order with a cancellation point at every comparison, for
/// merge_duplicate_points_in_polygon_soup() (a third of a second on 500,000 points).
struct PolledLessXyz
{
  CancellationPoll* poll = nullptr;
  Kernel::Less_xyz_3 less;
  bool operator()(const Point& a, const Point& b) const
  {
    this->poll->tick();
    return this->less(a, b);
  }
};

struct PolledSoupTraits
{
  using Less_xyz_3 = PolledLessXyz;
  CancellationPoll* poll = nullptr;
  Less_xyz_3 less_xyz_3_object() const { return { this->poll, Kernel().less_xyz_3_object() }; }
};

/// Drops triangles whose corners merged or are exactly collinear (exact predicate).
std::size_t removeDegenerateTriangles(RepairedSoup& soup)
{
  std::vector<bool> keep(soup.triangles.size());
  std::size_t removed = 0;
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const CgalTriangle& t = soup.triangles[i];
    keep[i] = t[0] != t[1] && t[1] != t[2] && t[2] != t[0] &&
      !CGAL::collinear(soup.points[t[0]], soup.points[t[1]], soup.points[t[2]]);
    removed += keep[i] ? 0 : 1;
  }
  keepTriangles(soup, keep);
  return removed;
}

/// Keeps the first of triangles on the same three points, whatever their orientation: two
/// coincident faces cannot both be part of a surface.
std::size_t removeDuplicateTriangles(RepairedSoup& soup, CancellationPoll& poll)
{
  std::vector<std::pair<CgalTriangle, std::size_t>> sorted(soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    CgalTriangle key = soup.triangles[i];
    std::sort(key.begin(), key.end());
    sorted[i] = { key, i };
  }
  std::sort(sorted.begin(), sorted.end(),
    [&poll](const auto& a, const auto& b)
    {
      poll.tick();
      return a < b;
    });
  std::vector<bool> keep(soup.triangles.size(), true);
  std::size_t removed = 0;
  for (std::size_t i = 1; i < sorted.size(); ++i)
  {
    if (sorted[i].first == sorted[i - 1].first)
    {
      keep[sorted[i].second] = false;
      ++removed;
    }
  }
  keepTriangles(soup, keep);
  return removed;
}

/// Whether coplanar, non-degenerate triangles s and t face the same way and overlap with some
/// area: no supporting
/// line of an edge of either has the other triangle wholly on its outer side (two convex
/// polygons' interiors are disjoint exactly when such a line separates them). Exact: the
/// orientation tests run on the coordinate plane the triangles' plane projects onto one to
/// one.
bool interiorsOverlap(const std::array<Point, 3>& s, const std::array<Point, 3>& t)
{
  using Point2 = Kernel::Point_2;
  std::array<Point2, 3> a, b;
  for (int axis = 0; axis < 3; ++axis)
  {
    const auto project = [axis](const Point& p)
    {
      return axis == 0 ? Point2(p.y(), p.z())
        : axis == 1    ? Point2(p.z(), p.x())
                       : Point2(p.x(), p.y());
    };
    for (int k = 0; k < 3; ++k)
    {
      a[k] = project(s[k]);
      b[k] = project(t[k]);
    }
    if (!CGAL::collinear(a[0], a[1], a[2]))
    {
      break;
    }
  }
  const auto separates = [](const std::array<Point2, 3>& x, const std::array<Point2, 3>& y)
  {
    for (int k = 0; k < 3; ++k)
    {
      const Point2 &p = x[k], &q = x[(k + 1) % 3];
      const CGAL::Orientation inside = CGAL::orientation(p, q, x[(k + 2) % 3]);
      if (CGAL::orientation(p, q, y[0]) != inside && CGAL::orientation(p, q, y[1]) != inside &&
        CGAL::orientation(p, q, y[2]) != inside)
      {
        return true;
      }
    }
    return false;
  };
  // Facing the same way only: a face lying face to face on another (a block's bottom on the
  // floor) is a contact, which splitAtContacts() handles.
  return CGAL::orientation(a[0], a[1], a[2]) == CGAL::orientation(b[0], b[1], b[2]) &&
    !separates(a, b) && !separates(b, a);
}

/// Of triangles that lie in one plane, face the same way and overlap with some area (two
/// triangulations of one face, a face folded onto itself, a polygon drawn over another, a
/// block's face on a wall), keeps those of the larger input polygon (of the first of equal
/// ones). CGAL 5.5's autorefinement does not handle such coplanar overlaps (it binds
/// references to null points, or never ends), and no surface can hold both. The smaller
/// polygon is the one likely to lie within the other: keeping the first instead dropped a
/// wall's triangle for the block face given before it, half the wall, and daylight poured
/// into the room. Whole polygons are compared, not their triangles, so that of two
/// triangulations of one polygon one stays whole, not a mixture with gaps.
std::size_t removeOverlappingTriangles(
  RepairedSoup& soup, const TriangleSoup& input, CancellationPoll& poll)
{
  using TriangleBox = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t>;
  std::vector<TriangleBox> boxes;
  boxes.reserve(soup.triangles.size());
  const auto corners = [&soup](std::size_t i)
  {
    const CgalTriangle& t = soup.triangles[i];
    return std::array<Point, 3>{ soup.points[t[0]], soup.points[t[1]], soup.points[t[2]] };
  };
  const auto polygonOf = [&](std::size_t i) -> std::size_t
  { return input.polygon.empty() ? soup.input[i] : input.polygon[soup.input[i]]; };
  std::vector<double> polygonArea;
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const std::array<Point, 3> c = corners(i);
    boxes.emplace_back(c[0].bbox() + c[1].bbox() + c[2].bbox(), i);
    const std::size_t polygon = polygonOf(i);
    polygonArea.resize(std::max(polygonArea.size(), polygon + 1), 0.0);
    polygonArea[polygon] += std::sqrt(CGAL::squared_area(c[0], c[1], c[2]));
  }
  // Whether triangle i goes before j: that of the larger polygon, then of the earlier one,
  // then the earlier triangle.
  const auto before = [&](std::size_t i, std::size_t j)
  {
    const std::size_t p = polygonOf(i), q = polygonOf(j);
    return polygonArea[p] != polygonArea[q] ? polygonArea[p] > polygonArea[q]
      : p != q                              ? p < q
                                            : i < j;
  };
  // The pairs (loser, winner), gathered in whatever order the boxes meet, then decided in
  // the losers' order: a triangle goes when it overlaps one before it that stays.
  std::vector<std::pair<std::size_t, std::size_t>> overlapping;
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(),
    [&](const TriangleBox& x, const TriangleBox& y)
    {
      poll.tick();
      const std::array<Point, 3> s = corners(x.info()), t = corners(y.info());
      if (CGAL::coplanar(s[0], s[1], s[2], t[0]) && CGAL::coplanar(s[0], s[1], s[2], t[1]) &&
        CGAL::coplanar(s[0], s[1], s[2], t[2]) && interiorsOverlap(s, t))
      {
        overlapping.push_back(before(x.info(), y.info()) ? std::make_pair(y.info(), x.info())
                                                         : std::make_pair(x.info(), y.info()));
      }
    });
  std::sort(overlapping.begin(), overlapping.end(),
    [&](const auto& a, const auto& b)
    { return a.first != b.first ? before(a.first, b.first) : before(a.second, b.second); });
  std::vector<bool> keep(soup.triangles.size(), true);
  std::size_t removed = 0;
  for (const auto& [loser, winner] : overlapping)
  {
    if (keep[loser] && keep[winner])
    {
      keep[loser] = false;
      ++removed;
    }
  }
  keepTriangles(soup, keep);
  return removed;
}

bool sameCyclicOrder(const CgalTriangle& a, const CgalTriangle& b, const std::vector<Point>& points)
{
  for (int k = 0; k < 3; ++k)
  {
    if (points[b[k]] == points[a[0]])
    {
      return points[b[(k + 1) % 3]] == points[a[1]];
    }
  }
  return false;
}

} // namespace

void keepTriangles(RepairedSoup& soup, const std::vector<bool>& keep)
{
  const bool oriented = soup.flipped.size() == soup.triangles.size();
  std::size_t kept = 0;
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    if (keep[i])
    {
      soup.triangles[kept] = soup.triangles[i];
      soup.input[kept] = soup.input[i];
      if (oriented)
      {
        soup.flipped[kept] = soup.flipped[i];
      }
      ++kept;
    }
  }
  soup.triangles.resize(kept);
  soup.input.resize(kept);
  if (oriented)
  {
    soup.flipped.resize(kept);
  }
}

std::size_t orientSoup(RepairedSoup& soup)
{
  const std::vector<CgalTriangle> before = soup.triangles;
  const std::size_t pointsBefore = soup.points.size();
  PMP::orient_polygon_soup(soup.points, soup.triangles);
  soup.flipped.resize(soup.triangles.size(), false);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    soup.flipped[i] =
      soup.flipped[i] != !sameCyclicOrder(before[i], soup.triangles[i], soup.points);
  }
  return soup.points.size() - pointsBefore;
}

RepairedSoup repairAndOrient(const std::vector<Vec3>& points, const TriangleSoup& input,
  CgalRemeshOutput& out, CancellationPoll& poll)
{
  RepairedSoup soup;
  soup.points.reserve(points.size());
  for (const Vec3& p : points)
  {
    soup.points.push_back(toPoint(p));
  }
  soup.triangles.reserve(input.triangles.size());
  soup.input.resize(input.triangles.size());
  for (std::size_t i = 0; i < input.triangles.size(); ++i)
  {
    const Triangle& t = input.triangles[i];
    soup.triangles.push_back({ t[0], t[1], t[2] });
    soup.input[i] = i;
  }
  PMP::merge_duplicate_points_in_polygon_soup(
    soup.points, soup.triangles, CGAL::parameters::geom_traits(PolledSoupTraits{ &poll }));
  poll.check();
  out.degenerateTriangles = removeDegenerateTriangles(soup);
  out.duplicateTriangles = removeDuplicateTriangles(soup, poll);
  out.foldedTriangles = removeOverlappingTriangles(soup, input, poll);
  PMP::remove_isolated_points_in_polygon_soup(soup.points, soup.triangles);
  poll.check();
  // A soup that already is an oriented manifold mesh (most are) would come out of
  // orient_polygon_soup() unchanged, after a quarter of a second per 200,000 triangles that
  // cannot be interrupted: test for it first, which is several times faster.
  if (isPolygonMesh(soup.triangles, poll))
  {
    soup.flipped.assign(soup.triangles.size(), false);
    return soup;
  }
  poll.check();
  out.splitPoints = orientSoup(soup);
  poll.check();
  if (!isPolygonMesh(soup.triangles, poll))
  {
    throw Error("the oriented triangles still do not form a manifold surface");
  }
  return soup;
}

} // namespace cgal

bool cgalIsPolygonSoupAPolygonMesh(const std::vector<SoupTriangle>& triangles)
{
  return cgal::PMP::is_polygon_soup_a_polygon_mesh(triangles);
}

} // namespace mlr::detail
