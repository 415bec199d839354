// A rotation of 3-space as a 3x3 matrix: how a light is turned in one frame.
#pragma once

#include "Vec3.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace mlr
{

struct Rotation
{
  /// The matrix's rows: apply(v) = (row0.v, row1.v, row2.v).
  Vec3 row0{ 1, 0, 0 }, row1{ 0, 1, 0 }, row2{ 0, 0, 1 };

  constexpr Vec3 apply(const Vec3& v) const { return { dot(row0, v), dot(row1, v), dot(row2, v) }; }

  /// The matrix as rows of numbers, for code that holds rotations as arrays.
  std::array<std::array<double, 3>, 3> rows() const
  {
    return { { { row0.x, row0.y, row0.z }, { row1.x, row1.y, row1.z },
      { row2.x, row2.y, row2.z } } };
  }

  bool isIdentity() const
  {
    return row0 == Vec3(1, 0, 0) && row1 == Vec3(0, 1, 0) && row2 == Vec3(0, 0, 1);
  }

  bool isFinite() const
  {
    return mlr::isFinite(row0) && mlr::isFinite(row1) && mlr::isFinite(row2);
  }

  /// The rotation of the unit quaternion (w, x, y, z); the caller normalises it.
  static Rotation fromQuaternion(double w, double x, double y, double z)
  {
    Rotation r;
    r.row0 = { 1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y) };
    r.row1 = { 2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x) };
    r.row2 = { 2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y) };
    return r;
  }

  /**
   * The smallest rotation that takes the unit vector `from` to the unit vector `to`: about
   * from x to, by the angle between them. Opposite vectors have no unique smallest rotation;
   * they get the half turn about an axis perpendicular to `from`.
   */
  static Rotation between(const Vec3& from, const Vec3& to)
  {
    const double c = dot(from, to);
    if (c < -1 + 1e-12)
    {
      Vec3 t, b;
      orthonormalBasis(from, t, b);
      // R = 2 t t^T - I: a half turn about t.
      Rotation r;
      r.row0 = { 2 * t.x * t.x - 1, 2 * t.x * t.y, 2 * t.x * t.z };
      r.row1 = { 2 * t.y * t.x, 2 * t.y * t.y - 1, 2 * t.y * t.z };
      r.row2 = { 2 * t.z * t.x, 2 * t.z * t.y, 2 * t.z * t.z - 1 };
      return r;
    }
    // Rodrigues with v = from x to: R = I + [v]x + [v]x^2 / (1 + c).
    const Vec3 v = cross(from, to);
    const double k = 1 / (1 + c);
    Rotation r;
    r.row0 = { 1 - k * (v.y * v.y + v.z * v.z), k * v.x * v.y - v.z, k * v.x * v.z + v.y };
    r.row1 = { k * v.x * v.y + v.z, 1 - k * (v.x * v.x + v.z * v.z), k * v.y * v.z - v.x };
    r.row2 = { k * v.x * v.z - v.y, k * v.y * v.z + v.x, 1 - k * (v.x * v.x + v.y * v.y) };
    return r;
  }
};

} // namespace mlr
