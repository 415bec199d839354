// A 3-vector of doubles: points, directions and normals in scene space.
#pragma once

#include <cmath>

namespace mlr
{

struct Vec3
{
  double x = 0, y = 0, z = 0;

  constexpr Vec3() = default;
  constexpr Vec3(double x_, double y_, double z_)
    : x(x_)
    , y(y_)
    , z(z_)
  {
  }

  constexpr double operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  double& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }

  constexpr Vec3 operator+(const Vec3& o) const { return { x + o.x, y + o.y, z + o.z }; }
  constexpr Vec3 operator-(const Vec3& o) const { return { x - o.x, y - o.y, z - o.z }; }
  constexpr Vec3 operator-() const { return { -x, -y, -z }; }
  constexpr Vec3 operator*(double s) const { return { x * s, y * s, z * s }; }
  constexpr Vec3 operator/(double s) const { return { x / s, y / s, z / s }; }
  Vec3& operator+=(const Vec3& o)
  {
    x += o.x;
    y += o.y;
    z += o.z;
    return *this;
  }
  Vec3& operator-=(const Vec3& o)
  {
    x -= o.x;
    y -= o.y;
    z -= o.z;
    return *this;
  }
  Vec3& operator*=(double s)
  {
    x *= s;
    y *= s;
    z *= s;
    return *this;
  }
  constexpr bool operator==(const Vec3& o) const { return x == o.x && y == o.y && z == o.z; }
  constexpr bool operator!=(const Vec3& o) const { return !(*this == o); }
};

constexpr Vec3 operator*(double s, const Vec3& v)
{
  return v * s;
}

constexpr double dot(const Vec3& a, const Vec3& b)
{
  return a.x * b.x + a.y * b.y + a.z * b.z;
}

constexpr Vec3 cross(const Vec3& a, const Vec3& b)
{
  return { a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x };
}

inline double length(const Vec3& v)
{
  return std::sqrt(dot(v, v));
}

constexpr double lengthSquared(const Vec3& v)
{
  return dot(v, v);
}

inline Vec3 normalize(const Vec3& v)
{
  return v / length(v);
}

inline bool isFinite(const Vec3& v)
{
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

/// Twice the area vector of a triangle: its direction is the right-hand-rule normal.
constexpr Vec3 triangleAreaVector(const Vec3& a, const Vec3& b, const Vec3& c)
{
  return cross(b - a, c - a);
}

/// Builds an orthonormal basis (t, b) around the unit vector n (Duff et al. 2017).
inline void orthonormalBasis(const Vec3& n, Vec3& t, Vec3& b)
{
  const double sign = std::copysign(1.0, n.z);
  const double a = -1.0 / (sign + n.z);
  const double bb = n.x * n.y * a;
  t = { 1.0 + sign * n.x * n.x * a, sign * bb, -sign * n.x };
  b = { bb, sign + n.y * n.y * a, -n.y };
}

} // namespace mlr
