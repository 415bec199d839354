// The patches' bounced light read as a linear function inside each patch, so that final
// gathering sees the light's gradient across a patch instead of only its mean
// (Documentation/Method.md, section 3).
#pragma once

#include "Rgb.h"
#include "Vec3.h"

#include <array>
#include <cstdint>
#include <vector>

namespace mlr
{

/**
 * How a patch's four elements read its bounced light: the patch's value moved along the
 * least-squares gradient from its edge neighbours that lie in its plane and share its
 * reflectance, evaluated at each element's centroid. A corner element (Scene's elements 0, 1,
 * 2 of the patch: corners a, b, c) reads
 *   v + phi sum_i weights[k][i] (v_i - v),
 * the middle one (element 3, whose centroid is the patch's) reads v, and the four have the
 * mean v whatever phi: light moves within a patch, never between patches. phi in [0, 1],
 * channel by channel, is the largest that keeps every element at or above zero. That limiter
 * lets the light fall towards a shadow or a corner, where a patch has neighbours on one side
 * only, but never below nothing; a range limiter (Barth and Jespersen's) stops the gradient
 * at every local minimum, which is where the patches beside an occluder are. A neighbour
 * whose normal is opposite (an inconsistently oriented mesh) is read on its other side. A
 * patch with no such neighbour stays constant.
 */
struct LinearStencil
{
  static constexpr int MaxNeighbours = 3;
  std::array<std::array<double, MaxNeighbours>, 3> weights{};
  std::array<std::uint32_t, MaxNeighbours> neighbour{};
  std::array<bool, MaxNeighbours> flipped{};
  int count = 0;

  /// The four elements' values (corners a, b, c, then the middle) from the patch's value and
  /// its neighbours' (count of them). Each channel has its own phi.
  void elementValues(const Rgb& value, const Rgb* neighbours, Rgb* out) const;
};

/// One stencil per triangle; the normals are unit and the reflectances one per triangle.
std::vector<LinearStencil> linearStencils(const std::vector<Vec3>& points,
  const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<Vec3>& normals,
  const std::vector<Rgb>& reflectance);

} // namespace mlr
