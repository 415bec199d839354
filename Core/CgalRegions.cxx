// Components and regions: each connected surface is remeshed in a mesh of its own, so that
// a failure costs only that surface, and each of its regions (one material and orientation,
// bounded by sharp edges) as one CGAL surface patch, with its constraints and corners kept.
#include "CgalRemeshingInternal.h"

#include "Error.h"

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/detect_features.h>
#include <CGAL/Polygon_mesh_processing/polygon_soup_to_polygon_mesh.h>
#include <CGAL/boost/graph/helpers.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace mlr::detail::cgal
{
namespace
{

/// A border vertex whose two border edges turn by more than this stays put. Lower than the
/// sharp-edge angle because rounding a border corner loses area, bending a crease does not.
constexpr double CornerTurnDegrees = 10;

constexpr double Pi = 3.14159265358979323846;

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
      std::binary_search(soup.contactEdges.begin(), soup.contactEdges.end(),
        std::make_pair(std::min(p, q), std::max(p, q))))
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

} // namespace

std::vector<std::vector<std::size_t>> connectedComponents(
  const RepairedSoup& soup, CancellationPoll& poll)
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

ComponentLayout layOutComponent(Mesh& mesh, const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<std::size_t>& faces, const std::vector<std::size_t>& pointOfVertex,
  double sharpEdgeAngle, std::size_t firstRegionId)
{
  ComponentLayout layout;
  layout.constrained =
    markConstrainedEdges(mesh, soup, input, faces, pointOfVertex, sharpEdgeAngle);
  layout.corner = markCorners(mesh, layout.constrained);
  // Contact lines keep every point: both surfaces along a line keep the same polyline, so
  // remeshing opens no crack between them, and a curved line is not cut short.
  for (EdgeIndex e : mesh.edges())
  {
    const std::size_t p = pointOfVertex[mesh.vertex(e, 0)], q = pointOfVertex[mesh.vertex(e, 1)];
    if (std::binary_search(soup.contactEdges.begin(), soup.contactEdges.end(),
          std::make_pair(std::min(p, q), std::max(p, q))))
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

} // namespace mlr::detail::cgal
