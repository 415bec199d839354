// predictedSpeedup against the paper's eq. (4),
//   n (1 + lambda (l - 1)) + k n
//   ----------------------------   with n frames, k the gathering ratio, lambda the
//     n + lambda (l - 1) + k        first-bounce survival and l the mean path length,
// the cost of n classic solves over one solve reusing shooting and gathering, in ray casts.
// The expected values are worked out by hand (the arithmetic is in the comments), not with
// the formula under test.
#include "Solver.h"

#include <gtest/gtest.h>

using mlr::predictedSpeedup;

TEST(PredictedSpeedup, MatchesEquationFourWorkedByHand)
{
  // n = 30, k = 1, lambda = 0.25, l = 5: lambda (l - 1) = 1; (30 * 2 + 30) / (30 + 1 + 1) = 90
  // / 32.
  EXPECT_DOUBLE_EQ(predictedSpeedup(30, 1.0, 0.25, 5.0), 2.8125);
  // n = 2, k = 1, lambda = 1, l = 3: lambda (l - 1) = 2; (2 * 3 + 2) / (2 + 2 + 1) = 8 / 5.
  EXPECT_DOUBLE_EQ(predictedSpeedup(2, 1.0, 1.0, 3.0), 1.6);
  // n = 10, k = 0.5, lambda = 0.5, l = 2.2: lambda (l - 1) = 0.6; (16 + 5) / 11.1 = 70 / 37.
  EXPECT_DOUBLE_EQ(predictedSpeedup(10, 0.5, 0.5, 2.2), 70.0 / 37.0);
  EXPECT_NEAR(predictedSpeedup(10, 0.5, 0.5, 2.2), 1.8918918918918919, 1e-15);
  // n = 100, k = 2, lambda = 0.001, l = 11: lambda (l - 1) = 0.01; (101 + 200) / 102.01.
  EXPECT_NEAR(predictedSpeedup(100, 2.0, 0.001, 11.0), 2.9506911087148318, 1e-14);
  // The paper's room (30 positions, k = 1, lambda = 0.25) quotes "about 2.8": l = 4.94 gives
  // lambda (l - 1) = 0.985 and (30 * 1.985 + 30) / 31.985 = 89.55 / 31.985.
  EXPECT_NEAR(predictedSpeedup(30, 1.0, 0.25, 4.94), 2.799749882757543, 1e-13);
}

TEST(PredictedSpeedup, Limits)
{
  // One frame: nothing to reuse, whatever k, lambda and l.
  EXPECT_DOUBLE_EQ(predictedSpeedup(1, 1.0, 0.25, 5.0), 1.0);
  EXPECT_DOUBLE_EQ(predictedSpeedup(1, 3.0, 0.7, 9.0), 1.0);
  EXPECT_DOUBLE_EQ(predictedSpeedup(1, 0.0, 1.0, 1.0), 1.0);
  // Walks that end at their first hit and no gathering: shooting with reuse still casts one
  // first ray per frame and path, as n classic solves do.
  EXPECT_DOUBLE_EQ(predictedSpeedup(7, 0.0, 1.0, 1.0), 1.0);
  EXPECT_DOUBLE_EQ(predictedSpeedup(7, 0.0, 0.25, 1.0), 1.0);
  // Walks that end at their first hit, k = 1: (n + n) / (n + 1) = 2n / (n + 1); 8 / 5 at n = 4.
  EXPECT_DOUBLE_EQ(predictedSpeedup(4, 1.0, 0.25, 1.0), 1.6);
  // Gathering only (lambda (l - 1) = 0, k large): the speed-up tends to n.
  // (30 + 30e9) / (30 + 1e9) = 30 - 870 / (1e9 + 30).
  EXPECT_NEAR(predictedSpeedup(30, 1e9, 0.25, 1.0), 30.0 - 8.7e-7, 1e-12);
  // Eq. (5): n -> infinity gives k + 1 + lambda (l - 1) = 1 + 1 + 1 = 3 for k = 1,
  // lambda = 0.25, l = 5; at n = 1e9 it is 3e9 / (1e9 + 2) = 3 - 6 / (1e9 + 2) = 2.999999994.
  EXPECT_NEAR(predictedSpeedup(1000000000, 1.0, 0.25, 5.0), 2.999999994, 1e-12);
  // Indirect light alone, lambda = 1 in eq. (5): k + l = 0.5 + 4.
  EXPECT_NEAR(predictedSpeedup(1000000000, 0.5, 1.0, 4.0), 4.5, 1e-7);
}

TEST(PredictedSpeedup, GrowsWithFramesAndStaysBelowTheLimit)
{
  // Eq. (4) increases with n towards eq. (5): reuse pays more the more frames share a path.
  double previous = 1.0;
  for (std::size_t n : { 2, 3, 10, 30, 100, 1000 })
  {
    const double s = predictedSpeedup(n, 1.0, 0.25, 5.0);
    EXPECT_GT(s, previous) << n;
    EXPECT_LT(s, 3.0) << n;
    previous = s;
  }
}
