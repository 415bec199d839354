// Private to Core: the boundary between Remeshing.cxx and the translation units of
// mlrCgalRemeshing, the only ones that include CGAL (up to ~45 s and 1.6 GB each to compile,
// so nothing else sees CGAL's headers).
#pragma once

#include "PolygonSoup.h"
#include "Scene.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr::detail
{

/// The input after triangulating its polygons: corners index the input points, each
/// triangle is oriented like its polygon and carries the index of its distinct material.
struct TriangleSoup
{
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> material;
  /// The input polygon each triangle was cut from (empty: each triangle its own).
  std::vector<std::uint32_t> polygon;
};

/// Patches CGAL produced, plus the triangles it refused (to be refined only).
struct CgalRemeshOutput
{
  std::vector<Vec3> points;
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> material; ///< index of the distinct material, per triangle
  /// The refused triangles, oriented like their input polygons, and their points. They are
  /// pieces of input triangles once these were split along contact lines, so they can no
  /// longer be indices into the input.
  std::vector<Vec3> refinePoints;
  TriangleSoup refineOnly;
  std::size_t regions = 0;
  std::size_t fallbackRegions = 0;
  std::size_t degenerateTriangles = 0;
  std::size_t duplicateTriangles = 0;
  std::size_t foldedTriangles = 0; ///< dropped, overlapping a larger polygon in its plane
  std::size_t splitPoints = 0;
  std::size_t contactSplitTriangles = 0; ///< repaired triangles cut along contact lines
  std::size_t contactEdges = 0;          ///< edges of the contact lines, once split
  std::size_t coveredTriangles = 0;      ///< pieces dropped, face to face on a closed surface
  double coveredArea = 0;
  double contactSeconds = 0; ///< finding contacts, splitting, dropping covered
  std::vector<std::string> warnings;
};

struct CgalRemeshSettings
{
  double targetEdgeLength = 0;
  double sharpEdgeAngle = 30;
  /// Faces whose remeshed region area differs from the input by more than this fraction
  /// are refined only.
  double areaTolerance = 0.005;
  /// Split surfaces where they touch or cross each other, and drop what lies face to face on
  /// a closed surface (see remesh() in Remeshing.h).
  bool splitAtContacts = true;
  /// Called with the triangle count once surfaces are split along their contacts, before
  /// anything is allocated for it; may throw mlr::Error (over the memory limit).
  std::function<void(std::size_t triangles)> checkTriangleCount;
};

/**
 * Repairs and orients the triangles, splits them along the lines where surfaces touch or
 * cross, drops the pieces lying face to face on closed surfaces, and isotropically remeshes region
 * by region with the contact lines as constraints. Never lets a CGAL exception escape: what CGAL
 * refuses is listed in refineOnly with a warning (if splitting fails, the surfaces are
 * remeshed unsplit, with a warning).
 * Throws mlr::Cancelled when `progress` returns false, mlr::Error when memory runs out.
 */
CgalRemeshOutput remeshWithCgal(const std::vector<Vec3>& points, const TriangleSoup& soup,
  const std::vector<Material>& materials, const CgalRemeshSettings& settings,
  const std::function<bool(double)>& progress);

} // namespace mlr::detail
