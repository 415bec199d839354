// Contact lines. Where a surface touches or crosses another (a block standing on a floor, a
// panel through a wall), a patch on both sides of the line would average the lit side with
// the shadowed one, and light would leak across it. The soup is split along these lines
// first (CGAL's autorefinement: exact predicates, intersection points rounded once), and the
// lines become remeshing constraints.
#include "CgalRemeshingInternal.h"

#include "DisjointSets.h"
#include "Error.h"

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Projection_traits_xy_3.h>
#include <CGAL/Projection_traits_xz_3.h>
#include <CGAL/Projection_traits_yz_3.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/box_intersection_d.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <numeric>

namespace mlr::detail::cgal
{
namespace
{

constexpr std::size_t NoOrigin = std::numeric_limits<std::size_t>::max();

/// Where autorefinement is in the soup, shared by the visitor's copies.
struct SplitTracking
{
  Mesh::Property_map<FaceIndex, std::size_t> origin;
  std::size_t splitting = NoOrigin;
  CancellationPoll* poll = nullptr;
};

/// Gives the pieces of a split face the origin of that face, and lets autorefinement be
/// cancelled at its steps (its vertex points are polled too).
struct SplitVisitor : PMP::Corefinement::Default_visitor<Mesh>
{
  SplitTracking* tracking = nullptr;

  void before_subface_creations(FaceIndex f, Mesh&)
  {
    this->tracking->splitting = this->tracking->origin[f];
    this->tracking->poll->tick();
  }
  void after_subface_created(FaceIndex f, Mesh&)
  {
    this->tracking->origin[f] = this->tracking->splitting;
  }
  void progress_filtering_intersections(double) const { this->tracking->poll->tick(); }
  void triangulating_faces_step() const { this->tracking->poll->tick(); }
  void intersection_of_coplanar_faces_step() const { this->tracking->poll->tick(); }
};

/// Connected surfaces of the soup (triangles sharing a point), which of them are closed, and
/// each triangle's edges: what the contact search and the covered faces need, without building a
/// mesh of the whole soup.
struct Surfaces
{
  std::vector<std::size_t> of; ///< surface of each triangle
  std::size_t count = 0;
  std::vector<bool> closed; ///< every edge shared by two triangles
  /// (smaller point, larger point, triangle) for every triangle edge, sorted.
  std::vector<std::array<std::size_t, 3>> edges;
};

Surfaces findSurfaces(const RepairedSoup& soup, CancellationPoll& poll)
{
  DisjointSets connected(soup.points.size());
  for (const CgalTriangle& t : soup.triangles)
  {
    poll.tick();
    for (int k = 1; k < 3; ++k)
    {
      connected.join(t[0], t[static_cast<std::size_t>(k)]);
    }
  }
  Surfaces s;
  std::vector<std::size_t> index(soup.points.size(), NoOrigin);
  s.of.resize(soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    std::size_t& surface = index[connected.find(soup.triangles[i][0])];
    if (surface == NoOrigin)
    {
      surface = s.count++;
    }
    s.of[i] = surface;
  }
  return s;
}

/// Fills in the edges of `s` and which of its surfaces are closed.
void findEdges(const RepairedSoup& soup, Surfaces& s, CancellationPoll& poll)
{
  s.closed.assign(s.count, true);
  s.edges.reserve(3 * soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const CgalTriangle& t = soup.triangles[i];
    for (std::size_t k = 0; k < 3; ++k)
    {
      const std::size_t a = t[k], b = t[(k + 1) % 3];
      s.edges.push_back({ std::min(a, b), std::max(a, b), i });
    }
  }
  std::sort(s.edges.begin(), s.edges.end(),
    [&poll](const auto& a, const auto& b)
    {
      poll.tick();
      return a < b;
    });
  for (std::size_t i = 0; i < s.edges.size();)
  {
    std::size_t j = i + 1;
    while (j < s.edges.size() && s.edges[j][0] == s.edges[i][0] && s.edges[j][1] == s.edges[i][1])
    {
      ++j;
    }
    if (j - i != 2)
    {
      s.closed[s.of[s.edges[i][2]]] = false;
    }
    i = j;
  }
}

using TriangleBox = CGAL::Box_intersection_d::Box_with_info_d<double, 3, std::size_t>;

/// Triangles that touch or cross a triangle of another surface: boxes first
/// (box_intersection_d), then CGAL's exact triangle-triangle predicate.
std::vector<bool> touchingTriangles(
  const RepairedSoup& soup, const Surfaces& surfaces, CancellationPoll& poll)
{
  std::vector<bool> touching(soup.triangles.size(), false);
  if (surfaces.count < 2)
  {
    return touching;
  }
  std::vector<TriangleBox> boxes;
  boxes.reserve(soup.triangles.size());
  std::vector<CGAL::Bbox_3> surfaceBox(surfaces.count);
  std::vector<bool> started(surfaces.count, false);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const CgalTriangle& t = soup.triangles[i];
    boxes.emplace_back(
      soup.points[t[0]].bbox() + soup.points[t[1]].bbox() + soup.points[t[2]].bbox(), i);
    const std::size_t s = surfaces.of[i];
    surfaceBox[s] = started[s] ? surfaceBox[s] + boxes.back().bbox() : boxes.back().bbox();
    started[s] = true;
  }
  // Only triangles within the box of another surface can touch it: on most scenes this
  // leaves a small fraction, and none on a single surface however large.
  std::vector<TriangleBox> surfaceBoxes;
  for (std::size_t s = 0; s < surfaces.count; ++s)
  {
    surfaceBoxes.emplace_back(surfaceBox[s], s);
  }
  std::vector<bool> candidate(soup.triangles.size(), false);
  CGAL::box_intersection_d(boxes.begin(), boxes.end(), surfaceBoxes.begin(), surfaceBoxes.end(),
    [&](const TriangleBox& triangle, const TriangleBox& surface)
    {
      poll.tick();
      candidate[triangle.info()] =
        candidate[triangle.info()] || surfaces.of[triangle.info()] != surface.info();
    });
  boxes.erase(std::remove_if(boxes.begin(), boxes.end(),
                [&](const TriangleBox& b) { return !candidate[b.info()]; }),
    boxes.end());
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(),
    [&](const TriangleBox& a, const TriangleBox& b)
    {
      poll.tick();
      const std::size_t i = a.info(), j = b.info();
      if (surfaces.of[i] == surfaces.of[j] || (touching[i] && touching[j]))
      {
        return;
      }
      const CgalTriangle &s = soup.triangles[i], &t = soup.triangles[j];
      if (CGAL::do_intersect(
            Kernel::Triangle_3(soup.points[s[0]], soup.points[s[1]], soup.points[s[2]]),
            Kernel::Triangle_3(soup.points[t[0]], soup.points[t[1]], soup.points[t[2]])))
      {
        touching[i] = touching[j] = true;
      }
    });
  return touching;
}

/// A connected closed surface: an open surface lying on it face to face (the floor under a
/// block) is covered, never seen. Its distance tree is built when first needed.
struct ClosedSurface
{
  std::vector<std::size_t> triangles; ///< of the soup before splitting
  CGAL::Bbox_3 box;
  double tolerance = 0; ///< distance under which a point lies on the surface
  TriangleList faces;
  std::unique_ptr<Tree> tree;
};

/// The closed surfaces, each with only its triangles that touch another surface: a piece lying
/// on a closed surface lies on those.
std::vector<ClosedSurface> findClosedSurfaces(
  const RepairedSoup& soup, const Surfaces& surfaces, const std::vector<bool>& touching)
{
  std::vector<ClosedSurface> closed(surfaces.count);
  std::vector<CGAL::Bbox_3> whole(surfaces.count);
  std::vector<bool> started(surfaces.count, false);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    const std::size_t s = surfaces.of[i];
    if (surfaces.closed[s])
    {
      const CgalTriangle& t = soup.triangles[i];
      const CGAL::Bbox_3 box =
        soup.points[t[0]].bbox() + soup.points[t[1]].bbox() + soup.points[t[2]].bbox();
      whole[s] = started[s] ? whole[s] + box : box;
      started[s] = true;
      if (touching[i])
      {
        closed[s].box = closed[s].triangles.empty() ? box : closed[s].box + box;
        closed[s].triangles.push_back(i);
      }
    }
  }
  for (std::size_t s = 0; s < surfaces.count; ++s)
  {
    const CGAL::Bbox_3& b = whole[s];
    const double diagonal = std::sqrt(CGAL::square(b.xmax() - b.xmin()) +
      CGAL::square(b.ymax() - b.ymin()) + CGAL::square(b.zmax() - b.zmin()));
    // Contact points are rounded once to doubles: far above that, far below any real gap.
    closed[s].tolerance = 1e-9 * diagonal;
  }
  return closed;
}

const Tree& distanceTree(ClosedSurface& closed, const RepairedSoup& soup)
{
  if (!closed.tree)
  {
    for (std::size_t i : closed.triangles)
    {
      const CgalTriangle& t = soup.triangles[i];
      closed.faces.emplace_back(soup.points[t[0]], soup.points[t[1]], soup.points[t[2]]);
    }
    closed.tree = std::make_unique<Tree>(closed.faces.begin(), closed.faces.end());
    closed.tree->accelerate_distance_queries();
  }
  return *closed.tree;
}

/**
 * Marks the triangles of `split` (whose surfaces are `surfaceOf`) that lie face to face on a
 * closed surface of another surface (the floor under a block), once triangles have been split
 * along the contacts so that each lies wholly on or off it. The closed surfaces themselves are
 * kept whole, so that they stay closed; where two closed surfaces touch face to face, both
 * contact faces go, leaving one closed surface around both. Triangles inside a closed surface
 * but not on it are kept: with two-sided surfaces a closed box may be a room as well as a
 * solid, and only the light's position could tell.
 */
std::vector<bool> coveredTriangles(const RepairedSoup& split,
  const std::vector<std::size_t>& surfaceOf, const std::vector<bool>& piece,
  const RepairedSoup& original, std::vector<ClosedSurface>& closed, CancellationPoll& poll)
{
  std::vector<bool> covered(split.triangles.size(), false);
  std::vector<TriangleBox> closedBoxes;
  for (std::size_t s = 0; s < closed.size(); ++s)
  {
    if (!closed[s].triangles.empty())
    {
      const double t = closed[s].tolerance;
      const CGAL::Bbox_3& b = closed[s].box;
      closedBoxes.emplace_back(CGAL::Bbox_3(b.xmin() - t, b.ymin() - t, b.zmin() - t, b.xmax() + t,
                                 b.ymax() + t, b.zmax() + t),
        s);
    }
  }
  if (closedBoxes.empty())
  {
    return covered;
  }
  std::vector<TriangleBox> centroids;
  std::vector<Point> centroidOf(split.triangles.size());
  for (std::size_t i = 0; i < split.triangles.size(); ++i)
  {
    // Only pieces of triangles that touched another surface can lie on one.
    if (piece[i])
    {
      const CgalTriangle& t = split.triangles[i];
      centroidOf[i] = CGAL::centroid(split.points[t[0]], split.points[t[1]], split.points[t[2]]);
      centroids.emplace_back(centroidOf[i].bbox(), i);
    }
  }
  CGAL::box_intersection_d(centroids.begin(), centroids.end(), closedBoxes.begin(),
    closedBoxes.end(),
    [&](const TriangleBox& triangle, const TriangleBox& closedBox)
    {
      poll.tick();
      const std::size_t i = triangle.info();
      ClosedSurface& surface = closed[closedBox.info()];
      if (surfaceOf[i] != closedBox.info() && !covered[i])
      {
        covered[i] = distanceTree(surface, original).squared_distance(centroidOf[i]) <=
          CGAL::square(surface.tolerance);
      }
    });
  return covered;
}

/// Pieces in an order given by their point indices alone, each turned to start at its smallest
/// index (which keeps its orientation).
void sortPieces(std::vector<CgalTriangle>& pieces)
{
  for (CgalTriangle& t : pieces)
  {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());
  }
  std::sort(pieces.begin(), pieces.end());
}

/// See triangulateCanonically(). `Projection` drops the coordinate nearest the triangle's
/// normal; its predicates are exact on the points' coordinates, so the result depends on
/// nothing else.
template <typename Projection>
bool triangulateInProjection(const std::vector<Point>& points, const CgalTriangle& origin,
  const std::vector<std::size_t>& used,
  const std::vector<std::pair<std::size_t, std::size_t>>& border,
  const std::vector<std::pair<std::size_t, std::size_t>>& inner, std::vector<CgalTriangle>& result)
{
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<std::size_t, Projection>;
  using FaceBase = CGAL::Constrained_triangulation_face_base_2<Projection,
    CGAL::Triangulation_face_base_with_info_2<bool, Projection>>;
  using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
  using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Projection, Tds,
    CGAL::No_constraint_intersection_tag>;
  const Projection traits;
  const CGAL::Orientation turn =
    traits.orientation_2_object()(points[origin[0]], points[origin[1]], points[origin[2]]);
  if (turn == CGAL::COLLINEAR)
  {
    return false;
  }
  Cdt cdt(traits);
  // Where points are cocircular the triangulation depends on the insertion order: that of
  // the point indices, which follow the input and, for points made by splitting, their
  // coordinates.
  std::vector<typename Cdt::Vertex_handle> vertex(used.size());
  for (std::size_t i = 0; i < used.size(); ++i)
  {
    vertex[i] = cdt.insert(points[used[i]]);
    vertex[i]->info() = used[i];
  }
  auto handle = [&](std::size_t point)
  {
    return vertex[static_cast<std::size_t>(
      std::lower_bound(used.begin(), used.end(), point) - used.begin())];
  };
  for (const auto* edges : { &border, &inner })
  {
    for (const auto& [a, b] : *edges)
    {
      cdt.insert_constraint(handle(a), handle(b));
    }
  }
  if (cdt.number_of_vertices() != used.size())
  {
    return false; // two points projected onto one, or a constraint crossed another
  }
  for (const auto* edges : { &border, &inner })
  {
    for (const auto& [a, b] : *edges)
    {
      if (!cdt.is_edge(handle(a), handle(b)))
      {
        return false; // a point lies on a constraint in projection
      }
    }
  }
  // Faces outside the triangle's border (where rounding made the border concave) are
  // reached from the infinite face without crossing the border.
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f)
  {
    f->info() = true;
  }
  std::vector<typename Cdt::Face_handle> front{ cdt.infinite_face() };
  front.back()->info() = false;
  while (!front.empty())
  {
    const typename Cdt::Face_handle f = front.back();
    front.pop_back();
    for (int i = 0; i < 3; ++i)
    {
      const typename Cdt::Vertex_handle a = f->vertex(Cdt::cw(i)), b = f->vertex(Cdt::ccw(i));
      const bool onBorder = !cdt.is_infinite(a) && !cdt.is_infinite(b) &&
        std::binary_search(border.begin(), border.end(),
          std::make_pair(std::min(a->info(), b->info()), std::max(a->info(), b->info())));
      const typename Cdt::Face_handle g = f->neighbor(i);
      if (!onBorder && g->info())
      {
        g->info() = false;
        front.push_back(g);
      }
    }
  }
  result.clear();
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f)
  {
    if (f->info())
    {
      CgalTriangle t = { f->vertex(0)->info(), f->vertex(1)->info(), f->vertex(2)->info() };
      if (turn == CGAL::CLOCKWISE)
      {
        std::swap(t[1], t[2]);
      }
      result.push_back(t);
    }
  }
  return true;
}

/**
 * Triangulates again, from the point indices and coordinates alone, the triangle `origin`
 * that autorefinement split into `faces` (its output, degenerate faces included), keeping the
 * contact edges among them. `pieces` (the non-degenerate faces) is replaced when the new
 * triangulation has the same points and area, and kept otherwise (rounding may leave the
 * border too far from flat for a projection; then only their order is made canonical).
 */
void triangulateCanonically(const std::vector<Point>& points, const CgalTriangle& origin,
  const std::vector<CgalTriangle>& faces,
  const std::vector<std::pair<std::size_t, std::size_t>>& contactEdges,
  std::vector<CgalTriangle>& pieces)
{
  std::vector<std::size_t> used;
  std::vector<std::pair<std::size_t, std::size_t>> edges;
  for (const CgalTriangle& t : faces)
  {
    for (std::size_t k = 0; k < 3; ++k)
    {
      const std::size_t a = t[k], b = t[(k + 1) % 3];
      used.push_back(a);
      if (a != b)
      {
        edges.emplace_back(std::min(a, b), std::max(a, b));
      }
    }
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::sort(edges.begin(), edges.end());
  // Edges of one face only are the triangle's border; the others are inside, and kept when on
  // a contact line.
  std::vector<std::pair<std::size_t, std::size_t>> border, inner;
  for (std::size_t i = 0; i < edges.size();)
  {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j] == edges[i])
    {
      ++j;
    }
    if (j - i == 1)
    {
      border.push_back(edges[i]);
    }
    else if (std::binary_search(contactEdges.begin(), contactEdges.end(), edges[i]))
    {
      inner.push_back(edges[i]);
    }
    i = j;
  }
  const Vec3 normal = triangleAreaVector(
    toVec3(points[origin[0]]), toVec3(points[origin[1]]), toVec3(points[origin[2]]));
  const double nx = std::abs(normal.x), ny = std::abs(normal.y), nz = std::abs(normal.z);
  std::vector<CgalTriangle> result;
  bool ok = false;
  try
  {
    if (nz >= nx && nz >= ny)
    {
      ok = triangulateInProjection<CGAL::Projection_traits_xy_3<Kernel>>(
        points, origin, used, border, inner, result);
    }
    else if (nx >= ny)
    {
      ok = triangulateInProjection<CGAL::Projection_traits_yz_3<Kernel>>(
        points, origin, used, border, inner, result);
    }
    else
    {
      ok = triangulateInProjection<CGAL::Projection_traits_xz_3<Kernel>>(
        points, origin, used, border, inner, result);
    }
  }
  catch (const std::exception&)
  {
    ok = false; // constraints crossing in projection: keep autorefinement's triangles
  }
  if (!ok || result.empty())
  {
    return;
  }
  auto area = [&points](const std::vector<CgalTriangle>& triangles)
  {
    double sum = 0;
    for (const CgalTriangle& t : triangles)
    {
      sum += triangleArea(points[t[0]], points[t[1]], points[t[2]]);
    }
    return sum;
  };
  std::vector<std::size_t> corners;
  for (const CgalTriangle& t : result)
  {
    corners.insert(corners.end(), t.begin(), t.end());
  }
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const double before = area(pieces);
  if (corners == used && std::abs(area(result) - before) <= 1e-9 * before)
  {
    pieces = std::move(result);
  }
}

/// The triangles CGAL's autorefinement works on: those touching another surface, and their
/// neighbours across an edge, so that an intersection point on a shared edge splits both
/// triangles of that edge and no T-junction is left behind.
std::vector<std::size_t> refinementSet(const Surfaces& surfaces, const std::vector<bool>& touching)
{
  std::vector<bool> in = touching;
  for (std::size_t e = 0; e < surfaces.edges.size();)
  {
    std::size_t end = e + 1;
    while (end < surfaces.edges.size() && surfaces.edges[end][0] == surfaces.edges[e][0] &&
      surfaces.edges[end][1] == surfaces.edges[e][1])
    {
      ++end;
    }
    bool any = false;
    for (std::size_t k = e; k < end; ++k)
    {
      any = any || touching[surfaces.edges[k][2]];
    }
    for (std::size_t k = e; any && k < end; ++k)
    {
      in[surfaces.edges[k][2]] = true;
    }
    e = end;
  }
  std::vector<std::size_t> set;
  for (std::size_t i = 0; i < in.size(); ++i)
  {
    if (in[i])
    {
      set.push_back(i);
    }
  }
  return set;
}

} // namespace

bool splitAtContacts(RepairedSoup& soup, const CgalRemeshSettings& settings, CgalRemeshOutput& out,
  CancellationPoll& poll)
{
  Surfaces surfaces = findSurfaces(soup, poll);
  const std::vector<bool> touching = touchingTriangles(soup, surfaces, poll);
  if (std::find(touching.begin(), touching.end(), true) == touching.end())
  {
    return false; // nothing touches, so nothing lies on a closed surface either
  }
  findEdges(soup, surfaces, poll);
  std::vector<std::size_t> set = refinementSet(surfaces, touching);
  std::vector<bool> inSet(soup.triangles.size(), false);
  for (std::size_t i : set)
  {
    inSet[i] = true;
  }

  // The set as a mesh of its own; its first vertices are soup points. Where the set touches
  // itself at a point only (a pinch, which a mesh cannot hold), it grows by the triangles
  // around its points, a few times, and at worst to the whole soup.
  std::vector<std::size_t> localIndex(soup.points.size(), NoOrigin);
  std::vector<std::size_t> globalPoint;
  std::vector<Point> localPoints;
  std::vector<CgalTriangle> localTriangles;
  for (int growth = 0;; ++growth)
  {
    for (std::size_t p : globalPoint)
    {
      localIndex[p] = NoOrigin;
    }
    globalPoint.clear();
    localPoints.clear();
    localTriangles.clear();
    for (std::size_t i : set)
    {
      CgalTriangle local;
      for (std::size_t k = 0; k < 3; ++k)
      {
        const std::size_t p = soup.triangles[i][k];
        if (localIndex[p] == NoOrigin)
        {
          localIndex[p] = localPoints.size();
          localPoints.push_back(soup.points[p]);
          globalPoint.push_back(p);
        }
        local[k] = localIndex[p];
      }
      localTriangles.push_back(local);
    }
    poll.check();
    if (isPolygonMesh(localTriangles, poll))
    {
      break;
    }
    if (set.size() == soup.triangles.size())
    {
      throw Error("the triangles around the contacts do not form a manifold surface");
    }
    set.clear();
    for (std::size_t i = 0; i < soup.triangles.size(); ++i)
    {
      const CgalTriangle& t = soup.triangles[i];
      inSet[i] = growth >= 2 || inSet[i] || localIndex[t[0]] != NoOrigin ||
        localIndex[t[1]] != NoOrigin || localIndex[t[2]] != NoOrigin;
      if (inSet[i])
      {
        set.push_back(i);
      }
    }
  }
  // Points that orientation split where more than two faces met on an edge sit on one place
  // as distinct vertices: CGAL 5.5's autorefinement then meets coincident edges of faces that
  // share no vertex, and binds a reference to a null pointer.
  {
    std::vector<Point> sorted = localPoints;
    std::sort(sorted.begin(), sorted.end());
    if (std::adjacent_find(sorted.begin(), sorted.end()) != sorted.end())
    {
      throw Error("the surfaces touch next to an edge shared by more than two faces");
    }
  }
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(localPoints, PolledTriangles(localTriangles, poll), mesh);
  if (mesh.number_of_faces() != set.size() || mesh.number_of_vertices() != localPoints.size())
  {
    throw Error("the surface mesh lost triangles when it was built from the soup");
  }
  SplitTracking tracking;
  tracking.origin = mesh.add_property_map<FaceIndex, std::size_t>("f:origin", NoOrigin).first;
  tracking.poll = &poll;
  for (std::size_t f = 0; f < set.size(); ++f)
  {
    tracking.origin[FaceIndex(static_cast<Mesh::size_type>(f))] = set[f];
  }
  auto contact = mesh.add_property_map<EdgeIndex, bool>("e:contact", false).first;
  if (!set.empty())
  {
    SplitVisitor visitor;
    visitor.tracking = &tracking;
    PMP::experimental::autorefine(mesh,
      CGAL::parameters::vertex_point_map(PolledPointMap{ &mesh, &poll })
        .edge_is_constrained_map(contact)
        .visitor(visitor));
    poll.check();
  }
  const std::size_t triangleCount = soup.triangles.size() - set.size() + mesh.number_of_faces();
  if (settings.checkTriangleCount && triangleCount != soup.triangles.size())
  {
    try
    {
      settings.checkTriangleCount(triangleCount);
    }
    catch (const Error& e)
    {
      throw OverLimit{ e.what() };
    }
  }

  // The split soup: the soup's points, then the new ones. Autorefinement may create several
  // vertices at one intersection point of one surface (where edges of two surfaces cross):
  // they are merged within each surface, never across surfaces.
  RepairedSoup split;
  split.points = soup.points;
  std::vector<std::size_t> pointOf(mesh.num_vertices(), NoOrigin);
  std::vector<std::size_t> surfaceOfVertex(mesh.num_vertices(), NoOrigin);
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t o = tracking.origin[f];
    if (o >= soup.triangles.size())
    {
      throw Error("autorefinement made a face of unknown origin");
    }
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
    {
      surfaceOfVertex[v] = surfaces.of[o];
    }
  }
  std::vector<VertexIndex> added;
  for (VertexIndex v : mesh.vertices())
  {
    if (static_cast<std::size_t>(v) < globalPoint.size())
    {
      pointOf[v] = globalPoint[v];
    }
    else if (surfaceOfVertex[v] != NoOrigin)
    {
      added.push_back(v);
    }
  }
  std::sort(added.begin(), added.end(),
    [&](VertexIndex a, VertexIndex b)
    {
      return surfaceOfVertex[a] != surfaceOfVertex[b] ? surfaceOfVertex[a] < surfaceOfVertex[b]
                                                      : mesh.point(a) < mesh.point(b);
    });
  for (std::size_t i = 0; i < added.size(); ++i)
  {
    const VertexIndex v = added[i];
    if (i == 0 || surfaceOfVertex[v] != surfaceOfVertex[added[i - 1]] ||
      mesh.point(v) != mesh.point(added[i - 1]))
    {
      split.points.push_back(mesh.point(v));
    }
    pointOf[v] = split.points.size() - 1;
  }

  std::vector<std::size_t> surfaceOf;
  std::vector<bool> piece;
  auto keep = [&](const CgalTriangle& t, std::size_t origin)
  {
    piece.push_back(inSet[origin]);
    split.triangles.push_back(t);
    split.input.push_back(soup.input[origin]);
    split.flipped.push_back(soup.flipped[origin]);
    surfaceOf.push_back(surfaces.of[origin]);
  };
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    if (!inSet[i])
    {
      keep(soup.triangles[i], i);
    }
  }
  for (EdgeIndex e : mesh.edges())
  {
    const std::size_t a = pointOf[mesh.vertex(e, 0)], b = pointOf[mesh.vertex(e, 1)];
    if (contact[e] && a != b)
    {
      split.contactEdges.emplace_back(std::min(a, b), std::max(a, b));
    }
  }
  std::sort(split.contactEdges.begin(), split.contactEdges.end());
  split.contactEdges.erase(
    std::unique(split.contactEdges.begin(), split.contactEdges.end()), split.contactEdges.end());

  // Autorefinement's faces come in an order, and with a triangulation where points are
  // cocircular, that follow heap addresses (its box intersection breaks ties by box
  // address), so they change from run to run. Each split triangle is triangulated again,
  // from values only, and its pieces sorted: the same input always gives the same patches.
  std::vector<std::vector<CgalTriangle>> faceOf(set.size()), piecesOf(set.size());
  std::size_t degenerate = 0;
  for (FaceIndex f : mesh.faces())
  {
    const HalfedgeIndex h = mesh.halfedge(f);
    const CgalTriangle t = { pointOf[mesh.source(h)], pointOf[mesh.target(h)],
      pointOf[mesh.target(mesh.next(h))] };
    const auto k = static_cast<std::size_t>(
      std::lower_bound(set.begin(), set.end(), tracking.origin[f]) - set.begin());
    faceOf[k].push_back(t);
    if (t[0] != t[1] && t[1] != t[2] && t[2] != t[0] &&
      !CGAL::collinear(split.points[t[0]], split.points[t[1]], split.points[t[2]]))
    {
      piecesOf[k].push_back(t);
    }
    else
    {
      ++degenerate;
    }
  }
  std::vector<std::size_t> pieces(soup.triangles.size(), 0);
  for (std::size_t k = 0; k < set.size(); ++k)
  {
    poll.tick();
    std::vector<CgalTriangle>& p = piecesOf[k];
    if (p.size() > 1)
    {
      triangulateCanonically(
        split.points, soup.triangles[set[k]], faceOf[k], split.contactEdges, p);
    }
    sortPieces(p);
    pieces[set[k]] = p.size();
    for (const CgalTriangle& t : p)
    {
      keep(t, set[k]);
    }
  }

  std::vector<ClosedSurface> closed = findClosedSurfaces(soup, surfaces, touching);
  const std::vector<bool> covered = coveredTriangles(split, surfaceOf, piece, soup, closed, poll);
  std::vector<bool> keepTriangle(split.triangles.size());
  for (std::size_t i = 0; i < split.triangles.size(); ++i)
  {
    keepTriangle[i] = !covered[i];
    if (covered[i])
    {
      const CgalTriangle& t = split.triangles[i];
      ++out.coveredTriangles;
      out.coveredArea += triangleArea(split.points[t[0]], split.points[t[1]], split.points[t[2]]);
    }
  }
  if (out.coveredTriangles == 0 && split.contactEdges.empty() &&
    mesh.number_of_faces() == set.size())
  {
    return false; // touching at points or edges the surfaces already have
  }
  keepTriangles(split, keepTriangle);
  out.contactEdges = split.contactEdges.size();
  out.contactSplitTriangles = static_cast<std::size_t>(
    std::count_if(pieces.begin(), pieces.end(), [](std::size_t n) { return n > 1; }));
  if (split.triangles.empty())
  {
    throw Error("every face lies on a closed surface");
  }
  // Dropping covered or degenerate pieces can leave surfaces that meet at one point only (and
  // checking 200,000 triangles takes a tenth of a second, so only then).
  if ((out.coveredTriangles > 0 || degenerate > 0) && !isPolygonMesh(split.triangles, poll))
  {
    out.splitPoints += orientSoup(split);
    if (!isPolygonMesh(split.triangles, poll))
    {
      throw Error("the split triangles do not form a manifold surface");
    }
  }
  soup = std::move(split);
  return true;
}

} // namespace mlr::detail::cgal
