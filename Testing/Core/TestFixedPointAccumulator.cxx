// FixedPointAccumulator: sums in whole quanta, exact and the same whatever the order of the
// adds and the number of workers (copies or one shared copy with atomic adds), each value
// rounded to the nearest quantum, and exact far beyond double precision.
#include "FixedPointAccumulator.h"
#include "Random.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <thread>
#include <vector>

#include <sys/mman.h>

using namespace mlr;

namespace
{
/// One add: a value for a (record, side, frame).
struct Score
{
  std::size_t record;
  int side;
  std::size_t frame;
  double value;
};

constexpr std::size_t Records = 5;
constexpr std::size_t Frames = 7;
constexpr double Quantum = 1.0 / 1024;

/// Values from 0 to 3 that are no multiples of the quantum, so that every add rounds.
std::vector<Score> someScores(std::size_t count)
{
  RandomStream random(42, StreamPurpose::Shooting, 0);
  std::vector<Score> scores(count);
  for (Score& s : scores)
  {
    s.record = static_cast<std::size_t>(random.uniform() * Records);
    s.side = random.uniform() < 0.5 ? 0 : 1;
    s.frame = static_cast<std::size_t>(random.uniform() * Frames);
    s.value = 3.0 * random.uniform();
  }
  return scores;
}

/// The expected sums, in quanta: each value rounded to the nearest quantum, then added.
std::vector<std::int64_t> expectedQuanta(const std::vector<Score>& scores, double quantum = Quantum)
{
  std::vector<std::int64_t> q(Records * 2 * Frames, 0);
  for (const Score& s : scores)
  {
    q[(s.record * 2 + static_cast<std::size_t>(s.side)) * Frames + s.frame] +=
      std::llround(s.value / quantum);
  }
  return q;
}

/// Scores `scores` with `workers` workers, score i by worker i % workers, in the given
/// order, and returns every total.
std::vector<double> totals(const std::vector<Score>& scores, int workers, bool copyPerWorker,
  FrameLayout layout, const std::vector<std::uint8_t>* stored = nullptr)
{
  FixedPointAccumulator<1> sums(workers, copyPerWorker, Records, Frames, Quantum, layout, stored);
  for (std::size_t i = 0; i < scores.size(); ++i)
  {
    const Score& s = scores[i];
    sums.add(sums.slots(static_cast<int>(i % workers), s.record, s.side), s.frame, &s.value);
  }
  std::vector<double> out;
  for (std::size_t r = 0; r < Records; ++r)
  {
    for (int side = 0; side < 2; ++side)
    {
      for (std::size_t f = 0; f < Frames; ++f)
      {
        double t = 0;
        sums.total(r, side, f, &t);
        out.push_back(t);
      }
    }
  }
  return out;
}
}

TEST(FixedPointAccumulator, SumsAreExactWholeQuanta)
{
  const std::vector<Score> scores = someScores(20000);
  const std::vector<std::int64_t> quanta = expectedQuanta(scores);
  const std::vector<double> sums = totals(scores, 1, true, FrameLayout::FramesInner);
  ASSERT_EQ(sums.size(), quanta.size());
  for (std::size_t i = 0; i < sums.size(); ++i)
  {
    EXPECT_EQ(sums[i], static_cast<double>(quanta[i]) * Quantum) << "slot " << i;
  }
}

TEST(FixedPointAccumulator, SumsDoNotDependOnOrderWorkersSharingOrLayout)
{
  std::vector<Score> scores = someScores(20000);
  const std::vector<double> reference = totals(scores, 1, true, FrameLayout::FramesInner);
  // Floating-point sums of the same values in another order differ in their last bits;
  // these must not.
  std::vector<Score> reversed(scores.rbegin(), scores.rend());
  std::vector<Score> sorted = scores;
  std::sort(
    sorted.begin(), sorted.end(), [](const Score& a, const Score& b) { return a.value > b.value; });
  for (const std::vector<Score>* order : { &scores, &reversed, &sorted })
  {
    for (int workers : { 1, 2, 3, 8 })
    {
      for (bool copyPerWorker : { true, false })
      {
        for (FrameLayout layout : { FrameLayout::FramesInner, FrameLayout::FramesOuter })
        {
          EXPECT_EQ(totals(*order, workers, copyPerWorker, layout), reference)
            << workers << " workers, copy per worker " << copyPerWorker << ", layout "
            << static_cast<int>(layout);
        }
      }
    }
  }
}

TEST(FixedPointAccumulator, ConcurrentAddsAndCarriesLoseNothing)
{
  // Every thread adds the same scores at once, to low words of its own or to one shared set,
  // and carries into the high words they all share: a plain (non-atomic) read-modify-write
  // of shared words would lose some of them. At 2^-30 a value is up to 3 x 2^30 quanta and
  // a low word carries every other add or so; at 2^-33 every add has quanta above 32 bits.
  const std::vector<Score> scores = someScores(200000);
  constexpr int threads = 4;
  for (const double quantum : { Quantum, 0x1.0p-30, 0x1.0p-33 })
  {
    const std::vector<std::int64_t> quanta = expectedQuanta(scores, quantum);
    for (const bool copyPerWorker : { false, true })
    {
      FixedPointAccumulator<1> sums(
        threads, copyPerWorker, Records, Frames, quantum, FrameLayout::FramesInner);
      std::vector<std::thread> pool;
      for (int w = 0; w < threads; ++w)
      {
        pool.emplace_back(
          [&, w]
          {
            for (const Score& s : scores)
            {
              sums.add(sums.slots(w, s.record, s.side), s.frame, &s.value);
            }
          });
      }
      for (std::thread& t : pool)
      {
        t.join();
      }
      for (bool collapsed : { false, true })
      {
        for (std::size_t r = 0; r < Records; ++r)
        {
          for (int side = 0; side < 2; ++side)
          {
            for (std::size_t f = 0; f < Frames; ++f)
            {
              double t = 0;
              sums.total(r, side, f, &t);
              ASSERT_EQ(
                t, threads * static_cast<double>(quanta[(r * 2 + side) * Frames + f]) * quantum)
                << quantum << " copy per worker " << copyPerWorker << " collapsed " << collapsed;
            }
          }
        }
        sums.collapse();
      }
    }
  }
}

TEST(FixedPointAccumulator, EachValueRoundsToTheNearestQuantum)
{
  const double q = 0.01;
  const struct
  {
    double value;
    double expected;
  } cases[] = {
    { 0.0, 0.0 }, { 0.0049, 0.0 },                          // below half a quantum: lost
    { 0.0051, 0.01 },                                       // above half: one quantum
    { 0.0149, 0.01 }, { 0.0151, 0.02 }, { 12.3456, 12.35 }, // 1234.56 quanta
  };
  for (const auto& c : cases)
  {
    FixedPointAccumulator<1> sums(1, true, 1, 1, q, FrameLayout::FramesInner);
    sums.add(sums.slots(0, 0, 0), 0, &c.value);
    double t = -1;
    sums.total(0, 0, 0, &t);
    EXPECT_NEAR(t, c.expected, 1e-12) << c.value;
    EXPECT_LE(std::abs(t - c.value), q / 2) << c.value;
  }
  // Rounding is per add: 1000 adds of 0.4 quanta sum to nothing, 1000 of 0.6 quanta to
  // 1000 quanta; the error of n adds is at most n / 2 quanta.
  for (double fraction : { 0.4, 0.6 })
  {
    FixedPointAccumulator<1> sums(1, true, 1, 1, q, FrameLayout::FramesInner);
    const double value = fraction * q;
    for (int i = 0; i < 1000; ++i)
    {
      sums.add(sums.slots(0, 0, 0), 0, &value);
    }
    double t = -1;
    sums.total(0, 0, 0, &t);
    EXPECT_NEAR(t, fraction < 0.5 ? 0.0 : 1000 * q, 1e-9) << fraction;
    EXPECT_LE(std::abs(t - 1000 * value), 1000 * q / 2);
  }
}

TEST(FixedPointAccumulator, EachChannelHasItsOwnQuantum)
{
  // A channel a million times weaker than another keeps its digits.
  FixedPointAccumulator<3> sums(2, true, 3, 2, { 1.0, 1e-3, 1e-6 }, FrameLayout::FramesOuter);
  const double value[3] = { 0.0123, 0.0123, 0.0123 };
  sums.add(sums.slots(1, 2, 1), 1, value);
  double t[3] = { -1, -1, -1 };
  sums.total(2, 1, 1, t);
  EXPECT_EQ(t[0], 0.0);
  EXPECT_NEAR(t[1], 0.012, 1e-15);
  EXPECT_NEAR(t[2], 0.0123, 1e-15);
  // Nothing landed anywhere else.
  for (std::size_t r = 0; r < 3; ++r)
  {
    for (int side = 0; side < 2; ++side)
    {
      for (std::size_t f = 0; f < 2; ++f)
      {
        if (r == 2 && side == 1 && f == 1)
        {
          continue;
        }
        sums.total(r, side, f, t);
        EXPECT_EQ(t[0] + t[1] + t[2], 0.0) << r << " " << side << " " << f;
      }
    }
  }
}

TEST(FixedPointAccumulator, EverySlotIsDistinctInBothLayouts)
{
  // A distinct count of quanta in every (record, side, frame, channel): any two slots that
  // alias, in either layout, would read back a sum.
  for (FrameLayout layout : { FrameLayout::FramesInner, FrameLayout::FramesOuter })
  {
    const std::size_t records = 4, frames = 3;
    FixedPointAccumulator<3> sums(1, true, records, frames, 1.0, layout);
    auto code = [&](std::size_t r, int side, std::size_t f, int c)
    { return static_cast<double>(((r * 2 + side) * frames + f) * 3 + c + 1); };
    for (std::size_t r = 0; r < records; ++r)
    {
      for (int side = 0; side < 2; ++side)
      {
        const SlotRun slots = sums.slots(0, r, side);
        for (std::size_t f = 0; f < frames; ++f)
        {
          const double v[3] = { code(r, side, f, 0), code(r, side, f, 1), code(r, side, f, 2) };
          sums.add(slots, f, v);
        }
      }
    }
    for (std::size_t r = 0; r < records; ++r)
    {
      for (int side = 0; side < 2; ++side)
      {
        for (std::size_t f = 0; f < frames; ++f)
        {
          double t[3];
          sums.total(r, side, f, t);
          for (int c = 0; c < 3; ++c)
          {
            EXPECT_EQ(t[c], code(r, side, f, c)) << static_cast<int>(layout);
          }
        }
      }
    }
  }
}

TEST(FixedPointAccumulator, CollapseKeepsTheSumsInTheFirstCopy)
{
  const std::vector<Score> scores = someScores(5000);
  const std::vector<std::int64_t> quanta = expectedQuanta(scores);
  FixedPointAccumulator<1> sums(3, true, Records, Frames, Quantum, FrameLayout::FramesInner);
  for (std::size_t i = 0; i < scores.size(); ++i)
  {
    const Score& s = scores[i];
    sums.add(sums.slots(static_cast<int>(i % 3), s.record, s.side), s.frame, &s.value);
  }
  ASSERT_EQ(sums.copySize(), Records * 2 * Frames);
  const std::int64_t* first = sums.collapse();
  // FramesInner: (record, side) major, frames innermost, as expectedQuanta lays them out.
  for (std::size_t i = 0; i < sums.copySize(); ++i)
  {
    EXPECT_EQ(first[i], quanta[i]) << i;
  }
  // The other copies are zero now, so the totals are unchanged.
  for (std::size_t i = 0; i < quanta.size(); ++i)
  {
    double t = 0;
    sums.total(i / (2 * Frames), static_cast<int>(i / Frames % 2), i % Frames, &t);
    EXPECT_EQ(t, static_cast<double>(quanta[i]) * Quantum);
  }
}

TEST(FixedPointAccumulator, ExactNearTheCapacityOfASlot)
{
  // A slot holds up to 2^63 quanta. At 2^60 quanta a double cannot hold one more quantum
  // (its spacing there is 256), the integer sum can.
  const double q = 0x1.0p-20; // a power of two: value / q is exact
  FixedPointAccumulator<1> sums(2, true, 1, 1, q, FrameLayout::FramesInner);
  const double big = 0x1.0p60 * q, one = q;
  sums.add(sums.slots(0, 0, 0), 0, &big);
  double floating = big;
  for (int i = 0; i < 1000; ++i)
  {
    sums.add(sums.slots(1, 0, 0), 0, &one);
    floating += one;
  }
  EXPECT_EQ(floating, big) << "the double sum was expected to lose the small adds";
  const std::int64_t* first = sums.collapse();
  EXPECT_EQ(first[0], (std::int64_t(1) << 60) + 1000);
  // Up to just below 2^63 quanta: 3 x 2^61 + 2^60 = 7 x 2^60.
  FixedPointAccumulator<1> full(1, true, 1, 1, q, FrameLayout::FramesInner);
  const double quarter = 0x1.0p61 * q, eighth = 0x1.0p60 * q;
  for (int i = 0; i < 3; ++i)
  {
    full.add(full.slots(0, 0, 0), 0, &quarter);
  }
  full.add(full.slots(0, 0, 0), 0, &eighth);
  double t = 0;
  full.total(0, 0, 0, &t);
  EXPECT_EQ(t, 7 * 0x1.0p60 * q);
  EXPECT_EQ(full.collapse()[0], 7 * (std::int64_t(1) << 60));
  EXPECT_GT(full.collapse()[0], 0) << "wrapped around";
}

TEST(FixedPointAccumulator, BytesCountEveryCopy)
{
  // (copies of the low words + the high words) x records x 2 sides x frames x channels x 4
  // bytes: two copies take 12 bytes a slot, one takes 8.
  EXPECT_EQ(FixedPointAccumulator<1>::bytes(1, 10, 7), 10u * 2 * 7 * 8);
  EXPECT_EQ(FixedPointAccumulator<1>::bytes(2, 10, 7), 10u * 2 * 7 * 12);
  EXPECT_EQ(FixedPointAccumulator<3>::bytes(4, 10, 7), 5u * 10 * 2 * 7 * 3 * 4);
  // Large counts do not wrap in 32 bits.
  EXPECT_EQ(FixedPointAccumulator<3>::bytes(8, 1000000, 1000), 9ull * 1000000 * 2 * 1000 * 3 * 4);
}

TEST(FixedPointAccumulator, SidesWithoutSlotsOverflowAndLoseNothing)
{
  // Slots for some sides only (what reachability gives): scores on the others go to the
  // workers' overflow entries, and every total is the same as with slots for all.
  const std::vector<Score> scores = someScores(20000);
  const std::vector<double> reference = totals(scores, 1, true, FrameLayout::FramesInner);
  std::vector<std::uint8_t> stored(Records * 2, 0);
  for (std::size_t i = 0; i < stored.size(); i += 3)
  {
    stored[i] = 1;
  }
  std::vector<std::uint8_t> none(Records * 2, 0);
  for (const std::vector<std::uint8_t>* mask : { &stored, &none })
  {
    for (int workers : { 1, 3 })
    {
      for (bool copyPerWorker : { true, false })
      {
        for (FrameLayout layout : { FrameLayout::FramesInner, FrameLayout::FramesOuter })
        {
          EXPECT_EQ(totals(scores, workers, copyPerWorker, layout, mask), reference)
            << workers << " workers, copy per worker " << copyPerWorker;
        }
      }
    }
  }
  EXPECT_EQ(FixedPointAccumulator<1>::storedBytes(1, 4, Frames), 4u * Frames * 8);

  // Collapsed and merged (as before a sum over processes), the totals stay, and the
  // overflow is one block in side order with an entry for every flagged side.
  FixedPointAccumulator<1> sums(
    3, true, Records, Frames, Quantum, FrameLayout::FramesInner, &stored);
  for (std::size_t i = 0; i < scores.size(); ++i)
  {
    const Score& s = scores[i];
    sums.add(sums.slots(static_cast<int>(i % 3), s.record, s.side), s.frame, &s.value);
  }
  EXPECT_EQ(sums.copySize(), 4 * Frames);
  std::vector<std::int64_t> flags(Records * 2, 0);
  sums.markOverflow(flags);
  EXPECT_EQ(std::count(flags.begin(), flags.end(), 1), 6) << "every side without slots was hit";
  flags[0] = 1; // a side another process overflowed: it gets an entry of zeros
  sums.collapse();
  std::size_t count = 0;
  sums.mergeOverflow(flags, count);
  EXPECT_EQ(count, 7 * Frames);
  EXPECT_EQ(sums.overflowSides(), 7u);
  std::vector<double> merged;
  for (std::size_t r = 0; r < Records; ++r)
  {
    for (int side = 0; side < 2; ++side)
    {
      for (std::size_t f = 0; f < Frames; ++f)
      {
        double t = 0;
        sums.total(r, side, f, &t);
        merged.push_back(t);
      }
    }
  }
  EXPECT_EQ(merged, reference);
}

TEST(FixedPointAccumulator, ReadSumsGiveTheirPagesBackAndTheRestStay)
{
  // 2,000 records x 2 sides x 300 frames, FramesInner: 9.6 MB, four whole 2 MiB pages and a
  // part. Once the first half of the records is read, the pages holding only theirs go back
  // to the system (mincore: not resident), and the other records keep their sums.
  constexpr std::size_t Many = 2000, Long = 300;
  FixedPointAccumulator<1> sums(1, true, Many, Long, 1.0, FrameLayout::FramesInner);
  const double one = 1;
  for (std::size_t r = 0; r < Many; ++r)
  {
    for (std::size_t f = 0; f < Long; ++f)
    {
      sums.add(sums.slots(0, r, 0), f, &one);
    }
  }
  std::int64_t* first = sums.collapse();
  const std::size_t pageBytes = HugePageBytes;
  auto resident = [&](std::size_t page)
  {
    unsigned char flag = 0;
    EXPECT_EQ(mincore(reinterpret_cast<char*>(first) + page * pageBytes, 4096, &flag), 0);
    return (flag & 1) != 0;
  };
  EXPECT_TRUE(resident(0));
  sums.releaseBefore(Many / 2);
  // The first half's slots: 1000 records x 2 sides x 300 frames x 8 bytes = 4.8 MB, two whole
  // pages.
  EXPECT_FALSE(resident(0));
  EXPECT_FALSE(resident(1));
  EXPECT_TRUE(resident(2));
  for (std::size_t r = Many / 2; r < Many; ++r)
  {
    double t = 0;
    sums.total(r, 0, Long - 1, &t);
    ASSERT_EQ(t, 1.0) << r;
  }
}
