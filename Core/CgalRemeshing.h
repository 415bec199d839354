// Private to Core: the boundary between Remeshing.cxx and the one translation unit that
// includes CGAL (CGAL headers take ~45 s and 1.6 GB to compile, so nothing else sees them).
#pragma once

#include "Remeshing.h"

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
};

/// Patches CGAL produced, plus the input triangles it refused (to be refined only).
struct CgalRemeshOutput
{
  std::vector<Vec3> points;
  std::vector<Triangle> triangles;
  std::vector<std::uint32_t> material; ///< index of the distinct material, per triangle
  std::vector<std::size_t> refineOnly; ///< indices into TriangleSoup::triangles
  std::size_t regions = 0;
  std::size_t fallbackRegions = 0;
  std::size_t degenerateTriangles = 0;
  std::size_t duplicateTriangles = 0;
  std::size_t splitPoints = 0;
  std::vector<std::string> warnings;
};

struct CgalRemeshSettings
{
  double targetEdgeLength = 0;
  double sharpEdgeAngle = 30;
  /// Faces whose remeshed region area differs from the input by more than this fraction
  /// are refined only.
  double areaTolerance = 0.005;
};

/**
 * Repairs, orients and isotropically remeshes the triangles region by region. Never lets a
 * CGAL exception escape: what CGAL refuses is listed in refineOnly with a warning.
 * Throws mlr::Cancelled when `progress` returns false, mlr::Error when memory runs out.
 */
CgalRemeshOutput remeshWithCgal(const std::vector<Vec3>& points, const TriangleSoup& soup,
  const std::vector<Material>& materials, const CgalRemeshSettings& settings,
  const std::function<bool(double)>& progress);

} // namespace mlr::detail
