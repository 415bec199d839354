// An RGB triplet of doubles: reflectance, power (W) or radiosity (W/m^2) per channel.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

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

/// Luminance of linear sRGB/Rec. 709 primaries: a luminous efficacy times it gives lumens.
constexpr double luminance(const Rgb& c)
{
  return 0.2126 * c.r + 0.7152 * c.g + 0.0722 * c.b;
}

/**
 * An RGB triplet stored in single precision, for results that are few (a sensor's per frame)
 * and compared with thresholds: seven significant digits. Arithmetic is done in Rgb; values
 * are rounded once, when stored.
 */
struct FloatRgb
{
  float r = 0, g = 0, b = 0;

  constexpr FloatRgb() = default;
  constexpr explicit FloatRgb(const Rgb& c)
    : r(static_cast<float>(c.r))
    , g(static_cast<float>(c.g))
    , b(static_cast<float>(c.b))
  {
  }
  constexpr operator Rgb() const { return { r, g, b }; }
};

/**
 * An RGB triplet stored in 16 bits per channel, for the results kept per element, side and
 * frame (6 bytes where three floats take 12): those results are most of a solve's memory
 * (MemoryPlan). A channel is a non-negative binary float with a 7-bit exponent and a 9-bit
 * mantissa: relative spacing 2^-9, so a value is rounded to within 2^-10 = 0.1% of itself,
 * an order of magnitude below the Monte Carlo noise of any solve's element, and the range is
 * 2^-62 to 2^64, enough for any unit (the solver has none: W per square scene unit). Smaller
 * values are 0, larger ones infinite. Arithmetic is done in Rgb; values are rounded once, when
 * stored, to nearest, so rounding has no bias beyond a fraction of its own 0.1%. A stored
 * value read and stored again keeps its bits, so copies, blends of one estimate and sums of
 * one value and zeros are exact.
 */
struct PackedRgb
{
  /// The largest relative rounding of a stored value: a sum of stored values is within this
  /// share of the sum of the exact ones.
  static constexpr double RelativeRounding = 0x1.0p-10;

  std::uint16_t r = 0, g = 0, b = 0;

  constexpr PackedRgb() = default;
  explicit PackedRgb(const Rgb& c)
    : r(encode(c.r))
    , g(encode(c.g))
    , b(encode(c.b))
  {
  }
  operator Rgb() const { return { decode(r), decode(g), decode(b) }; }

  /// The code of the non-negative `value` rounded to nearest (NaN stays NaN; negative values,
  /// which no result has, are 0).
  static std::uint16_t encode(double value)
  {
    if (!(value > 0))
    {
      return value == value ? 0 : NotANumber;
    }
    std::uint64_t bits;
    std::memcpy(&bits, &value, sizeof bits);
    // Rounds the 52-bit mantissa to 9 bits; a carry moves into the exponent, as it should.
    const std::uint64_t rounded = (bits + (std::uint64_t(1) << 42)) >> 43;
    if (rounded < Lowest)
    {
      return 0;
    }
    return rounded - Offset >= Infinity ? Infinity : static_cast<std::uint16_t>(rounded - Offset);
  }
  /// The code's exponent and mantissa placed in a float's, offset so that exponent 127 lands
  /// on the float's infinity and NaN, then scaled exactly by 2^-64; code 0 is masked to 0.
  /// Without a branch: rows of frames mix zeros and values, and a branch on them mispredicts
  /// (gathering took 1.5 times as long with one).
  static double decode(std::uint16_t code)
  {
    const std::uint32_t bits = ((std::uint32_t(code) << 14) + (std::uint32_t(128) << 23)) &
      (0u - static_cast<std::uint32_t>(code != 0));
    float value;
    std::memcpy(&value, &bits, sizeof value);
    return static_cast<double>(value * 0x1.0p-64f);
  }

private:
  /// The double exponent of code exponent 0 (bias 1023 against 63), in mantissa units.
  static constexpr std::uint64_t Offset = std::uint64_t(1023 - 63) << 9;
  /// The smallest code kept: exponent 1, 2^-62; below it, 0.
  static constexpr std::uint64_t Lowest = Offset + (std::uint64_t(1) << 9);
  static constexpr std::uint16_t Infinity = 127 << 9;
  static constexpr std::uint16_t NotANumber = Infinity | 1;
};

} // namespace mlr
