// Counter-based random streams and the sampling routines built on them.
//
// Every path, and every gathering ray set, draws from its own stream keyed by
// (seed, purpose, a, b). A stream's numbers therefore depend only on its key, never on
// which thread runs it or in which order: that is what makes a solve bit-identical
// whatever the thread count.
#pragma once

#include "Vec3.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace mlr
{

/// What a stream is used for, so that shooting and gathering never share numbers.
enum class StreamPurpose : std::uint64_t
{
  Shooting = 1,
  Gathering = 2,
};

/// SplitMix64 (Steele, Lea, Flood 2014): a 64-bit state advanced by a Weyl step and
/// finalised by a strong mixer. Small, fast and statistically sound for Monte Carlo.
class RandomStream
{
public:
  RandomStream(std::uint64_t seed, StreamPurpose purpose, std::uint64_t a, std::uint64_t b = 0)
  {
    std::uint64_t k = mix(seed + 0x243f6a8885a308d3ULL);
    k = mix(k ^ (static_cast<std::uint64_t>(purpose) * 0x13198a2e03707344ULL));
    k = mix(k ^ (a + 0xa4093822299f31d0ULL));
    this->State = mix(k ^ (b + 0x082efa98ec4e6c89ULL));
  }

  std::uint64_t nextBits()
  {
    this->State += 0x9e3779b97f4a7c15ULL;
    return mix(this->State);
  }

  /// Uniform in [0, 1).
  double uniform() { return static_cast<double>(this->nextBits() >> 11) * 0x1.0p-53; }

private:
  static std::uint64_t mix(std::uint64_t z)
  {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  std::uint64_t State;
};

/// A cosine-distributed direction around the unit normal n (pdf cos(theta)/pi).
inline Vec3 sampleCosineDirection(const Vec3& n, double u1, double u2)
{
  constexpr double twoPi = 6.283185307179586476925286766559;
  const double r = std::sqrt(u1);
  const double phi = twoPi * u2;
  Vec3 t, b;
  orthonormalBasis(n, t, b);
  const double z = std::sqrt(std::max(0.0, 1.0 - u1));
  return t * (r * std::cos(phi)) + b * (r * std::sin(phi)) + n * z;
}

/// A uniformly distributed point on triangle (a, b, c).
inline Vec3 sampleTriangle(const Vec3& a, const Vec3& b, const Vec3& c, double u1, double u2)
{
  const double su = std::sqrt(u1);
  const double wa = 1.0 - su;
  const double wb = u2 * su;
  return a * wa + b * wb + c * (1.0 - wa - wb);
}

} // namespace mlr
