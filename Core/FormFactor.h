// Exact form factors of polygons, by Lambert's formula.
#pragma once

#include "Vec3.h"

#include <vector>

namespace mlr
{

/**
 * Form factor from a differential area at `point` with unit normal `normal` to a planar
 * polygon, by Lambert's contour integral:
 *   F = 1/(2 pi) * sum_i angle(R_i, R_i+1) * normal . unit(R_i x R_i+1),  R_i = v_i - point.
 * Exact for a polygon wholly in front of the point (no horizon clipping) and unoccluded. The
 * result is positive whichever way the polygon is wound.
 */
double pointToPolygonFormFactor(
  const Vec3& point, const Vec3& normal, const std::vector<Vec3>& polygon);

} // namespace mlr
