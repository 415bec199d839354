// From any polygonal surface with per-polygon materials to the solver's patches.
#pragma once

#include "PolygonSoup.h"
#include "Scene.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace mlr
{

struct RemeshOptions
{
  /// h: target patch edge length. 0 derives it from targetPatchCount.
  double targetEdgeLength = 0;
  /// Patches aimed at when targetEdgeLength is 0.
  std::size_t targetPatchCount = 3000;
  /// Edges whose dihedral angle exceeds this (degrees) are kept as sharp features.
  double sharpEdgeAngle = 30;
  /// Remesh with CGAL; when false every region is only refined (split to size).
  bool useCgal = true;
  /// Split surfaces along the lines where they touch or cross (a block standing on a floor,
  /// a panel through a wall) and drop what lies face to face on a closed surface, so that no
  /// patch straddles a contact (CGAL only).
  bool splitAtContacts = true;
  /// Refuse (mlr::Error) a remeshing whose memory estimate exceeds this many bytes, before
  /// allocating it; 0 means half of the physical memory, as for the solver.
  std::uint64_t memoryLimitBytes = 0;
  /// Called once the polygons are triangulated and duplicates dropped, before CGAL or
  /// refinement allocate anything, with the number of patches expected; it may throw (e.g.
  /// mlr::Error when a solve of that many patches would not fit) to stop before the work.
  std::function<void(std::size_t expectedPatches)> checkExpectedPatches;
};

struct RemeshStatistics
{
  std::size_t inputPolygons = 0;
  std::size_t inputTriangles = 0;   ///< after triangulating the polygons
  std::size_t droppedPolygons = 0;  ///< fewer than 3 points, duplicate, zero area or self-crossing
  std::size_t removedTriangles = 0; ///< degenerate or duplicate once duplicate points merged
  /// Connected faces of one material and orientation, bounded by sharp edges (CGAL only).
  std::size_t regions = 0;
  std::size_t fallbackRegions = 0; ///< regions CGAL refused, refined only (with a warning)
  /// Triangles (after repair) cut along the lines where other surfaces touch or cross them.
  std::size_t contactSplitTriangles = 0;
  /// Pieces dropped because they lie face to face on a closed surface (the floor under a
  /// block), and their area: outputArea is about inputArea - coveredArea.
  std::size_t coveredTriangles = 0;
  double coveredArea = 0;
  std::size_t patches = 0;
  double targetEdgeLength = 0; ///< the h actually used
  double inputArea = 0;        ///< of the triangulated polygons that were kept
  double outputArea = 0;       ///< of the patches
  double seconds = 0;          ///< wall-clock time of remesh(); callers copy it to secondsRemeshing
  double secondsContacts = 0;  ///< of which finding contacts, splitting and dropping covered pieces
};

/// remesh() warns when it keeps more than this many times the patches its patch size aims at.
constexpr double ManyMorePatchesThanAimed = 4;

struct RemeshResult
{
  PatchMesh mesh;
  RemeshStatistics statistics;
  std::vector<std::string> warnings;
};

/// Receives the fraction done in [0, 1]; return false to cancel (mlr::Cancelled is thrown).
using RemeshProgress = std::function<bool(double fraction)>;

/**
 * Turns a polygon soup into well-shaped triangular patches of about edge length h, each with
 * exactly one material. Throws mlr::Error for input that cannot give a scene (NaN/Inf
 * points, no polygon with area, bad indices, mismatched materials) and mlr::Cancelled.
 * Recoverable oddities (dropped polygons, regions only refined) become warnings.
 *
 * With CGAL, polygons are triangulated, duplicate points merged, degenerate and duplicate
 * triangles removed, and the soup oriented (points are split where it is not a manifold).
 *
 * Contact lines (splitAtContacts): surfaces are then split where they touch or cross one
 * another (CGAL's autorefinement, exact predicates), so that a floor is cut along the
 * footprint of a block standing on it and a wall along the line where a panel passes
 * through it; these lines are kept as constraints by the remeshing below, so no patch, and
 * no element, straddles a contact and averages light with shadow there. Every point of a
 * contact line stays, so that both surfaces keep the same polyline and no crack opens between
 * them; a finely tessellated curved object crossing a surface thus adds small patches along
 * the line (a 200,000-triangle sphere crossing a floor at h = 0.12: about 9,000 patches where
 * 5,400 were aimed at). Pieces that lie face to face on a closed surface (the floor under a
 * closed block) are dropped: one side faces into the closed surface and receives no light,
 * the other coincides with the closed surface's own face, and rays would hit both at the same
 * distance. The closed surface is
 * kept whole, so it stays closed; where two closed surfaces touch face to face (stacked
 * boxes) both contact faces go and one closed surface remains around both. What lies inside a
 * closed surface without touching it is kept: surfaces are two-sided, so a closed box may be
 * a room as well as a solid block, and only the light's position could tell (the floor inside
 * an open box, without a bottom face, is also kept, as a region of its own). A polygon lying
 * on a closed object's face (a label on a box) is therefore dropped, the object's material
 * showing there. If CGAL fails to split, the surfaces are remeshed unsplit, with a warning.
 *
 * Each region is then isotropically remeshed with its border, sharp edges, contact lines
 * and corners kept, its vertices projected onto its own input triangles. Every patch keeps
 * the orientation of the polygon it lies on. A region whose remeshing fails or changes its
 * area by more than 0.5% keeps its input triangles (cut along the contact lines), only
 * refined.
 *
 * The same soup and options give the same patches, bit for bit, in any process: nothing
 * depends on addresses, time or the heap. Autorefinement's pieces, whose order and
 * triangulation follow box addresses inside CGAL, are triangulated again from their points
 * and sorted (a split triangle whose pieces rounding bends too far to be triangulated in a
 * plane keeps CGAL's triangulation, only sorted).
 */
RemeshResult remesh(
  const PolygonSoup& soup, const RemeshOptions& options, const RemeshProgress& progress = {});

/// The h at which remeshing cuts `area` into about `patches` patches (a little more than the
/// side of `patches` equilateral triangles covering it).
double edgeLengthForPatchCount(double area, std::size_t patches);

} // namespace mlr
