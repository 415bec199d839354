// Power accumulators in 64-bit fixed point.
//
// Integer addition is associative, so the sums do not depend on which worker traced which
// path, nor in which order: with per-path random streams the solve is bit-identical for any
// thread count. Workers add either to a copy of their own (plain adds) or to one copy shared
// by all (relaxed atomic adds: the memory does not grow with the core count; the locked adds
// make shooting 1.5x to 1.8x slower where the sums stay in cache, and the smaller footprint
// makes it faster where they do not). The solver picks per-worker copies when they fit in
// half the memory limit (MemoryPlan, planSolveMemory in Solver.h).
#pragma once

#include "MemoryBudget.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <new>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace mlr
{

/// How the frames of one (record, side) are laid out.
enum class FrameLayout
{
  /// Frames contiguous per record: reuse scores every frame of one record at once.
  FramesInner,
  /// One block per frame: a classic solve scores one frame at a time, and one frame's block
  /// stays in cache where the whole buffer would not.
  FramesOuter,
};

/// FixedPointAccumulator's buffers are aligned to and allocated in whole 2 MiB pages (see
/// allocateZeroed). With transparent huge pages the last page is resident whole, so the
/// memory plan counts the rounded size.
constexpr std::uint64_t FixedPointPageBytes = std::uint64_t(2) << 20;

/// The bytes a buffer of `bytes` takes once rounded up to whole pages (saturating).
inline std::uint64_t fixedPointBufferBytes(std::uint64_t bytes)
{
  const std::uint64_t pages = bytes / FixedPointPageBytes + (bytes % FixedPointPageBytes != 0);
  return pages > UINT64_MAX / FixedPointPageBytes ? UINT64_MAX : pages * FixedPointPageBytes;
}

/**
 * `Channels` (1 or 3) fixed-point sums for every (record, side, frame), in one copy per
 * worker or one shared copy. The caller picks the quantum: values are rounded to multiples
 * of it, and a slot holds up to 2^63 quanta.
 */
template <int Channels>
class FixedPointAccumulator
{
public:
  /// One quantum for every channel.
  FixedPointAccumulator(int workers, bool copyPerWorker, std::size_t records, std::size_t frames,
    double quantum, FrameLayout layout)
    : FixedPointAccumulator(workers, copyPerWorker, records, frames, filled(quantum), layout)
  {
  }

  /// One quantum per channel: a channel much weaker than the others keeps its precision.
  FixedPointAccumulator(int workers, bool copyPerWorker, std::size_t records, std::size_t frames,
    const std::array<double, Channels>& quantum, FrameLayout layout)
    : Stride(records * 2 * frames * Channels)
    , RecordStride(layout == FrameLayout::FramesInner ? 2 * frames * Channels : 2 * Channels)
    , SideStride(layout == FrameLayout::FramesInner ? frames * Channels : Channels)
    , FrameStride(layout == FrameLayout::FramesInner ? Channels : records * 2 * Channels)
    , Quantum(quantum)
    , CopyStride(copyPerWorker ? Stride : 0)
    , Shared(!copyPerWorker && workers > 1)
    , Size(static_cast<std::size_t>(copyPerWorker ? workers : 1) * Stride)
    , Values(allocateZeroed(Size))
  {
    for (int c = 0; c < Channels; ++c)
    {
      this->InverseQuantum[c] = 1.0 / this->Quantum[c];
    }
  }

  /// The slots of (record, side) at frame 0 that `worker` adds to; add() steps to other
  /// frames.
  std::int64_t* slots(int worker, std::size_t record, int side)
  {
    return this->Values.get() + static_cast<std::size_t>(worker) * this->CopyStride +
      this->offset(record, side, 0);
  }

  /// Adds non-negative values to one frame's slot (`values` has Channels entries).
  void add(std::int64_t* recordSlots, std::size_t frame, const double* values) const
  {
    std::int64_t* s = recordSlots + frame * this->FrameStride;
    for (int c = 0; c < Channels; ++c)
    {
      // Values are >= 0, so truncating x + 0.5 rounds to nearest.
      const auto quanta = static_cast<std::int64_t>(values[c] * this->InverseQuantum[c] + 0.5);
      if (!this->Shared)
      {
        s[c] += quanta;
      }
      else if (quanta != 0) // frames a path does not light cost no locked write
      {
        __atomic_fetch_add(&s[c], quanta, __ATOMIC_RELAXED);
      }
    }
  }

  /// Asks the cache for the slots add() will touch for frames [first, first + count), so
  /// that the miss overlaps work done before the add. Always inlined: GCC's IPA finds a
  /// function that only prefetches free of side effects and deletes calls to it.
  [[gnu::always_inline]] void prefetch(
    const std::int64_t* recordSlots, std::size_t first, std::size_t count) const
  {
    const std::int64_t* begin = recordSlots + first * this->FrameStride;
    if (this->FrameStride == Channels)
    {
      const std::int64_t* end = begin + count * Channels;
      for (const std::int64_t* p = begin; p < end; p += 8)
      {
        __builtin_prefetch(p);
      }
      __builtin_prefetch(end - 1);
      return;
    }
    for (std::size_t f = 0; f < count; ++f)
    {
      __builtin_prefetch(begin + f * this->FrameStride);
    }
  }

  /// The sums of (record, side, frame) over workers, written to `out` (Channels entries).
  void total(std::size_t record, int side, std::size_t frame, double* out) const
  {
    const std::int64_t* v = this->Values.get() + this->offset(record, side, frame);
    std::int64_t sum[Channels] = {};
    for (std::size_t w = 0; w * this->Stride < this->Size; ++w, v += this->Stride)
    {
      for (int c = 0; c < Channels; ++c)
      {
        sum[c] += v[c];
      }
    }
    for (int c = 0; c < Channels; ++c)
    {
      out[c] = static_cast<double>(sum[c]) * this->Quantum[c];
    }
  }

  /// Adds every worker's copy into the first and zeroes the others: the sums are unchanged,
  /// and the first copy (copySize() values) can then be summed over processes as a whole.
  std::int64_t* collapse()
  {
    std::int64_t* first = this->Values.get();
    for (std::size_t w = 1; w * this->Stride < this->Size; ++w)
    {
      std::int64_t* copy = first + w * this->Stride;
      for (std::size_t i = 0; i < this->Stride; ++i)
      {
        first[i] += copy[i];
        copy[i] = 0;
      }
    }
    return first;
  }
  std::size_t copySize() const { return this->Stride; }

  /// Bytes of `copies` copies (the worker count, or 1 when shared).
  static std::uint64_t bytes(int copies, std::size_t records, std::size_t frames)
  {
    return saturatingProduct(
      { static_cast<std::uint64_t>(copies), records, 2, frames, Channels, sizeof(std::int64_t) });
  }

  /// What those copies allocate: bytes() rounded up to whole pages.
  static std::uint64_t allocatedBytes(int copies, std::size_t records, std::size_t frames)
  {
    return fixedPointBufferBytes(bytes(copies, records, frames));
  }

private:
  std::size_t offset(std::size_t record, int side, std::size_t frame) const
  {
    return record * this->RecordStride + static_cast<std::size_t>(side) * this->SideStride +
      frame * this->FrameStride;
  }

  static std::array<double, Channels> filled(double value)
  {
    std::array<double, Channels> a;
    a.fill(value);
    return a;
  }

  struct Free
  {
    void operator()(std::int64_t* p) const { std::free(p); }
  };

  /// Scores land on random records all over the buffer (megabytes per worker): with 4 KiB
  /// pages nearly every score misses the TLB. 2 MiB pages, where the kernel grants them, cut
  /// those misses by 512.
  static std::unique_ptr<std::int64_t[], Free> allocateZeroed(std::size_t count)
  {
    const std::size_t bytes = std::max<std::size_t>(count * sizeof(std::int64_t), 1);
    const std::size_t rounded = static_cast<std::size_t>(fixedPointBufferBytes(bytes));
    void* memory = std::aligned_alloc(FixedPointPageBytes, rounded);
    if (!memory)
    {
      throw std::bad_alloc();
    }
#ifdef MADV_HUGEPAGE
    madvise(memory, rounded, MADV_HUGEPAGE);
#endif
    std::memset(memory, 0, bytes);
    return std::unique_ptr<std::int64_t[], Free>(static_cast<std::int64_t*>(memory));
  }

  std::size_t Stride;
  std::size_t RecordStride;
  std::size_t SideStride;
  std::size_t FrameStride;
  std::array<double, Channels> Quantum;
  std::array<double, Channels> InverseQuantum;
  std::size_t CopyStride; ///< 0 when the copy is shared
  bool Shared;            ///< one copy for several workers: atomic adds
  std::size_t Size;
  std::unique_ptr<std::int64_t[], Free> Values;
};

} // namespace mlr
