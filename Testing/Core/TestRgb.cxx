// The stored form of results (PackedRgb): its rounding, its range and the bits it keeps.
#include "Random.h"
#include "Rgb.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

using namespace mlr;

namespace
{
double stored(double value)
{
  return PackedRgb::decode(PackedRgb::encode(value));
}
}

TEST(Rgb, AStoredValueIsWithinATenthOfAPercentOfItself)
{
  // Every binade from the smallest kept value to the largest finite one, at random points:
  // the spacing is 2^-9 of the binade, so rounding to nearest stays within 2^-10.
  RandomStream random(7, StreamPurpose::Gathering, 0, 0);
  for (int exponent = -62; exponent < 63; ++exponent)
  {
    for (int i = 0; i < 200; ++i)
    {
      const double value = std::ldexp(1.0 + random.uniform(), exponent);
      EXPECT_LE(std::abs(stored(value) - value), std::ldexp(value, -10)) << value;
    }
  }
}

TEST(Rgb, RoundingToNearestHasNoBias)
{
  // The mean relative rounding error over many values of one binade is far below the 2^-10
  // bound of one value: 100,000 uniform values have a mean error whose standard deviation is
  // about 2^-10 / sqrt(3 x 100,000) = 1.8e-6.
  RandomStream random(11, StreamPurpose::Gathering, 0, 0);
  double sum = 0;
  constexpr int Count = 100000;
  for (int i = 0; i < Count; ++i)
  {
    const double value = 3.0 + random.uniform();
    sum += (stored(value) - value) / value;
  }
  EXPECT_LT(std::abs(sum / Count), 1e-5);
}

TEST(Rgb, AStoredValueStoredAgainKeepsItsBits)
{
  for (unsigned code = 0; code < 127u << 9; ++code)
  {
    const auto c = static_cast<std::uint16_t>(code);
    ASSERT_EQ(PackedRgb::encode(PackedRgb::decode(c)), code == 0 || code >= 512 ? c : 0);
  }
  const PackedRgb color(Rgb(0.25, 1e-9, 3e12));
  const Rgb back(color);
  const PackedRgb again(back);
  EXPECT_EQ(again.r, color.r);
  EXPECT_EQ(again.g, color.g);
  EXPECT_EQ(again.b, color.b);
  EXPECT_EQ(back.r, 0.25); // a power of two is exact
}

TEST(Rgb, TheRangeCoversAnyUnitAndItsEndsAreClear)
{
  EXPECT_EQ(stored(0), 0);
  EXPECT_EQ(stored(-1), 0);
  EXPECT_EQ(stored(std::ldexp(1.0, -63)), 0);
  EXPECT_EQ(stored(std::ldexp(1.0, -62)), std::ldexp(1.0, -62));
  // A square kilometre unit under the sun and a square micrometre one alike.
  EXPECT_NEAR(stored(1e9) / 1e9, 1, 1e-3);
  EXPECT_NEAR(stored(1e-9) / 1e-9, 1, 1e-3);
  EXPECT_TRUE(std::isinf(stored(1e20)));
  EXPECT_TRUE(std::isinf(stored(std::numeric_limits<double>::infinity())));
  EXPECT_TRUE(std::isnan(stored(std::nan(""))));
}
