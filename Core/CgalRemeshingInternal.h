// Private to the translation units of mlrCgalRemeshing (CgalSoupRepair, CgalContacts,
// CgalRegions and CgalRemeshing.cxx), the only ones that include CGAL: the kernel and mesh
// types, the soup they hand on to one another and the helpers they share. The heavy CGAL
// algorithms are included where they run, not here.
#pragma once

#include "CgalRemeshing.h"

#include "CancellationPoll.h"
#include "ManifoldCheck.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <boost/property_map/property_map.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <string>
#include <utility>
#include <vector>

namespace mlr::detail::cgal
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

/// Triangles and their AABB tree, for distances to closed surfaces and projection in remeshing.
using TriangleList = std::vector<Kernel::Triangle_3>;
using TreePrimitive = CGAL::AABB_triangle_primitive<Kernel, TriangleList::const_iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<Kernel, TreePrimitive>>;

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

/// The regions, constrained edges and corners of one component mesh.
struct ComponentLayout
{
  Mesh::Property_map<FaceIndex, std::size_t> region;
  Mesh::Property_map<EdgeIndex, bool> constrained;
  Mesh::Property_map<VertexIndex, bool> corner;
  std::vector<Region> regions;
};

/// A limit the caller set was exceeded: not derived from std::exception, so that guarded()
/// does not take it for a CGAL failure.
struct OverLimit
{
  std::string message;
};

inline Point toPoint(const Vec3& p)
{
  return { p.x, p.y, p.z };
}

inline Vec3 toVec3(const Point& p)
{
  return { p.x(), p.y(), p.z() };
}

inline double triangleArea(const Point& a, const Point& b, const Point& c)
{
  return 0.5 * length(triangleAreaVector(toVec3(a), toVec3(b), toVec3(c)));
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
  const_iterator end() const
  {
    return { this->Triangles->data() + this->Triangles->size(), this->Poll };
  }

private:
  const std::vector<CgalTriangle>* Triangles;
  CancellationPoll* Poll;
};

/// CGAL's is_polygon_soup_a_polygon_mesh() verdict, computed on flat arrays: CGAL's own
/// keeps every oriented edge in a std::set, and a cancellation unwinding through it spent
/// 0.15-0.5 s freeing 3,000,000 nodes (1,000,000 triangles). See ManifoldCheck.h.
inline bool isPolygonMesh(const std::vector<CgalTriangle>& triangles, CancellationPoll& poll)
{
  return isTriangleSoupAPolygonMesh(triangles, poll);
}

// Soup repair (CgalSoupRepair.cxx).

/// Keeps the triangles for which `keep` is true, with their origins, in their order.
void keepTriangles(RepairedSoup& soup, const std::vector<bool>& keep);

/// orient_polygon_soup() may reverse triangles and duplicates points where the surface is
/// not a manifold; it keeps the triangles' order and the existing points. A reversal adds to
/// any earlier one. Returns the number of points added.
std::size_t orientSoup(RepairedSoup& soup);

/// The input with duplicate points merged, degenerate and duplicate triangles and isolated
/// points removed, and oriented; what was removed or split is counted in `out`. Throws when
/// the oriented triangles are still not a manifold surface.
RepairedSoup repairAndOrient(const std::vector<Vec3>& points, const TriangleSoup& input,
  CgalRemeshOutput& out, CancellationPoll& poll);

// Contact lines (CgalContacts.cxx).

/**
 * Splits the soup along the lines where triangles of different surfaces touch or cross, and
 * drops the pieces lying face to face on closed surfaces. Only the triangles near a contact go
 * through CGAL's autorefinement (it takes seconds on 200,000 triangles); the rest are kept as they
 * are. Returns false, leaving the soup unchanged, when nothing touches. CGAL may throw: the
 * caller guards this.
 */
bool splitAtContacts(RepairedSoup& soup, const CgalRemeshSettings& settings, CgalRemeshOutput& out,
  CancellationPoll& poll);

// Components and regions (CgalRegions.cxx).

/// The soup's connected components, each as the indices of its triangles.
std::vector<std::vector<std::size_t>> connectedComponents(
  const RepairedSoup& soup, CancellationPoll& poll);

/// The component's triangles as a mesh of their own; face i is soup triangle faces[i], and
/// vertex v is soup point used[v].
Mesh buildComponentMesh(const RepairedSoup& soup, const std::vector<std::size_t>& faces,
  std::vector<std::size_t>& localIndex, std::vector<std::size_t>& used, CancellationPoll& poll);

/// Marks the constrained edges and corners of a component mesh and finds its regions,
/// numbered from `firstRegionId`.
ComponentLayout layOutComponent(Mesh& mesh, const RepairedSoup& soup, const TriangleSoup& input,
  const std::vector<std::size_t>& faces, const std::vector<std::size_t>& pointOfVertex,
  double sharpEdgeAngle, std::size_t firstRegionId);

} // namespace mlr::detail::cgal
