// Ear-clipping triangulation of a planar simple polygon (convex or concave).
#pragma once

#include "Vec3.h"

#include <array>
#include <cstdint>
#include <vector>

namespace mlr
{

/// Newell's normal of a polygon: its length is twice the polygon's area, its direction the
/// right-hand-rule normal. Robust for concave and slightly non-planar polygons.
Vec3 newellNormal(const std::vector<Vec3>& polygon);

/**
 * Triangulates a planar simple polygon by ear clipping in its own plane.
 *
 * Consecutive duplicate and collinear vertices are dropped. Returns triangles as indices
 * into `polygon`, oriented like the polygon; returns an empty list when the polygon has no
 * area or is not simple (ears run out before the polygon is consumed).
 */
std::vector<std::array<std::uint32_t, 3>> triangulatePolygon(const std::vector<Vec3>& polygon);

} // namespace mlr
