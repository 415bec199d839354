// The readers' checked size arithmetic at the limits of 64 bits: what a hostile file can put
// in an offset, a count or a stride.
#include "CheckedArithmetic.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <limits>

using namespace mlr::scenefile;

namespace
{
constexpr std::int64_t Max = std::numeric_limits<std::int64_t>::max();
constexpr std::int64_t Min = std::numeric_limits<std::int64_t>::min();
}

TEST(CheckedArithmetic, SumsThatWrapAreRefusedAndResultsKeptOtherwise)
{
  std::int64_t r = 7;
  EXPECT_FALSE(checkedAdd(Max, 1, r));
  EXPECT_FALSE(checkedAdd(Min, -1, r));
  EXPECT_EQ(r, 7);
  EXPECT_TRUE(checkedAdd(Max, 0, r));
  EXPECT_EQ(r, Max);
  EXPECT_TRUE(checkedAdd(Min, Max, r));
  EXPECT_EQ(r, -1);
  EXPECT_TRUE(checkedAdd(0, 0, r));
  EXPECT_EQ(r, 0);
}

TEST(CheckedArithmetic, ProductsThatWrapAreRefused)
{
  std::int64_t r = 7;
  EXPECT_FALSE(checkedMultiply(Max, 2, r));
  EXPECT_FALSE(checkedMultiply(Min, -1, r)); // -LLONG_MIN does not exist
  EXPECT_FALSE(checkedMultiply(std::int64_t(1) << 32, std::int64_t(1) << 31, r));
  EXPECT_EQ(r, 7);
  EXPECT_TRUE(checkedMultiply(std::int64_t(1) << 31, std::int64_t(1) << 31, r));
  EXPECT_EQ(r, std::int64_t(1) << 62);
  EXPECT_TRUE(checkedMultiply(Min, 1, r));
  EXPECT_EQ(r, Min);
  EXPECT_TRUE(checkedMultiply(Max, 0, r));
  EXPECT_EQ(r, 0);
}

TEST(CheckedArithmetic, SpansFitExactlyUpToTheLength)
{
  // 4 items 12 bytes apart, the last 8 bytes long, from byte 4: bytes 4 to 48.
  EXPECT_TRUE(spanFits(4, 4, 12, 8, 48));
  EXPECT_FALSE(spanFits(4, 4, 12, 8, 47));
  EXPECT_TRUE(spanFits(0, 0, 12, 8, 0)); // nothing from byte 0 of nothing
  EXPECT_TRUE(spanFits(48, 0, 12, 8, 48));
  EXPECT_FALSE(spanFits(49, 0, 12, 8, 48));
  EXPECT_TRUE(spanFits(Max - 8, 1, 0, 8, Max));
}

TEST(CheckedArithmetic, SpansWhoseSumWouldWrapDoNotFit)
{
  // byteOffset 2^63 - 6 with 12 bytes: offset + length wraps to a small negative number.
  EXPECT_FALSE(spanFits(Max - 5, 1, 0, 12, 1000));
  EXPECT_FALSE(spanFits(0, Max, Max, 1, Max));
  EXPECT_FALSE(spanFits(0, 2, Max, Max, Max));
  EXPECT_FALSE(spanFits(Min, 1, 0, 1, 100));
  EXPECT_FALSE(spanFits(0, -1, 4, 4, 100));
  EXPECT_FALSE(spanFits(0, 1, -4, 4, 100));
  EXPECT_FALSE(spanFits(0, 1, 4, -4, 100));
  EXPECT_FALSE(spanFits(0, 1, 4, 4, -100));
  EXPECT_FALSE(spanFits(0, 1, 0, Min, 100));
}
