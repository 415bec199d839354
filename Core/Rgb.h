// An RGB triplet of doubles: reflectance, power (W) or radiosity (W/m^2) per channel.
#pragma once

#include <algorithm>
#include <cmath>

namespace mlr
{

struct Rgb
{
  double r = 0, g = 0, b = 0;

  constexpr Rgb() = default;
  constexpr Rgb(double r_, double g_, double b_)
    : r(r_)
    , g(g_)
    , b(b_)
  {
  }
  constexpr explicit Rgb(double grey)
    : r(grey)
    , g(grey)
    , b(grey)
  {
  }

  constexpr double operator[](int i) const { return i == 0 ? r : (i == 1 ? g : b); }
  double& operator[](int i) { return i == 0 ? r : (i == 1 ? g : b); }

  constexpr Rgb operator+(const Rgb& o) const { return { r + o.r, g + o.g, b + o.b }; }
  constexpr Rgb operator-(const Rgb& o) const { return { r - o.r, g - o.g, b - o.b }; }
  constexpr Rgb operator*(const Rgb& o) const { return { r * o.r, g * o.g, b * o.b }; }
  constexpr Rgb operator*(double s) const { return { r * s, g * s, b * s }; }
  constexpr Rgb operator/(double s) const { return { r / s, g / s, b / s }; }
  Rgb& operator+=(const Rgb& o)
  {
    r += o.r;
    g += o.g;
    b += o.b;
    return *this;
  }
  constexpr bool operator==(const Rgb& o) const { return r == o.r && g == o.g && b == o.b; }
  constexpr bool operator!=(const Rgb& o) const { return !(*this == o); }

  constexpr double maxComponent() const { return std::max(r, std::max(g, b)); }
  constexpr double minComponent() const { return std::min(r, std::min(g, b)); }
  constexpr double sum() const { return r + g + b; }
  bool isFinite() const { return std::isfinite(r) && std::isfinite(g) && std::isfinite(b); }
};

constexpr Rgb operator*(double s, const Rgb& c)
{
  return c * s;
}

/**
 * An RGB triplet stored in single precision, for the results kept per element, side and
 * frame: half the memory of Rgb, and seven significant digits, far below the Monte Carlo
 * noise of any solve (and the precision of the float32 arrays the outputs carry). Arithmetic
 * is done in Rgb; values are rounded once, when stored.
 */
struct PackedRgb
{
  float r = 0, g = 0, b = 0;

  constexpr PackedRgb() = default;
  constexpr explicit PackedRgb(const Rgb& c)
    : r(static_cast<float>(c.r))
    , g(static_cast<float>(c.g))
    , b(static_cast<float>(c.b))
  {
  }
  constexpr operator Rgb() const { return { r, g, b }; }
  PackedRgb& operator+=(const Rgb& o) { return *this = PackedRgb(Rgb(*this) + o); }
};

} // namespace mlr
