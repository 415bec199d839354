// The lit sides a Solution chooses once its radiosity is complete, for elements and patches.
#include "Solution.h"

#include <gtest/gtest.h>

using namespace mlr;

TEST(Solution, LitSidesAreTheSidesThatReceivedMoreOverTheAnimation)
{
  // Two frames, one patch of four elements. Frame 0 lights the front, frame 1 the back more
  // brightly: over the animation the back received more.
  Solution solution(2, 4, 1);
  auto set = [](std::vector<PackedRgb>& data, std::size_t index, double value)
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
  solution.chooseLitSides();
  EXPECT_EQ(solution.patchLitSide(0), Side::Back);
  EXPECT_EQ(solution.litSide(0), Side::Back);
  EXPECT_EQ(solution.litSide(1), Side::Front);
  EXPECT_EQ(solution.litSide(2), Side::Back);
  EXPECT_EQ(solution.litSide(3), Side::Front);
}
