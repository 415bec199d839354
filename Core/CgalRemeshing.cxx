// Contact splitting and isotropic remeshing with CGAL. The only translation unit of the
// project that includes CGAL: its headers take ~45 s and 1.6 GB to compile, and its
// -frounding-math must not reach the solver.
#include "CgalRemeshing.h"

#include "CancellationPoll.h"
#include "Error.h"
#include "ManifoldCheck.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Projection_traits_xy_3.h>
#include <CGAL/Projection_traits_xz_3.h>
#include <CGAL/Projection_traits_yz_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/box_intersection_d.h>
#include <CGAL/boost/graph/helpers.h>

#include <boost/property_map/property_map.hpp>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <new>
#include <numeric>
#include <sstream>

namespace mlr::detail
{

namespace
{
using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Mesh = CGAL::Surface_mesh<Point>;
using VertexIndex = Mesh::Vertex_index;
using HalfedgeIndex = Mesh::Halfedge_index;
using EdgeIndex = Mesh::Edge_index;
using FaceIndex = Mesh::Face_index;
using CgalTriangle = std::array<std::size_t, 3>;
namespace PMP = CGAL::Polygon_mesh_processing;

/// Remeshing passes and tangential relaxation steps per pass. The first pass does most of
/// the splitting or coarsening, the others even out valences and angles. Measured on cubes,
/// rooms and spheres: 5 x 5 keeps the smallest angles near 25-40 degrees at little cost.
constexpr unsigned Iterations = 5;
constexpr unsigned RelaxationSteps = 5;
/// A border vertex whose two border edges turn by more than this stays put. Lower than the
/// sharp-edge angle because rounding a border corner loses area, bending a crease does not.
constexpr double CornerTurnDegrees = 10;
/// Warnings about refused regions beyond this many are summed up in one line.
constexpr std::size_t MaximumRegionWarnings = 10;

constexpr double Pi = 3.14159265358979323846;

/// The triangles CGAL works on, after repair, orientation and splitting along contacts,
/// with where each came from.
struct RepairedSoup
{
  std::vector<Point> points;
  std::vector<CgalTriangle> triangles;
  std::vector<std::size_t> input; ///< index into TriangleSoup::triangles
  std::vector<bool> flipped;      ///< orient_polygon_soup reversed it
  /// Edges (point indices, smaller first, sorted) on lines where surfaces touch or cross:
  /// constraints for remeshing, so that no patch straddles a contact.
  std::vector<std::pair<std::size_t, std::size_t>> contactEdges;
};

/// Connected faces of one material and one orientation with respect to the input, bounded
/// by sharp edges: remeshed as one CGAL surface patch.
struct Region
{
  std::size_t id = 0; ///< over the whole scene, for warnings
  std::uint32_t material = 0;
  bool flipped = false;
  double inputArea = 0;
  std::vector<std::size_t> triangles; ///< indices into RepairedSoup::triangles
};

/// What a remeshing outcome is short of to be kept; empty when it is fine.
using Refusal = std::string;

Point toPoint(const Vec3& p)
{
  return { p.x, p.y, p.z };
}

Vec3 toVec3(const Point& p)
{
  return { p.x(), p.y(), p.z() };
}

double triangleArea(const Point& a, const Point& b, const Point& c)
{
  return 0.5 * length(triangleAreaVector(toVec3(a), toVec3(b), toVec3(c)));
}

std::string countOf(std::size_t n, const std::string& noun)
{
  return std::to_string(n) + " " + noun + (n == 1 ? "" : "s");
}

std::string describe(const Rgb& c)
{
  std::ostringstream s;
  s << "(" << c.r << ", " << c.g << ", " << c.b << ")";
  return s.str();
}

std::string describeRegion(const Region& region, const std::vector<Material>& materials)
{
  std::ostringstream s;
  s << "region " << region.id << " (reflectance " << describe(materials[region.material].reflectance)
    << ", " << countOf(region.triangles.size(), "input triangle") << ")";
  return s.str();
}

void checkProgress(const std::function<bool(double)>& progress, double fraction)
{
  if (progress && !progress(fraction))
  {
    throw Cancelled();
  }
}

/// The mesh's vertex points, with a cancellation point at every read and write: CGAL's
/// isotropic remeshing reads points in all its steps (split, collapse, flip, relaxation,
/// projection), so it can be stopped within one pass, which on a 200,000-triangle surface
/// takes over a second. mlr::Cancelled then unwinds through CGAL; the mesh being remeshed is
/// thrown away.
struct PolledPointMap
{
  using key_type = VertexIndex;
  using value_type = Point;
  using reference = const Point&;
  using category = boost::read_write_property_map_tag;

  Mesh* mesh = nullptr;
  CancellationPoll* poll = nullptr;

  friend const Point& get(const PolledPointMap& map, VertexIndex v)
  {
    map.poll->tick();
    return map.mesh->point(v);
  }
  friend void put(const PolledPointMap& map, VertexIndex v, const Point& p)
  {
    map.poll->tick();
    map.mesh->point(v) = p;
  }
};

/// The soup's triangles as CGAL's soup functions read them (by index and by iteration), with
/// a cancellation point at every read: polygon_soup_to_polygon_mesh() runs for about a
/// second on 1,000,000 triangles, in one call. It reads the same triangles in the same order,
/// so its result is unchanged.
class PolledTriangles
{
public:
  using value_type = CgalTriangle;
  using size_type = std::size_t;
  using difference_type = std::ptrdiff_t;
  using reference = const CgalTriangle&;
  using const_reference = const CgalTriangle&;

  class const_iterator
  {
  public:
    using iterator_category = std::forward_iterator_tag;
    using value_type = CgalTriangle;
    using difference_type = std::ptrdiff_t;
    using pointer = const CgalTriangle*;
    using reference = const CgalTriangle&;

    const_iterator(const CgalTriangle* at, CancellationPoll* poll)
      : At(at)
      , Poll(poll)
    {
    }
    reference operator*() const
    {
      this->Poll->tick();
      return *this->At;
    }
    pointer operator->() const { return &**this; }
    const_iterator& operator++()
    {
      ++this->At;
      return *this;
    }
    const_iterator operator++(int)
    {
      const_iterator before = *this;
      ++this->At;
      return before;
    }
    bool operator==(const const_iterator& o) const { return this->At == o.At; }
    bool operator!=(const const_iterator& o) const { return this->At != o.At; }

  private:
    const CgalTriangle* At;
    CancellationPoll* Poll;
  };
  using iterator = const_iterator;

  PolledTriangles(const std::vector<CgalTriangle>& triangles, CancellationPoll& poll)
    : Triangles(&triangles)
    , Poll(&poll)
  {
  }
  std::size_t size() const { return this->Triangles->size(); }
  bool empty() const { return this->Triangles->empty(); }
  const CgalTriangle& operator[](std::size_t i) const
  {
    this->Poll->tick();
    return (*this->Triangles)[i];
  }
  const_iterator begin() const { return { this->Triangles->data(), this->Poll }; }
  const_iterator end() const { return { this->Triangles->data() + this->Triangles->size(), this->Poll }; }

private:
  const std::vector<CgalTriangle>* Triangles;
  CancellationPoll* Poll;
};

/// CGAL's is_polygon_soup_a_polygon_mesh() verdict, computed on flat arrays: CGAL's own
/// keeps every oriented edge in a std::set, and a cancellation unwinding through it spent
/// 0.15-0.5 s freeing 3,000,000 nodes (1,000,000 triangles). See ManifoldCheck.h.
bool isPolygonMesh(const std::vector<CgalTriangle>& triangles, CancellationPoll& poll)
{
  return isTriangleSoupAPolygonMesh(triangles, poll);
}

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

/// A face property map with a cancellation point at every write, for connected_components()
/// (which labels every face of a mesh in one call).
struct PolledFaceMap
{
  using key_type = FaceIndex;
  using value_type = std::size_t;
  using reference = std::size_t&;
  using category = boost::read_write_property_map_tag;

  Mesh::Property_map<FaceIndex, std::size_t> map;
  CancellationPoll* poll = nullptr;

  friend std::size_t get(const PolledFaceMap& m, FaceIndex f) { return m.map[f]; }
  friend void put(const PolledFaceMap& m, FaceIndex f, std::size_t value)
  {
    m.poll->tick();
    m.map[f] = value;
  }
};

// ---------------------------------------------------------------------------------------
// Soup repair. repair_polygon_soup() would reorder the triangles and lose their materials,
// so its steps run one by one, keeping track of where every triangle came from.

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
  std::sort(sorted.begin(), sorted.end(), [&poll](const auto& a, const auto& b) {
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

/// orient_polygon_soup() may reverse triangles and duplicates points where the surface is
/// not a manifold; it keeps the triangles' order and the existing points. A reversal adds to
/// any earlier one.
std::size_t orientSoup(RepairedSoup& soup)
{
  const std::vector<CgalTriangle> before = soup.triangles;
  const std::size_t pointsBefore = soup.points.size();
  PMP::orient_polygon_soup(soup.points, soup.triangles);
  soup.flipped.resize(soup.triangles.size(), false);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    soup.flipped[i] = soup.flipped[i] != !sameCyclicOrder(before[i], soup.triangles[i], soup.points);
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

// ---------------------------------------------------------------------------------------
// Contact lines. Where a surface touches or crosses another (a block standing on a floor, a
// panel through a wall), a patch on both sides of the line would average the lit side with
// the shadowed one, and light would leak across it. The soup is split along these lines
// first (CGAL's autorefinement: exact predicates, intersection points rounded once), and the
// lines become remeshing constraints.

constexpr std::size_t NoOrigin = std::numeric_limits<std::size_t>::max();

/// Triangles and their AABB tree, for distances here and projection in remeshing below.
using TriangleList = std::vector<Kernel::Triangle_3>;
using TreePrimitive = CGAL::AABB_triangle_primitive<Kernel, TriangleList::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, TreePrimitive>>;

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
  std::vector<bool> closed;    ///< every edge shared by two triangles
  /// (smaller point, larger point, triangle) for every triangle edge, sorted.
  std::vector<std::array<std::size_t, 3>> edges;
};

Surfaces findSurfaces(const RepairedSoup& soup, CancellationPoll& poll)
{
  // Union-find over points.
  std::vector<std::size_t> parent(soup.points.size());
  std::iota(parent.begin(), parent.end(), std::size_t(0));
  auto root = [&parent](std::size_t p) {
    while (parent[p] != p)
    {
      parent[p] = parent[parent[p]];
      p = parent[p];
    }
    return p;
  };
  for (const CgalTriangle& t : soup.triangles)
  {
    poll.tick();
    for (int k = 1; k < 3; ++k)
    {
      const std::size_t a = root(t[0]), b = root(t[static_cast<std::size_t>(k)]);
      parent[std::max(a, b)] = std::min(a, b);
    }
  }
  Surfaces s;
  std::vector<std::size_t> index(soup.points.size(), NoOrigin);
  s.of.resize(soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    std::size_t& surface = index[root(soup.triangles[i][0])];
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
  std::sort(s.edges.begin(), s.edges.end(), [&poll](const auto& a, const auto& b) {
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
std::vector<bool> touchingTriangles(const RepairedSoup& soup, const Surfaces& surfaces, CancellationPoll& poll)
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
    boxes.emplace_back(soup.points[t[0]].bbox() + soup.points[t[1]].bbox() + soup.points[t[2]].bbox(), i);
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
    [&](const TriangleBox& triangle, const TriangleBox& surface) {
      poll.tick();
      candidate[triangle.info()] = candidate[triangle.info()] || surfaces.of[triangle.info()] != surface.info();
    });
  boxes.erase(std::remove_if(boxes.begin(), boxes.end(), [&](const TriangleBox& b) { return !candidate[b.info()]; }),
    boxes.end());
  CGAL::box_self_intersection_d(boxes.begin(), boxes.end(), [&](const TriangleBox& a, const TriangleBox& b) {
    poll.tick();
    const std::size_t i = a.info(), j = b.info();
    if (surfaces.of[i] == surfaces.of[j] || (touching[i] && touching[j]))
    {
      return;
    }
    const CgalTriangle &s = soup.triangles[i], &t = soup.triangles[j];
    if (CGAL::do_intersect(Kernel::Triangle_3(soup.points[s[0]], soup.points[s[1]], soup.points[s[2]]),
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
      const CGAL::Bbox_3 box = soup.points[t[0]].bbox() + soup.points[t[1]].bbox() + soup.points[t[2]].bbox();
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
    const double diagonal = std::sqrt(CGAL::square(b.xmax() - b.xmin()) + CGAL::square(b.ymax() - b.ymin()) +
      CGAL::square(b.zmax() - b.zmin()));
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
std::vector<bool> coveredTriangles(const RepairedSoup& split, const std::vector<std::size_t>& surfaceOf,
  const std::vector<bool>& piece, const RepairedSoup& original, std::vector<ClosedSurface>& closed,
  CancellationPoll& poll)
{
  std::vector<bool> covered(split.triangles.size(), false);
  std::vector<TriangleBox> closedBoxes;
  for (std::size_t s = 0; s < closed.size(); ++s)
  {
    if (!closed[s].triangles.empty())
    {
      const double t = closed[s].tolerance;
      const CGAL::Bbox_3& b = closed[s].box;
      closedBoxes.emplace_back(
        CGAL::Bbox_3(b.xmin() - t, b.ymin() - t, b.zmin() - t, b.xmax() + t, b.ymax() + t, b.zmax() + t), s);
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
  CGAL::box_intersection_d(centroids.begin(), centroids.end(), closedBoxes.begin(), closedBoxes.end(),
    [&](const TriangleBox& triangle, const TriangleBox& closedBox) {
      poll.tick();
      const std::size_t i = triangle.info();
      ClosedSurface& surface = closed[closedBox.info()];
      if (surfaceOf[i] != closedBox.info() && !covered[i])
      {
        covered[i] = distanceTree(surface, original).squared_distance(centroidOf[i]) <= CGAL::square(surface.tolerance);
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
  const std::vector<std::size_t>& used, const std::vector<std::pair<std::size_t, std::size_t>>& border,
  const std::vector<std::pair<std::size_t, std::size_t>>& inner, std::vector<CgalTriangle>& result)
{
  using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<std::size_t, Projection>;
  using FaceBase = CGAL::Constrained_triangulation_face_base_2<Projection,
    CGAL::Triangulation_face_base_with_info_2<bool, Projection>>;
  using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
  using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Projection, Tds, CGAL::No_constraint_intersection_tag>;
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
  auto handle = [&](std::size_t point) {
    return vertex[static_cast<std::size_t>(std::lower_bound(used.begin(), used.end(), point) - used.begin())];
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
  const std::vector<CgalTriangle>& faces, const std::vector<std::pair<std::size_t, std::size_t>>& contactEdges,
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
  const Vec3 normal = triangleAreaVector(toVec3(points[origin[0]]), toVec3(points[origin[1]]), toVec3(points[origin[2]]));
  const double nx = std::abs(normal.x), ny = std::abs(normal.y), nz = std::abs(normal.z);
  std::vector<CgalTriangle> result;
  bool ok = false;
  try
  {
    if (nz >= nx && nz >= ny)
    {
      ok = triangulateInProjection<CGAL::Projection_traits_xy_3<Kernel>>(points, origin, used, border, inner, result);
    }
    else if (nx >= ny)
    {
      ok = triangulateInProjection<CGAL::Projection_traits_yz_3<Kernel>>(points, origin, used, border, inner, result);
    }
    else
    {
      ok = triangulateInProjection<CGAL::Projection_traits_xz_3<Kernel>>(points, origin, used, border, inner, result);
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
  auto area = [&points](const std::vector<CgalTriangle>& triangles) {
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

/// A limit the caller set was exceeded: not derived from std::exception, so that guarded()
/// does not take it for a CGAL failure.
struct OverLimit
{
  std::string message;
};

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

/**
 * Splits the soup along the lines where triangles of different surfaces touch or cross, and
 * drops the pieces lying face to face on closed surfaces. Only the triangles near a contact go through
 * CGAL's autorefinement (it takes seconds on 200,000 triangles); the rest are kept as they
 * are. Returns false, leaving the soup unchanged, when nothing touches. CGAL may throw: the
 * caller guards this.
 */
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
      inSet[i] = growth >= 2 || inSet[i] || localIndex[t[0]] != NoOrigin || localIndex[t[1]] != NoOrigin ||
        localIndex[t[2]] != NoOrigin;
      if (inSet[i])
      {
        set.push_back(i);
      }
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
  std::sort(added.begin(), added.end(), [&](VertexIndex a, VertexIndex b) {
    return surfaceOfVertex[a] != surfaceOfVertex[b] ? surfaceOfVertex[a] < surfaceOfVertex[b]
                                                    : mesh.point(a) < mesh.point(b);
  });
  for (std::size_t i = 0; i < added.size(); ++i)
  {
    const VertexIndex v = added[i];
    if (i == 0 || surfaceOfVertex[v] != surfaceOfVertex[added[i - 1]] || mesh.point(v) != mesh.point(added[i - 1]))
    {
      split.points.push_back(mesh.point(v));
    }
    pointOf[v] = split.points.size() - 1;
  }

  std::vector<std::size_t> surfaceOf;
  std::vector<bool> piece;
  auto keep = [&](const CgalTriangle& t, std::size_t origin) {
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
  split.contactEdges.erase(std::unique(split.contactEdges.begin(), split.contactEdges.end()), split.contactEdges.end());

  // Autorefinement's faces come in an order, and with a triangulation where points are
  // cocircular, that follow heap addresses (its box intersection breaks ties by box
  // address), so they change from run to run. Each split triangle is triangulated again,
  // from values only, and its pieces sorted: the same input always gives the same patches.
  std::vector<std::vector<CgalTriangle>> faceOf(set.size()), piecesOf(set.size());
  std::size_t degenerate = 0;
  for (FaceIndex f : mesh.faces())
  {
    const HalfedgeIndex h = mesh.halfedge(f);
    const CgalTriangle t = { pointOf[mesh.source(h)], pointOf[mesh.target(h)], pointOf[mesh.target(mesh.next(h))] };
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
      triangulateCanonically(split.points, soup.triangles[set[k]], faceOf[k], split.contactEdges, p);
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
  if (out.coveredTriangles == 0 && split.contactEdges.empty() && mesh.number_of_faces() == set.size())
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

// ---------------------------------------------------------------------------------------
// Components: each connected surface is remeshed in a mesh of its own, so that a failure
// costs only that surface.

std::vector<std::vector<std::size_t>> connectedComponents(const RepairedSoup& soup, CancellationPoll& poll)
{
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(soup.points, PolledTriangles(soup.triangles, poll), mesh);
  if (mesh.number_of_faces() != soup.triangles.size())
  {
    throw Error("the surface mesh lost triangles when it was built from the soup");
  }
  auto component = mesh.add_property_map<FaceIndex, std::size_t>("f:component", 0).first;
  const std::size_t count = PMP::connected_components(mesh, PolledFaceMap{ component, &poll });
  std::vector<std::vector<std::size_t>> components(count);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    poll.tick();
    // polygon_soup_to_polygon_mesh() adds face i for triangle i of a fresh mesh.
    components[component[FaceIndex(static_cast<Mesh::size_type>(i))]].push_back(i);
  }
  return components;
}

/// The component's triangles as a mesh of their own; face i is soup triangle faces[i], and
/// vertex v is soup point used[v].
Mesh buildComponentMesh(const RepairedSoup& soup, const std::vector<std::size_t>& faces,
  std::vector<std::size_t>& localIndex, std::vector<std::size_t>& used, CancellationPoll& poll)
{
  constexpr std::size_t None = std::numeric_limits<std::size_t>::max();
  std::vector<Point> points;
  used.clear();
  std::vector<CgalTriangle> triangles;
  triangles.reserve(faces.size());
  for (std::size_t f : faces)
  {
    CgalTriangle local;
    for (int k = 0; k < 3; ++k)
    {
      const std::size_t global = soup.triangles[f][static_cast<std::size_t>(k)];
      if (localIndex[global] == None)
      {
        localIndex[global] = points.size();
        points.push_back(soup.points[global]);
        used.push_back(global);
      }
      local[static_cast<std::size_t>(k)] = localIndex[global];
    }
    triangles.push_back(local);
  }
  for (std::size_t global : used)
  {
    localIndex[global] = None; // ready for the next component
  }
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(points, PolledTriangles(triangles, poll), mesh);
  return mesh;
}

// ---------------------------------------------------------------------------------------
// Regions, constraints and corners of one component mesh.

struct ComponentLayout
{
  Mesh::Property_map<FaceIndex, std::size_t> region;
  Mesh::Property_map<EdgeIndex, bool> constrained;
  Mesh::Property_map<VertexIndex, bool> corner;
  std::vector<Region> regions;
};

/// Sharp edges, edges between materials or orientations, contact lines and the mesh border.
Mesh::Property_map<EdgeIndex, bool> markConstrainedEdges(Mesh& mesh, const RepairedSoup& soup,
  const TriangleSoup& input, const std::vector<std::size_t>& faces,
  const std::vector<std::size_t>& pointOfVertex, double sharpEdgeAngle)
{
  auto constrained = mesh.add_property_map<EdgeIndex, bool>("e:constrained", false).first;
  PMP::detect_sharp_edges(mesh, sharpEdgeAngle, constrained);
  for (EdgeIndex e : mesh.edges())
  {
    const std::size_t p = pointOfVertex[mesh.vertex(e, 0)], q = pointOfVertex[mesh.vertex(e, 1)];
    if (mesh.is_border(e) ||
      std::binary_search(soup.contactEdges.begin(), soup.contactEdges.end(), std::make_pair(std::min(p, q), std::max(p, q))))
    {
      constrained[e] = true;
      continue;
    }
    const std::size_t a = faces[mesh.face(mesh.halfedge(e, 0))];
    const std::size_t b = faces[mesh.face(mesh.halfedge(e, 1))];
    if (input.material[soup.input[a]] != input.material[soup.input[b]] ||
      soup.flipped[a] != soup.flipped[b])
    {
      constrained[e] = true;
    }
  }
  return constrained;
}

/// Vertices where constrained edges end, branch or turn: remeshing must not move or remove
/// them, or corners get rounded (CGAL keeps only ends and branches on its own).
Mesh::Property_map<VertexIndex, bool> markCorners(
  Mesh& mesh, const Mesh::Property_map<EdgeIndex, bool>& constrained)
{
  auto corner = mesh.add_property_map<VertexIndex, bool>("v:corner", false).first;
  const double straight = std::cos(CornerTurnDegrees * Pi / 180);
  for (VertexIndex v : mesh.vertices())
  {
    std::vector<VertexIndex> ends;
    for (HalfedgeIndex h : CGAL::halfedges_around_target(v, mesh))
    {
      if (constrained[mesh.edge(h)])
      {
        ends.push_back(mesh.source(h));
      }
    }
    if (ends.empty())
    {
      continue;
    }
    if (ends.size() != 2)
    {
      corner[v] = true;
      continue;
    }
    const Vec3 p = toVec3(mesh.point(v));
    const Vec3 in = p - toVec3(mesh.point(ends[0]));
    const Vec3 out = toVec3(mesh.point(ends[1])) - p;
    corner[v] = dot(in, out) < straight * length(in) * length(out);
  }
  return corner;
}

ComponentLayout layOutComponent(Mesh& mesh, const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<std::size_t>& faces, const std::vector<std::size_t>& pointOfVertex,
  double sharpEdgeAngle, std::size_t firstRegionId)
{
  ComponentLayout layout;
  layout.constrained = markConstrainedEdges(mesh, soup, input, faces, pointOfVertex, sharpEdgeAngle);
  layout.corner = markCorners(mesh, layout.constrained);
  // Contact lines keep every point: both surfaces along a line keep the same polyline, so
  // remeshing opens no crack between them, and a curved line is not cut short.
  for (EdgeIndex e : mesh.edges())
  {
    const std::size_t p = pointOfVertex[mesh.vertex(e, 0)], q = pointOfVertex[mesh.vertex(e, 1)];
    if (std::binary_search(soup.contactEdges.begin(), soup.contactEdges.end(), std::make_pair(std::min(p, q), std::max(p, q))))
    {
      layout.corner[mesh.vertex(e, 0)] = true;
      layout.corner[mesh.vertex(e, 1)] = true;
    }
  }
  layout.region = mesh.add_property_map<FaceIndex, std::size_t>("f:region", 0).first;
  const std::size_t count = PMP::connected_components(
    mesh, layout.region, CGAL::parameters::edge_is_constrained_map(layout.constrained));
  layout.regions.resize(count);
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t s = faces[f];
    Region& region = layout.regions[layout.region[f]];
    region.material = input.material[soup.input[s]];
    region.flipped = soup.flipped[s];
    const CgalTriangle& t = soup.triangles[s];
    region.inputArea += triangleArea(soup.points[t[0]], soup.points[t[1]], soup.points[t[2]]);
    region.triangles.push_back(s);
  }
  for (std::size_t r = 0; r < count; ++r)
  {
    layout.regions[r].id = firstRegionId + r;
  }
  return layout;
}

// ---------------------------------------------------------------------------------------
// Remeshing.


/**
 * Projects moved vertices onto the input triangles of their own region, as CGAL does by
 * default, but onto the input as it was before the first pass: remeshing runs one pass per
 * call (to check for cancellation between passes) and CGAL would otherwise project onto the
 * previous pass's output, drifting off curved input.
 */
class RegionProjection
{
public:
  RegionProjection(const Mesh& mesh, const Mesh::Property_map<FaceIndex, std::size_t>& region,
    std::size_t regionCount)
    : MeshRef(&mesh)
    , RegionMap(region)
    , Triangles(std::make_shared<std::vector<TriangleList>>(regionCount))
    , Trees(std::make_shared<std::vector<std::unique_ptr<Tree>>>())
  {
    for (FaceIndex f : mesh.faces())
    {
      const HalfedgeIndex h = mesh.halfedge(f);
      (*this->Triangles)[region[f]].emplace_back(mesh.point(mesh.source(h)),
        mesh.point(mesh.target(h)), mesh.point(mesh.target(mesh.next(h))));
    }
    for (const TriangleList& triangles : *this->Triangles)
    {
      this->Trees->push_back(std::make_unique<Tree>(triangles.begin(), triangles.end()));
      this->Trees->back()->accelerate_distance_queries();
    }
  }

  Point operator()(VertexIndex v) const
  {
    const Mesh& mesh = *this->MeshRef;
    HalfedgeIndex h = mesh.halfedge(v);
    if (mesh.is_border(h))
    {
      h = mesh.opposite(h);
    }
    const FaceIndex f = mesh.face(h);
    if (f == Mesh::null_face())
    {
      return mesh.point(v);
    }
    return (*this->Trees)[this->RegionMap[f]]->closest_point(mesh.point(v));
  }

private:
  const Mesh* MeshRef;
  Mesh::Property_map<FaceIndex, std::size_t> RegionMap;
  // Shared: CGAL copies the functor.
  std::shared_ptr<std::vector<TriangleList>> Triangles;
  std::shared_ptr<std::vector<std::unique_ptr<Tree>>> Trees;
};

/// One remeshing pass over the whole component; passes run one by one so that progress can
/// be reported and cancellation checked between them.
void remeshPass(Mesh& mesh, ComponentLayout& layout, double h, const RegionProjection& projection,
  CancellationPoll& poll)
{
  PMP::isotropic_remeshing(mesh.faces(), h, mesh,
    CGAL::parameters::number_of_iterations(1)
      .vertex_point_map(PolledPointMap{ &mesh, &poll })
      .face_patch_map(layout.region)
      .edge_is_constrained_map(layout.constrained)
      .vertex_is_constrained_map(layout.corner)
      .protect_constraints(false)
      .collapse_constraints(true)
      .relax_constraints(false)
      .number_of_relaxation_steps(RelaxationSteps)
      .projection_functor(projection));
}

/// Why each region's remeshed faces cannot be kept (empty when they can).
std::vector<Refusal> checkRegions(const Mesh& mesh, const ComponentLayout& layout, double tolerance)
{
  std::vector<double> area(layout.regions.size(), 0.0);
  std::vector<Refusal> refusals(layout.regions.size());
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t r = layout.region[f];
    if (r >= layout.regions.size())
    {
      continue; // cannot happen: CGAL gives new faces their parent's patch
    }
    const HalfedgeIndex h = mesh.halfedge(f);
    const Point& a = mesh.point(mesh.source(h));
    const Point& b = mesh.point(mesh.target(h));
    const Point& c = mesh.point(mesh.target(mesh.next(h)));
    const double faceArea = triangleArea(a, b, c);
    if (!(faceArea > 0) || !std::isfinite(faceArea))
    {
      refusals[r] = "remeshing left a degenerate triangle";
    }
    area[r] += faceArea;
  }
  for (std::size_t r = 0; r < layout.regions.size(); ++r)
  {
    const double input = layout.regions[r].inputArea;
    const double change = (area[r] - input) / input;
    if (refusals[r].empty() && !(std::abs(change) <= tolerance))
    {
      std::ostringstream s;
      s << "remeshing changed its area by " << 100 * change << "% (more than "
        << 100 * tolerance << "%; the patch size may be too large for its curvature)";
      refusals[r] = s.str();
    }
  }
  return refusals;
}

/// Appends the faces of the accepted regions, oriented like their input polygons.
void emitRegions(const Mesh& mesh, const ComponentLayout& layout,
  const std::vector<Refusal>& refusals, CgalRemeshOutput& out)
{
  constexpr std::uint32_t None = std::numeric_limits<std::uint32_t>::max();
  std::vector<std::uint32_t> outputIndex(mesh.num_vertices(), None); // removed ones too
  for (FaceIndex f : mesh.faces())
  {
    const std::size_t r = layout.region[f];
    if (r >= layout.regions.size() || !refusals[r].empty())
    {
      continue;
    }
    Triangle t{};
    int k = 0;
    for (VertexIndex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh))
    {
      std::uint32_t& index = outputIndex[v];
      if (index == None)
      {
        index = static_cast<std::uint32_t>(out.points.size());
        out.points.push_back(toVec3(mesh.point(v)));
      }
      t[static_cast<std::size_t>(k++)] = index;
    }
    if (layout.regions[r].flipped)
    {
      std::swap(t[1], t[2]);
    }
    out.triangles.push_back(t);
    out.material.push_back(layout.regions[r].material);
  }
}

/// Collects the refused regions' triangles, oriented like their input, and says why, up to a
/// few warnings.
void refuseRegion(const Region& region, const RepairedSoup& soup, const TriangleSoup& input,
  const std::string& why, const std::vector<Material>& materials, CgalRemeshOutput& out)
{
  ++out.fallbackRegions;
  for (std::size_t s : region.triangles)
  {
    CgalTriangle t = soup.triangles[s];
    if (soup.flipped[s])
    {
      std::swap(t[1], t[2]);
    }
    const auto first = static_cast<std::uint32_t>(out.refinePoints.size());
    for (std::size_t k : t)
    {
      out.refinePoints.push_back(toVec3(soup.points[k]));
    }
    out.refineOnly.triangles.push_back({ first, first + 1, first + 2 });
    out.refineOnly.material.push_back(input.material[soup.input[s]]);
  }
  if (out.fallbackRegions <= MaximumRegionWarnings)
  {
    out.warnings.push_back(describeRegion(region, materials) + " was only refined, not remeshed: " + why);
  }
}

/**
 * Runs `step`, which calls CGAL. Any exception becomes the reason to refuse the component
 * (CGAL reports failed preconditions as exceptions, or not at all with CGAL_NDEBUG), except
 * running out of memory, which no fallback would survive.
 */
template <typename Step>
bool guarded(const Step& step, std::string& failure)
{
  try
  {
    step();
    return true;
  }
  catch (const Cancelled&)
  {
    throw; // the caller asked to stop: not a CGAL failure
  }
  catch (const std::bad_alloc&)
  {
    throw Error("ran out of memory while remeshing: give a larger patch size or a smaller scene");
  }
  catch (const std::exception& e)
  {
    failure = std::string("CGAL failed (") + e.what() + ")";
    return false;
  }
}

/// Refuses a component whose regions are not known yet, as one region.
void refuseComponent(const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<Material>& materials, const std::vector<std::size_t>& faces,
  const std::string& why, CgalRemeshOutput& out)
{
  Region whole;
  whole.id = out.regions++;
  whole.material = input.material[soup.input[faces.front()]];
  whole.triangles = faces;
  refuseRegion(whole, soup, input, why, materials, out);
}

/// Remeshes one component; what CGAL refuses goes to out.refineOnly with a warning.
/// `afterPass` reports progress outside the guarded CGAL calls, so cancelling is never
/// mistaken for a failure.
void processComponent(const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<Material>& materials, const std::vector<std::size_t>& faces,
  const CgalRemeshSettings& settings, std::vector<std::size_t>& localIndex,
  const std::function<void(double)>& afterPass, CancellationPoll& poll, CgalRemeshOutput& out)
{
  Mesh mesh;
  ComponentLayout layout;
  std::vector<std::size_t> pointOfVertex;
  bool valid = false;
  std::string failure;
  const bool built = guarded(
    [&] {
      mesh = buildComponentMesh(soup, faces, localIndex, pointOfVertex, poll);
      valid = CGAL::is_valid_polygon_mesh(mesh) && CGAL::is_triangle_mesh(mesh);
    },
    failure);
  if (built && !valid)
  {
    failure = "its surface is not a valid triangle mesh after repair";
  }
  poll.check();
  if (!built || !valid ||
    !guarded(
      [&] {
        layout = layOutComponent(mesh, soup, input, faces, pointOfVertex, settings.sharpEdgeAngle, out.regions);
      },
      failure))
  {
    refuseComponent(soup, input, materials, faces, failure, out);
    return;
  }
  out.regions += layout.regions.size();

  poll.check();
  std::unique_ptr<RegionProjection> projection;
  bool ok = guarded(
    [&] { projection = std::make_unique<RegionProjection>(mesh, layout.region, layout.regions.size()); },
    failure);
  for (unsigned pass = 0; ok && pass < Iterations; ++pass)
  {
    poll.check();
    ok = guarded([&] { remeshPass(mesh, layout, settings.targetEdgeLength, *projection, poll); }, failure);
    afterPass(double(pass + 1) / Iterations);
  }
  poll.check();
  std::vector<Refusal> refusals(layout.regions.size(), failure);
  if (ok && guarded([&] { refusals = checkRegions(mesh, layout, settings.areaTolerance); }, failure))
  {
    emitRegions(mesh, layout, refusals, out);
  }
  else
  {
    refusals.assign(layout.regions.size(), failure);
  }
  for (std::size_t r = 0; r < layout.regions.size(); ++r)
  {
    if (!refusals[r].empty())
    {
      refuseRegion(layout.regions[r], soup, input, refusals[r], materials, out);
    }
  }
}

void addRepairWarnings(CgalRemeshOutput& out)
{
  if (out.degenerateTriangles > 0)
  {
    out.warnings.push_back("removed " + countOf(out.degenerateTriangles, "triangle") +
      " that became degenerate when duplicate points were merged");
  }
  if (out.duplicateTriangles > 0)
  {
    out.warnings.push_back("removed " + countOf(out.duplicateTriangles, "duplicate triangle") +
      " (on the same 3 points as an earlier one, whose material was kept)");
  }
  if (out.splitPoints > 0)
  {
    out.warnings.push_back("split " + countOf(out.splitPoints, "point") +
      " where the surface is not a manifold (an edge shared by more than two faces, "
      "faces meeting only at a point, or opposite orientations): the surfaces meeting there "
      "were remeshed separately");
  }
  if (out.fallbackRegions > MaximumRegionWarnings)
  {
    out.warnings.push_back("... and " + countOf(out.fallbackRegions - MaximumRegionWarnings, "more region") +
      " only refined, not remeshed");
  }
}
}

CgalRemeshOutput remeshWithCgal(const std::vector<Vec3>& points, const TriangleSoup& input,
  const std::vector<Material>& materials, const CgalRemeshSettings& settings,
  const std::function<bool(double)>& progress)
{
  CgalRemeshOutput out;
  RepairedSoup soup;
  std::vector<std::vector<std::size_t>> components;
  constexpr double RepairShare = 0.05;
  constexpr double SplitShare = 0.05;
  double reported = 0;
  CancellationPoll poll([&] { return !progress || progress(reported); });
  try
  {
    soup = repairAndOrient(points, input, out, poll);
    poll.check();
    components = connectedComponents(soup, poll);
  }
  catch (const Cancelled&)
  {
    throw;
  }
  catch (const std::bad_alloc&)
  {
    throw Error("ran out of memory while repairing the surface: give a smaller scene");
  }
  catch (const std::exception& e)
  {
    out = CgalRemeshOutput{};
    out.refinePoints = points;
    out.refineOnly = input;
    out.warnings.push_back(std::string("CGAL could not repair the surface (") + e.what() +
      "): all " + countOf(input.triangles.size(), "triangle") + " were only refined, not remeshed");
    return out;
  }
  reported = RepairShare;
  checkProgress(progress, reported);

  if (settings.splitAtContacts)
  {
    RepairedSoup split = soup;
    CgalRemeshOutput counts;
    std::string failure;
    bool ok = false;
    bool changed = false;
    const auto start = std::chrono::steady_clock::now();
    try
    {
      ok = guarded([&] { changed = splitAtContacts(split, settings, counts, poll); }, failure);
    }
    catch (const OverLimit& e)
    {
      throw Error(e.message);
    }
    std::vector<std::vector<std::size_t>> splitComponents;
    ok = ok && (!changed || guarded([&] { splitComponents = connectedComponents(split, poll); }, failure));
    out.contactSeconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (ok && changed)
    {
      soup = std::move(split);
      components = std::move(splitComponents);
      out.contactSplitTriangles = counts.contactSplitTriangles;
      out.contactEdges = counts.contactEdges;
      out.coveredTriangles = counts.coveredTriangles;
      out.coveredArea = counts.coveredArea;
      out.splitPoints += counts.splitPoints;
    }
    else if (!ok)
    {
      out.warnings.push_back("surfaces were not split where they touch or cross (" + failure +
        "): patches may straddle contact lines, where light and shadow then leak");
    }
  }
  reported = RepairShare + SplitShare;
  checkProgress(progress, reported);

  // Progress in proportion to the faces remeshed, checked after every pass, in steps of at
  // least 0.1% so that thousands of tiny components do not flood the caller.
  const double total = static_cast<double>(std::max<std::size_t>(1, soup.triangles.size()));
  double done = 0;
  auto report = [&](double componentFraction) {
    const double fraction = RepairShare + SplitShare + (1 - RepairShare - SplitShare) * componentFraction;
    if (fraction - reported >= 0.001)
    {
      reported = fraction;
      checkProgress(progress, fraction);
    }
  };
  std::vector<std::size_t> localIndex(soup.points.size(), std::numeric_limits<std::size_t>::max());
  for (const std::vector<std::size_t>& faces : components)
  {
    const double share = static_cast<double>(faces.size()) / total;
    auto afterPass = [&](double passFraction) { report(done + share * passFraction); };
    processComponent(soup, input, materials, faces, settings, localIndex, afterPass, poll, out);
    done += share;
  }
  addRepairWarnings(out);
  return out;
}

bool cgalIsPolygonSoupAPolygonMesh(const std::vector<SoupTriangle>& triangles)
{
  return PMP::is_polygon_soup_a_polygon_mesh(triangles);
}

} // namespace mlr::detail
