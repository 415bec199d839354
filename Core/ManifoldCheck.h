// Private to Core: whether a triangle soup can become a polygon mesh, CGAL's verdict computed
// on flat arrays. CGAL's is_polygon_soup_a_polygon_mesh() keeps the soup's oriented edges in
// a std::set (3,000,000 nodes for 1,000,000 triangles); when a cancellation unwinds through
// it, freeing that set alone took 0.15-0.5 s. Vectors free at once.
#pragma once

#include "CancellationPoll.h"

#include <array>
#include <cstddef>
#include <vector>

namespace mlr::detail
{

using SoupTriangle = std::array<std::size_t, 3>;

/**
 * The verdict of CGAL 5.5's is_polygon_soup_a_polygon_mesh() on triangles, on every input:
 * true for no triangles; false if a triangle repeats a corner, if an oriented edge belongs
 * to two triangles (so also if three or more share an edge), or if the triangles around a
 * corner point form more than one fan (a non-manifold vertex: two cones touching at their
 * tips, say). polygon_soup_to_polygon_mesh() accepts exactly the soups that pass.
 * Calls poll.tick() at every step, so it may throw mlr::Cancelled.
 */
bool isTriangleSoupAPolygonMesh(const std::vector<SoupTriangle>& triangles, CancellationPoll& poll);

/// CGAL's own is_polygon_soup_a_polygon_mesh(), for the tests that compare the two
/// (defined in CgalSoupRepair.cxx, among the translation units that include CGAL).
bool cgalIsPolygonSoupAPolygonMesh(const std::vector<SoupTriangle>& triangles);

} // namespace mlr::detail
