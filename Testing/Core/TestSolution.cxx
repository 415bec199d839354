// The lit sides a Solution chooses once its radiosity is complete, and how it stores results.
#include "Solution.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

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

TEST(Solution, LitSidesDoNotDependOnTheWorkers)
{
  // More elements and patches than one worker's block, so that blocks end inside the data:
  // every element's and patch's choice follows litSideOf on its own sums, for 1 and 3 workers.
  constexpr std::size_t Frames = 3, Patches = 2500, Elements = 4 * Patches;
  Solution solution(Frames, Elements, Patches);
  std::uint64_t state = 12345;
  auto next = [&]
  {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return double(state >> 40) / double(1ull << 24);
  };
  for (std::size_t f = 0; f < Frames; ++f)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      for (std::size_t e = 0; e < Elements; ++e)
      {
        // A tenth of the elements black on both sides in every frame.
        const double value = e % 10 == 3 ? 0.0 : next();
        solution.directData()[solution.elementIndex(f, e, side)] =
          PackedRgb(Rgb(value, 0.5 * value, 0.25 * value));
      }
      for (std::size_t p = 0; p < Patches; ++p)
      {
        solution.patchData()[solution.patchIndex(f, p, side)] = PackedRgb(Rgb(next()));
      }
    }
  }
  solution.allocateIndirect();
  solution.chooseLitSides(1);
  const std::vector<Side> one(solution.litSideData()), onePatches(solution.patchLitSideData());
  solution.litSideData().assign(Elements, Side::Back);
  solution.patchLitSideData().assign(Patches, Side::Back);
  solution.chooseLitSides(3);
  EXPECT_EQ(solution.litSideData(), one);
  EXPECT_EQ(solution.patchLitSideData(), onePatches);
  std::size_t backs = 0;
  for (std::size_t e = 0; e < Elements; ++e)
  {
    double front = 0, back = 0, irradianceFront = 0, irradianceBack = 0;
    for (std::size_t f = 0; f < Frames; ++f)
    {
      front += solution.total(f, e, Side::Front).sum();
      back += solution.total(f, e, Side::Back).sum();
      irradianceFront += solution.irradiance(f, e, Side::Front).sum();
      irradianceBack += solution.irradiance(f, e, Side::Back).sum();
    }
    ASSERT_EQ(
      solution.litSide(e), Solution::litSideOf(front, back, irradianceFront, irradianceBack))
      << e;
    backs += solution.litSide(e) == Side::Back;
  }
  // Both choices occur, so the comparison above can fail.
  EXPECT_GT(backs, Elements / 4);
  EXPECT_LT(backs, 3 * Elements / 4);
  for (std::size_t p = 0; p < Patches; ++p)
  {
    double front = 0, back = 0;
    for (std::size_t f = 0; f < Frames; ++f)
    {
      front += solution.patchRadiosity(f, p, Side::Front).sum();
      back += solution.patchRadiosity(f, p, Side::Back).sum();
    }
    ASSERT_EQ(solution.patchLitSide(p), back > front ? Side::Back : Side::Front) << p;
  }
}

TEST(Solution, StoredResultsKeepTheirPrecisionInAnyUnit)
{
  // A room of 100 m^2 in metres, in micrometres and at the coordinate bound's scale, lit by
  // lights of 10^-20 W to 10^20 W: its irradiance ranges over 80 decades, beyond PackedRgb's
  // 37, and is stored as a multiple of the mean irradiance, lights' power over area, with
  // room for peaks of 10^15 times it and dim corners of 10^-15.
  for (const double metre : { 1.0, 1e6, 1e13 })
  {
    for (const double power : { 1e-20, 1.0, 1e20 })
    {
      const double area = 100 * metre * metre;
      const double scale = Solution::storageScaleFor(area, power);
      int exponent = 0;
      EXPECT_EQ(std::frexp(scale, &exponent), 0.5) << "a power of two";
      const double mean = power / area;
      EXPECT_GT(mean / scale, 0.7);
      EXPECT_LT(mean / scale, 1.5);
      Solution solution(1, 4, 1);
      solution.setStorageScale(scale);
      for (const double share : { 1e-15, 1.0, 1e15 })
      {
        const double irradiance = share * mean;
        const Rgb back = solution.load(solution.store(Rgb(irradiance, 0.5 * irradiance, 0)));
        EXPECT_NEAR(back.r, irradiance, PackedRgb::RelativeRounding * irradiance) << area;
        EXPECT_NEAR(back.g, 0.5 * irradiance, PackedRgb::RelativeRounding * irradiance) << area;
        EXPECT_EQ(back.b, 0.0);
      }
    }
  }
  // Lights all off: the area alone; no area: 1.
  EXPECT_EQ(Solution::storageScaleFor(4, 0), 0.25);
  EXPECT_EQ(Solution::storageScaleFor(0, 1), 1.0);
  EXPECT_EQ(Solution::storageScaleFor(std::nan(""), 1), 1.0);
}
