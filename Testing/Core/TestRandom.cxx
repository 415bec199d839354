// Random streams: reproducible per key, distinct for distinct keys, uniform in [0, 1) with
// the mean, variance and histogram of a uniform variable, and the two sampling routines.
// Seeds are fixed, so each check has one outcome; the tolerances are five standard
// deviations of the statistic for the sample size, so that a correct generator passes with
// any seed and a biased one fails.
#include "Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

using namespace mlr;

namespace
{
std::vector<std::uint64_t> bits(RandomStream stream, int count)
{
  std::vector<std::uint64_t> out(static_cast<std::size_t>(count));
  for (std::uint64_t& b : out)
  {
    b = stream.nextBits();
  }
  return out;
}
}

TEST(RandomStream, SameKeySameNumbers)
{
  const RandomStream key(12345, StreamPurpose::Shooting, 678, 9);
  EXPECT_EQ(bits(key, 1000), bits(RandomStream(12345, StreamPurpose::Shooting, 678, 9), 1000));
  // A copy continues where the original is, and both go on alike.
  RandomStream a(1, StreamPurpose::Gathering, 2, 3);
  a.uniform();
  RandomStream b = a;
  for (int i = 0; i < 100; ++i)
  {
    EXPECT_EQ(a.uniform(), b.uniform());
  }
}

TEST(RandomStream, EveryPartOfTheKeyChangesTheNumbers)
{
  const RandomStream base(5, StreamPurpose::Shooting, 10, 20);
  const RandomStream others[] = {
    RandomStream(6, StreamPurpose::Shooting, 10, 20),
    RandomStream(5, StreamPurpose::Gathering, 10, 20),
    RandomStream(5, StreamPurpose::Reachability, 10, 20),
    RandomStream(5, StreamPurpose::Shooting, 11, 20),
    RandomStream(5, StreamPurpose::Shooting, 10, 21),
    // a and b swapped: a path's index and a ray set's index must not collide.
    RandomStream(5, StreamPurpose::Shooting, 20, 10),
  };
  const std::vector<std::uint64_t> mine = bits(base, 1000);
  for (const RandomStream& other : others)
  {
    const std::vector<std::uint64_t> theirs = bits(other, 1000);
    int same = 0;
    for (std::size_t i = 0; i < mine.size(); ++i)
    {
      same += mine[i] == theirs[i] ? 1 : 0;
    }
    EXPECT_EQ(same, 0);
    // Not a shifted copy of the same sequence either (a Weyl sequence of equal states).
    int shifted = 0;
    for (std::size_t i = 0; i + 1 < mine.size(); ++i)
    {
      shifted += mine[i + 1] == theirs[i] || mine[i] == theirs[i + 1] ? 1 : 0;
    }
    EXPECT_EQ(shifted, 0);
  }
}

TEST(RandomStream, NeighbouringStreamsAreUncorrelated)
{
  // The solver keys paths by consecutive indices: stream a and a + 1 must look independent.
  // The sample correlation of n independent pairs has standard deviation 1 / sqrt(n).
  const int n = 100000;
  for (std::uint64_t a : { 0ull, 1ull, 1000000ull })
  {
    RandomStream x(3, StreamPurpose::Shooting, a), y(3, StreamPurpose::Shooting, a + 1);
    double sx = 0, sy = 0, sxx = 0, syy = 0, sxy = 0;
    for (int i = 0; i < n; ++i)
    {
      const double u = x.uniform(), v = y.uniform();
      sx += u, sy += v, sxx += u * u, syy += v * v, sxy += u * v;
    }
    const double cov = sxy / n - sx / n * sy / n;
    const double corr = cov / std::sqrt((sxx / n - sx / n * sx / n) * (syy / n - sy / n * sy / n));
    EXPECT_LT(std::abs(corr), 5.0 / std::sqrt(n)) << a;
  }
  // Nor are the first numbers of many consecutive streams, which is what a solve draws.
  double s = 0, ss = 0;
  for (int k = 0; k < n; ++k)
  {
    const double u =
      RandomStream(9, StreamPurpose::Gathering, static_cast<std::uint64_t>(k)).uniform();
    s += u, ss += u * u;
  }
  EXPECT_NEAR(s / n, 0.5, 5 * std::sqrt(1.0 / 12 / n));
}

TEST(RandomStream, UniformHasTheMomentsAndHistogramOfU01)
{
  const int n = 1000000;
  RandomStream random(2024, StreamPurpose::Shooting, 17);
  constexpr int bins = 100;
  std::vector<int> histogram(bins, 0);
  double sum = 0, sumSquares = 0, lo = 1, hi = 0;
  for (int i = 0; i < n; ++i)
  {
    const double u = random.uniform();
    ASSERT_GE(u, 0.0);
    ASSERT_LT(u, 1.0);
    lo = std::min(lo, u);
    hi = std::max(hi, u);
    sum += u;
    sumSquares += (u - 0.5) * (u - 0.5);
    ++histogram[static_cast<int>(u * bins)];
  }
  // Mean 1/2 with standard deviation sqrt(1/12 / n) = 2.9e-4.
  EXPECT_NEAR(sum / n, 0.5, 5 * std::sqrt(1.0 / 12 / n));
  // Variance 1/12: (u - 1/2)^2 has mean 1/12 and variance 1/80 - 1/144 = 1/180.
  EXPECT_NEAR(sumSquares / n, 1.0 / 12, 5 * std::sqrt(1.0 / 180 / n));
  // The whole interval is covered: n draws leave gaps of about 1/n at the ends.
  EXPECT_LT(lo, 1e-4);
  EXPECT_GT(hi, 1 - 1e-4);
  // Pearson's chi-square over 100 equal bins, 99 degrees of freedom: mean 99, standard
  // deviation 14; 170 is five deviations up (a probability of about 1e-6).
  const double expected = static_cast<double>(n) / bins;
  double chi2 = 0;
  for (int count : histogram)
  {
    chi2 += (count - expected) * (count - expected) / expected;
  }
  EXPECT_LT(chi2, 170.0);
  // And not suspiciously flat either (an equidistributed counter would give nearly 0).
  EXPECT_GT(chi2, 40.0);
}

TEST(RandomStream, UniformStaysBelowOne)
{
  // 53 bits: the largest value is 1 - 2^-53, never 1, which a draw of 1 would be (an index
  // of u * count would run past the end).
  RandomStream random(0, StreamPurpose::Reachability, 0);
  for (int i = 0; i < 100000; ++i)
  {
    const double u = random.uniform();
    ASSERT_LT(static_cast<int>(u * 3), 3);
  }
  EXPECT_LT(static_cast<double>(~std::uint64_t(0) >> 11) * 0x1.0p-53, 1.0);
}

TEST(Sampling, CosineDirectionsHaveTheCosineDensity)
{
  // pdf cos(theta) / pi over the hemisphere: E[cos] = 2/3, E[cos^2] = 1/2, so cos has
  // variance 1/18; the azimuth is uniform, so the tangential components average to 0.
  const Vec3 n = normalize(Vec3(1, 2, -0.5));
  RandomStream random(8, StreamPurpose::Gathering, 4);
  const int count = 200000;
  double sumCos = 0;
  Vec3 sum;
  for (int i = 0; i < count; ++i)
  {
    const Vec3 d = sampleCosineDirection(n, random);
    ASSERT_NEAR(length(d), 1.0, 1e-12);
    const double c = dot(d, n);
    ASSERT_GE(c, 0.0);
    sumCos += c;
    sum += d - n * c;
  }
  EXPECT_NEAR(sumCos / count, 2.0 / 3, 5 * std::sqrt(1.0 / 18 / count));
  // Each tangential component has variance (1 - E[cos^2]) / 2 = 1/4.
  EXPECT_LT(length(sum) / count, 5 * std::sqrt(2 * 0.25 / count));
}

TEST(Sampling, TrianglePointsAreUniform)
{
  // Inside the triangle, and a quarter of them in each of the four triangles of its
  // midpoint split (binomial: standard deviation sqrt(p (1 - p) / n)).
  const Vec3 a(0, 0, 0), b(2, 0, 1), c(0, 3, 1);
  RandomStream random(1, StreamPurpose::Shooting, 99);
  const int count = 200000;
  int inMiddle = 0, nearA = 0;
  Vec3 mean;
  for (int i = 0; i < count; ++i)
  {
    const Vec3 p = sampleTriangle(a, b, c, random.uniform(), random.uniform());
    // Barycentric coordinates from the two edges.
    const Vec3 e1 = b - a, e2 = c - a, q = p - a;
    const double d11 = dot(e1, e1), d12 = dot(e1, e2), d22 = dot(e2, e2);
    const double det = d11 * d22 - d12 * d12;
    const double v = (d22 * dot(q, e1) - d12 * dot(q, e2)) / det;
    const double w = (d11 * dot(q, e2) - d12 * dot(q, e1)) / det;
    ASSERT_GE(v, -1e-12);
    ASSERT_GE(w, -1e-12);
    ASSERT_LE(v + w, 1 + 1e-12);
    ASSERT_NEAR(length(q - e1 * v - e2 * w), 0.0, 1e-12) << "off the triangle's plane";
    inMiddle += v <= 0.5 && w <= 0.5 && v + w >= 0.5 ? 1 : 0;
    nearA += v + w < 0.5 ? 1 : 0;
    mean += p;
  }
  const double sigma = std::sqrt(0.25 * 0.75 / count);
  EXPECT_NEAR(static_cast<double>(inMiddle) / count, 0.25, 5 * sigma);
  EXPECT_NEAR(static_cast<double>(nearA) / count, 0.25, 5 * sigma);
  // The mean is the centroid (each coordinate's deviation is below its extent / sqrt(n)).
  EXPECT_NEAR(length(mean / count - (a + b + c) / 3.0), 0.0, 5 * 3 / std::sqrt(count));
}
