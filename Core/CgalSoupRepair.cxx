// Soup repair. repair_polygon_soup() would reorder the triangles and lose their materials,
// so its steps run one by one, keeping track of where every triangle came from.
#include "CgalRemeshingInternal.h"

#include "Error.h"

#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>

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

/// Keeps the first of two triangles that share an edge, lie in one plane and are on the same
/// side of that edge, so that they overlap: two triangulations of one face, or a face folded
/// onto itself. CGAL 5.5's autorefinement does not handle three such coplanar faces meeting
/// at a point (it binds a reference to a null point), and no surface can hold both.
std::size_t removeFoldedTriangles(RepairedSoup& soup, CancellationPoll& poll)
{
  std::vector<std::array<std::size_t, 4>> edges; // a, b (a < b), opposite corner, triangle
  edges.reserve(3 * soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const CgalTriangle& t = soup.triangles[i];
    for (int k = 0; k < 3; ++k)
    {
      const std::size_t a = t[k], b = t[(k + 1) % 3];
      edges.push_back({ std::min(a, b), std::max(a, b), t[(k + 2) % 3], i });
    }
  }
  std::sort(edges.begin(), edges.end(),
    [&poll](const auto& x, const auto& y)
    {
      poll.tick();
      return x < y;
    });
  std::vector<bool> keep(soup.triangles.size(), true);
  std::size_t removed = 0;
  for (std::size_t e = 0; e < edges.size();)
  {
    std::size_t end = e + 1;
    while (end < edges.size() && edges[end][0] == edges[e][0] && edges[end][1] == edges[e][1])
    {
      ++end;
    }
    const Point& a = soup.points[edges[e][0]];
    const Point& b = soup.points[edges[e][1]];
    for (std::size_t j = e + 1; j < end; ++j)
    {
      for (std::size_t i = e; i < j && keep[edges[j][3]]; ++i)
      {
        poll.tick();
        const Point& c = soup.points[edges[i][2]];
        const Point& d = soup.points[edges[j][2]];
        if (keep[edges[i][3]] && edges[i][3] != edges[j][3] && CGAL::coplanar(a, b, c, d) &&
          CGAL::coplanar_orientation(a, b, c, d) == CGAL::POSITIVE)
        {
          const std::size_t later = std::max(edges[i][3], edges[j][3]);
          keep[later] = false;
          ++removed;
        }
      }
    }
    e = end;
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
  out.foldedTriangles = removeFoldedTriangles(soup, poll);
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
