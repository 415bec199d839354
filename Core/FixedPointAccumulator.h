// Per-worker power accumulators in 64-bit fixed point.
//
// Integer addition is associative, so the sum over workers does not depend on which worker
// traced which path: with per-path random streams this makes the solve bit-identical for
// any thread count, without atomics in the hot loop.
#pragma once

#include "Rgb.h"

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace mlr
{

class FixedPointAccumulator
{
public:
  /// `records` items with 2 sides and `frames` RGB slots each, one copy per worker. A
  /// quantum of 2^-40 of the largest power keeps ~12 significant digits per score and
  /// leaves 2^23 times that power of headroom per slot.
  FixedPointAccumulator(int workers, std::size_t records, std::size_t frames, double maxPower)
    : Frames(frames)
    , Stride(records * 2 * frames * 3)
    , Quantum((maxPower > 0 ? maxPower : 1.0) * 0x1.0p-40)
    , Values(static_cast<std::size_t>(workers) * Stride, 0)
  {
  }

  /// The slots of (record, side) for frames [0, frames) of one worker.
  std::int64_t* slots(int worker, std::size_t record, int side)
  {
    return this->Values.data() + static_cast<std::size_t>(worker) * this->Stride +
      (record * 2 + static_cast<std::size_t>(side)) * this->Frames * 3;
  }

  /// Adds a non-negative power to one frame's RGB slot.
  void add(std::int64_t* frameSlots, std::size_t frame, const Rgb& power) const
  {
    std::int64_t* s = frameSlots + frame * 3;
    const double scale = 1.0 / this->Quantum;
    // Values are >= 0, so truncating x + 0.5 rounds to nearest.
    s[0] += static_cast<std::int64_t>(power.r * scale + 0.5);
    s[1] += static_cast<std::int64_t>(power.g * scale + 0.5);
    s[2] += static_cast<std::int64_t>(power.b * scale + 0.5);
  }

  /// The power of (record, side, frame) summed over workers.
  Rgb total(std::size_t record, int side, std::size_t frame) const
  {
    const std::size_t offset = ((record * 2 + static_cast<std::size_t>(side)) * this->Frames + frame) * 3;
    std::int64_t sum[3] = { 0, 0, 0 };
    for (std::size_t w = 0; w * this->Stride < this->Values.size(); ++w)
    {
      const std::int64_t* v = this->Values.data() + w * this->Stride + offset;
      sum[0] += v[0];
      sum[1] += v[1];
      sum[2] += v[2];
    }
    return { static_cast<double>(sum[0]) * this->Quantum,
      static_cast<double>(sum[1]) * this->Quantum, static_cast<double>(sum[2]) * this->Quantum };
  }

  /// True if any worker scored anything on (record, side) in any frame.
  bool received(std::size_t record, int side) const
  {
    const std::size_t offset = (record * 2 + static_cast<std::size_t>(side)) * this->Frames * 3;
    for (std::size_t w = 0; w * this->Stride < this->Values.size(); ++w)
    {
      const std::int64_t* v = this->Values.data() + w * this->Stride + offset;
      for (std::size_t i = 0; i < this->Frames * 3; ++i)
      {
        if (v[i] != 0)
        {
          return true;
        }
      }
    }
    return false;
  }

  static std::uint64_t bytes(int workers, std::size_t records, std::size_t frames)
  {
    return static_cast<std::uint64_t>(workers) * records * 2 * frames * 3 * sizeof(std::int64_t);
  }

private:
  std::size_t Frames;
  std::size_t Stride;
  double Quantum;
  std::vector<std::int64_t> Values;
};

} // namespace mlr
