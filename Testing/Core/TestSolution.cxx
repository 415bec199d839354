// The lit sides a Solution chooses once its radiosity is complete, and how it stores results.
#include "Solution.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mlr;

TEST(Solution, LitSidesAreTheSidesThatReceivedMoreOverTheAnimation)
{
  // Two frames, one patch of four elements. Frame 0 lights the front, frame 1 the back more
  // brightly: over the animation the back received more.
  Solution solution(2, 4, 1);
  auto set = [](StoredArray& data, std::size_t index, double value)
  { data[index] = PackedRgb(Rgb(value, value, value)); };
  set(solution.patchData(), solution.patchIndex(0, 0, Side::Front), 3.0);
  set(solution.patchData(), solution.patchIndex(1, 0, Side::Back), 4.0);
  // Element 0 like its patch; element 1 lit on its front only; element 2 by one channel more
  // on the back; element 3 alike on both sides (ties go to the front).
  set(solution.directData(), solution.elementIndex(0, 0, Side::Front), 1.0);
  set(solution.directData(), solution.elementIndex(1, 0, Side::Back), 2.0);
  set(solution.directData(), solution.elementIndex(0, 1, Side::Front), 1.0);
  solution.directData()[solution.elementIndex(1, 2, Side::Back)] = PackedRgb(Rgb(0, 0, 1e-3));
  set(solution.directData(), solution.elementIndex(0, 3, Side::Front), 1.0);
  set(solution.directData(), solution.elementIndex(1, 3, Side::Back), 1.0);
  solution.allocateIndirect();
  solution.chooseLitSides(2);
  EXPECT_EQ(solution.patchLitSide(0), Side::Back);
  EXPECT_EQ(solution.litSide(0), Side::Back);
  EXPECT_EQ(solution.litSide(1), Side::Front);
  EXPECT_EQ(solution.litSide(2), Side::Back);
  EXPECT_EQ(solution.litSide(3), Side::Front);
}

TEST(Solution, StoredResultsKeepTheirPrecisionInAnyUnit)
{
  // A room of 100 m^2 in metres, in micrometres and at the coordinate bound's scale: its
  // irradiance ranges over 40 decades, beyond PackedRgb's 37, and is stored as irradiance
  // times the area, the lights' power.
  for (const double metre : { 1.0, 1e6, 1e13 })
  {
    const double area = 100 * metre * metre;
    const double scale = Solution::storageScaleFor(area);
    int exponent = 0;
    EXPECT_EQ(std::frexp(scale, &exponent), 0.5) << "a power of two";
    EXPECT_GT(scale * area, 0.7);
    EXPECT_LT(scale * area, 1.5);
    Solution solution(1, 4, 1);
    solution.setStorageScale(scale);
    for (const double watts : { 1e-3, 1.0, 1e5 })
    {
      const double irradiance = watts / area;
      const Rgb back = solution.load(solution.store(Rgb(irradiance, 0.5 * irradiance, 0)));
      EXPECT_NEAR(back.r, irradiance, PackedRgb::RelativeRounding * irradiance) << area;
      EXPECT_NEAR(back.g, 0.5 * irradiance, PackedRgb::RelativeRounding * irradiance) << area;
      EXPECT_EQ(back.b, 0.0);
    }
  }
  EXPECT_EQ(Solution::storageScaleFor(0), 1.0);
  EXPECT_EQ(Solution::storageScaleFor(std::nan("")), 1.0);
}
