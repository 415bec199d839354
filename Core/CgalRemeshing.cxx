// Isotropic remeshing with CGAL. The only translation unit of the project that includes CGAL:
// its headers take ~45 s and 1.6 GB to compile, and its -frounding-math must not reach the
// solver.
#include "CgalRemeshing.h"

#include "CancellationPoll.h"
#include "Error.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/orient_polygon_soup.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_polygon_soup.h>
#include <CGAL/Surface_mesh.h>
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

/// The triangles CGAL works on, after repair and orientation, with where each came from.
struct RepairedSoup
{
  std::vector<Point> points;
  std::vector<CgalTriangle> triangles;
  std::vector<std::size_t> input; ///< index into TriangleSoup::triangles
  std::vector<bool> flipped;      ///< orient_polygon_soup reversed it
};

/// Connected faces of one material and one orientation with respect to the input, bounded
/// by sharp edges: remeshed as one CGAL surface patch.
struct Region
{
  std::size_t id = 0; ///< over the whole scene, for warnings
  std::uint32_t material = 0;
  bool flipped = false;
  double inputArea = 0;
  std::vector<std::size_t> inputTriangles;
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
    << ", " << countOf(region.inputTriangles.size(), "input triangle") << ")";
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

// ---------------------------------------------------------------------------------------
// Soup repair. repair_polygon_soup() would reorder the triangles and lose their materials,
// so its steps run one by one, keeping track of where every triangle came from.

void keepTriangles(RepairedSoup& soup, const std::vector<bool>& keep)
{
  std::size_t kept = 0;
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    if (keep[i])
    {
      soup.triangles[kept] = soup.triangles[i];
      soup.input[kept] = soup.input[i];
      ++kept;
    }
  }
  soup.triangles.resize(kept);
  soup.input.resize(kept);
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
std::size_t removeDuplicateTriangles(RepairedSoup& soup)
{
  std::vector<std::pair<CgalTriangle, std::size_t>> sorted(soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    CgalTriangle key = soup.triangles[i];
    std::sort(key.begin(), key.end());
    sorted[i] = { key, i };
  }
  std::sort(sorted.begin(), sorted.end());
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
/// not a manifold; it keeps the triangles' order and the existing points.
std::size_t orientSoup(RepairedSoup& soup)
{
  const std::vector<CgalTriangle> before = soup.triangles;
  const std::size_t pointsBefore = soup.points.size();
  PMP::orient_polygon_soup(soup.points, soup.triangles);
  soup.flipped.resize(soup.triangles.size());
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    soup.flipped[i] = !sameCyclicOrder(before[i], soup.triangles[i], soup.points);
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
  PMP::merge_duplicate_points_in_polygon_soup(soup.points, soup.triangles);
  poll.check();
  out.degenerateTriangles = removeDegenerateTriangles(soup);
  out.duplicateTriangles = removeDuplicateTriangles(soup);
  PMP::remove_isolated_points_in_polygon_soup(soup.points, soup.triangles);
  poll.check();
  // A soup that already is an oriented manifold mesh (most are) would come out of
  // orient_polygon_soup() unchanged, after a quarter of a second per 200,000 triangles that
  // cannot be interrupted: test for it first, which is several times faster.
  if (PMP::is_polygon_soup_a_polygon_mesh(soup.triangles))
  {
    soup.flipped.assign(soup.triangles.size(), false);
    return soup;
  }
  poll.check();
  out.splitPoints = orientSoup(soup);
  poll.check();
  if (!PMP::is_polygon_soup_a_polygon_mesh(soup.triangles))
  {
    throw Error("the oriented triangles still do not form a manifold surface");
  }
  return soup;
}

// ---------------------------------------------------------------------------------------
// Components: each connected surface is remeshed in a mesh of its own, so that a failure
// costs only that surface.

std::vector<std::vector<std::size_t>> connectedComponents(const RepairedSoup& soup)
{
  Mesh mesh;
  PMP::polygon_soup_to_polygon_mesh(soup.points, soup.triangles, mesh);
  if (mesh.number_of_faces() != soup.triangles.size())
  {
    throw Error("the surface mesh lost triangles when it was built from the soup");
  }
  auto component = mesh.add_property_map<FaceIndex, std::size_t>("f:component", 0).first;
  const std::size_t count = PMP::connected_components(mesh, component);
  std::vector<std::vector<std::size_t>> components(count);
  for (std::size_t i = 0; i < soup.triangles.size(); ++i)
  {
    // polygon_soup_to_polygon_mesh() adds face i for triangle i of a fresh mesh.
    components[component[FaceIndex(static_cast<Mesh::size_type>(i))]].push_back(i);
  }
  return components;
}

/// The component's triangles as a mesh of their own; face i is soup triangle faces[i].
Mesh buildComponentMesh(const RepairedSoup& soup, const std::vector<std::size_t>& faces,
  std::vector<std::size_t>& localIndex)
{
  constexpr std::size_t None = std::numeric_limits<std::size_t>::max();
  std::vector<Point> points;
  std::vector<std::size_t> used;
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
  PMP::polygon_soup_to_polygon_mesh(points, triangles, mesh);
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

/// Sharp edges, edges between materials or orientations, and the mesh border.
Mesh::Property_map<EdgeIndex, bool> markConstrainedEdges(Mesh& mesh, const RepairedSoup& soup,
  const TriangleSoup& input, const std::vector<std::size_t>& faces, double sharpEdgeAngle)
{
  auto constrained = mesh.add_property_map<EdgeIndex, bool>("e:constrained", false).first;
  PMP::detect_sharp_edges(mesh, sharpEdgeAngle, constrained);
  for (EdgeIndex e : mesh.edges())
  {
    if (mesh.is_border(e))
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
  const std::vector<std::size_t>& faces, double sharpEdgeAngle, std::size_t firstRegionId)
{
  ComponentLayout layout;
  layout.constrained = markConstrainedEdges(mesh, soup, input, faces, sharpEdgeAngle);
  layout.corner = markCorners(mesh, layout.constrained);
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
    region.inputTriangles.push_back(soup.input[s]);
  }
  for (std::size_t r = 0; r < count; ++r)
  {
    layout.regions[r].id = firstRegionId + r;
  }
  return layout;
}

// ---------------------------------------------------------------------------------------
// Remeshing.

using TriangleList = std::vector<Kernel::Triangle_3>;
using TreePrimitive = CGAL::AABB_triangle_primitive<Kernel, TriangleList::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, TreePrimitive>>;

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

/// Collects the refused regions' input triangles and says why, up to a few warnings.
void refuseRegion(const Region& region, const std::string& why,
  const std::vector<Material>& materials, CgalRemeshOutput& out)
{
  ++out.fallbackRegions;
  out.refineOnly.insert(out.refineOnly.end(), region.inputTriangles.begin(), region.inputTriangles.end());
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
  for (std::size_t f : faces)
  {
    whole.inputTriangles.push_back(soup.input[f]);
  }
  refuseRegion(whole, why, materials, out);
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
  bool valid = false;
  std::string failure;
  const bool built = guarded(
    [&] {
      mesh = buildComponentMesh(soup, faces, localIndex);
      valid = CGAL::is_valid_polygon_mesh(mesh) && CGAL::is_triangle_mesh(mesh);
    },
    failure);
  if (built && !valid)
  {
    failure = "its surface is not a valid triangle mesh after repair";
  }
  poll.check();
  if (!built || !valid ||
    !guarded([&] { layout = layOutComponent(mesh, soup, input, faces, settings.sharpEdgeAngle, out.regions); },
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
      refuseRegion(layout.regions[r], refusals[r], materials, out);
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
  double reported = 0;
  CancellationPoll poll([&] { return !progress || progress(reported); });
  try
  {
    soup = repairAndOrient(points, input, out, poll);
    poll.check();
    components = connectedComponents(soup);
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
    out.refineOnly.resize(input.triangles.size());
    std::iota(out.refineOnly.begin(), out.refineOnly.end(), std::size_t(0));
    out.warnings.push_back(std::string("CGAL could not repair the surface (") + e.what() +
      "): all " + countOf(input.triangles.size(), "triangle") + " were only refined, not remeshed");
    return out;
  }
  checkProgress(progress, RepairShare);

  // Progress in proportion to the faces remeshed, checked after every pass, in steps of at
  // least 0.1% so that thousands of tiny components do not flood the caller.
  const double total = static_cast<double>(std::max<std::size_t>(1, soup.triangles.size()));
  double done = 0;
  reported = RepairShare;
  auto report = [&](double componentFraction) {
    const double fraction = RepairShare + (1 - RepairShare) * componentFraction;
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

} // namespace mlr::detail
