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
  /// Probes that decide which sides light can reach: keyed by a fixed seed, never the solve's.
  Reachability = 3,
  /// The hemisphere rays and light samples of the sensors, keyed by the sensor.
  Sensors = 4,
  /// The pilot paths that choose how many paths each light position casts.
  Pilot = 5,
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

/// A cosine-distributed direction around the unit normal n (pdf cos(theta)/pi), by
/// Malley's method: a uniform point of the unit disk, lifted to the hemisphere. The disk
/// point comes from rejection, which costs fewer cycles than sin and cos.
inline Vec3 sampleCosineDirection(const Vec3& n, RandomStream& random)
{
  double a, b, s;
  do
  {
    a = 2.0 * random.uniform() - 1.0;
    b = 2.0 * random.uniform() - 1.0;
    s = a * a + b * b;
  } while (s >= 1.0);
  Vec3 t, bt;
  orthonormalBasis(n, t, bt);
  return t * a + bt * b + n * std::sqrt(1.0 - s);
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
