// Power accumulators in 64-bit fixed point.
//
// Integer addition is associative, so the sums do not depend on which worker traced which
// path, nor in which order: with per-path random streams the solve is bit-identical for any
// thread count. Workers add either to a copy of their own (plain adds) or to one copy shared
// by all (relaxed atomic adds: the memory does not grow with the core count; the locked adds
// make shooting 1.5x to 1.8x slower where the sums stay in cache, and the smaller footprint
// makes it faster where they do not). The solver picks per-worker copies when they fit in
// half the memory limit (MemoryPlan, planSolveMemory in Solver.h).
//
// Only the (record, side) pairs light can reach need slots (Reachability.h): the outsides of
// a closed room and the insides of closed blocks are about half of all sides, so the
// accumulators keep slots for the stored sides alone. The probes that decide reachability
// are a sample, so a path may still hit a side they judged dark: such a side gets its frames
// in a per-worker overflow entry, created on its first score, which keeps every quantum
// (sums stay exact and do not depend on which sides overflowed where).
#pragma once

#include "MemoryBudget.h"
#include "ZeroedMemory.h"

#include <algorithm>
#include <array>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <new>
#include <unordered_map>
#include <vector>

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

/// The bytes a buffer of `bytes` takes once rounded up to whole pages (saturating):
/// FixedPointAccumulator's buffers are aligned to and allocated in whole huge pages
/// (allocateZeroed), and the last one is resident whole.
inline std::uint64_t fixedPointBufferBytes(std::uint64_t bytes)
{
  const std::uint64_t pages = bytes / HugePageBytes + (bytes % HugePageBytes != 0);
  return pages > UINT64_MAX / HugePageBytes ? UINT64_MAX : pages * HugePageBytes;
}

/// Where add() writes the frames of one (record, side): slots `frameStride` apart, with
/// atomic adds when the run is in a copy several workers share.
struct SlotRun
{
  std::int64_t* base = nullptr;
  std::size_t frameStride = 0;
  bool atomic = false;
};

/**
 * `Channels` (1 or 3) fixed-point sums for every (record, side, frame), in one copy per
 * worker or one shared copy. The caller picks the quantum: values are rounded to multiples
 * of it, and a slot holds up to 2^63 quanta. `stored` (record * 2 + side flags, or null for
 * all) names the sides that get slots; the others overflow into per-worker entries.
 */
template <int Channels>
class FixedPointAccumulator
{
public:
  /// One quantum for every channel.
  FixedPointAccumulator(int workers, bool copyPerWorker, std::size_t records, std::size_t frames,
    double quantum, FrameLayout layout, const std::vector<std::uint8_t>* stored = nullptr)
    : FixedPointAccumulator(
        workers, copyPerWorker, records, frames, filled(quantum), layout, stored)
  {
  }

  /// One quantum per channel: a channel much weaker than the others keeps its precision.
  FixedPointAccumulator(int workers, bool copyPerWorker, std::size_t records, std::size_t frames,
    const std::array<double, Channels>& quantum, FrameLayout layout,
    const std::vector<std::uint8_t>* stored = nullptr)
    : Records(records)
    , Frames(frames)
    , StoredSides(stored ? storedCount(*stored) : records * 2)
    , Stride(StoredSides * frames * Channels)
    , SideStride(layout == FrameLayout::FramesInner ? frames * Channels : Channels)
    , FrameStride(layout == FrameLayout::FramesInner ? Channels : StoredSides * Channels)
    , Quantum(quantum)
    , CopyStride(copyPerWorker ? Stride : 0)
    , Shared(!copyPerWorker && workers > 1)
    , Size(static_cast<std::size_t>(copyPerWorker ? workers : 1) * Stride)
    , Values(allocateZeroed(Size))
    , Overflow(stored ? static_cast<std::size_t>(workers) : 0)
  {
    for (int c = 0; c < Channels; ++c)
    {
      this->InverseQuantum[c] = 1.0 / this->Quantum[c];
    }
    if (stored)
    {
      this->Slot.assign(records * 2, Unstored);
      std::uint32_t next = 0;
      for (std::size_t i = 0; i < records * 2; ++i)
      {
        if ((*stored)[i])
        {
          this->Slot[i] = next++;
        }
      }
    }
  }

  /// The slots of (record, side) that `worker` adds to; add() steps to the frames. A side
  /// without slots gets (once) an overflow entry of the worker's own.
  SlotRun slots(int worker, std::size_t record, int side)
  {
    const std::size_t s = this->storedIndex(record, side);
    if (s != Unstored)
    {
      return { this->Values.get() + static_cast<std::size_t>(worker) * this->CopyStride +
          s * this->SideStride,
        this->FrameStride, this->Shared };
    }
    std::vector<std::int64_t>& entry =
      this->Overflow[static_cast<std::size_t>(worker)][record * 2 + static_cast<std::size_t>(side)];
    if (entry.empty())
    {
      entry.assign(this->Frames * Channels, 0);
    }
    return { entry.data(), Channels, false };
  }

  /// Adds non-negative values to one frame's slot (`values` has Channels entries).
  void add(const SlotRun& run, std::size_t frame, const double* values) const
  {
    std::int64_t* s = run.base + frame * run.frameStride;
    for (int c = 0; c < Channels; ++c)
    {
      // Values are >= 0, so truncating x + 0.5 rounds to nearest.
      const auto quanta = static_cast<std::int64_t>(values[c] * this->InverseQuantum[c] + 0.5);
      if (!run.atomic)
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
    const SlotRun& run, std::size_t first, std::size_t count) const
  {
    const std::int64_t* begin = run.base + first * run.frameStride;
    if (run.frameStride == Channels)
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
      __builtin_prefetch(begin + f * run.frameStride);
    }
  }

  /// The sums of (record, side, frame) over workers, written to `out` (Channels entries).
  void total(std::size_t record, int side, std::size_t frame, double* out) const
  {
    std::int64_t sum[Channels] = {};
    const std::size_t s = this->storedIndex(record, side);
    if (s != Unstored)
    {
      const std::int64_t* v = this->Values.get() + s * this->SideStride + frame * this->FrameStride;
      for (std::size_t w = 0; w * this->Stride < this->Size; ++w, v += this->Stride)
      {
        for (int c = 0; c < Channels; ++c)
        {
          sum[c] += v[c];
        }
      }
    }
    else
    {
      const std::size_t key = record * 2 + static_cast<std::size_t>(side);
      const auto merged = this->Merged.find(key);
      if (merged != this->Merged.end())
      {
        for (int c = 0; c < Channels; ++c)
        {
          sum[c] += this->MergedValues[merged->second + frame * Channels + c];
        }
      }
      for (const auto& worker : this->Overflow)
      {
        const auto entry = worker.find(key);
        if (entry != worker.end())
        {
          for (int c = 0; c < Channels; ++c)
          {
            sum[c] += entry->second[frame * Channels + c];
          }
        }
      }
    }
    for (int c = 0; c < Channels; ++c)
    {
      out[c] = static_cast<double>(sum[c]) * this->Quantum[c];
    }
  }

  /// Marks (adds 1 to) flags[record * 2 + side] of every side with an overflow entry here;
  /// `flags` has 2 records entries, and may be summed over processes before mergeOverflow().
  void markOverflow(std::vector<std::int64_t>& flags) const
  {
    for (const auto& worker : this->Overflow)
    {
      for (const auto& entry : worker)
      {
        flags[entry.first] = 1;
      }
    }
  }

  /// Moves the workers' overflow entries into one block with an entry for every side whose
  /// flag is set (in side order, so that every process has the same block): returns it, of
  /// `count` values, to be summed over processes as a whole.
  std::int64_t* mergeOverflow(const std::vector<std::int64_t>& flags, std::size_t& count)
  {
    std::size_t entries = 0;
    for (std::size_t key = 0; key < flags.size(); ++key)
    {
      if (flags[key] != 0)
      {
        this->Merged[key] = entries * this->Frames * Channels;
        ++entries;
      }
    }
    this->MergedValues.assign(entries * this->Frames * Channels, 0);
    for (auto& worker : this->Overflow)
    {
      for (const auto& entry : worker)
      {
        std::int64_t* into = this->MergedValues.data() + this->Merged.at(entry.first);
        for (std::size_t i = 0; i < entry.second.size(); ++i)
        {
          into[i] += entry.second[i];
        }
      }
      worker.clear();
    }
    count = this->MergedValues.size();
    return this->MergedValues.data();
  }

  /// After collapse() and mergeOverflow(): the sums of (record, side), frame f's channels at
  /// run.base + f * run.frameStride, or a null base for a side nothing scored.
  SlotRun summed(std::size_t record, int side) const
  {
    const std::size_t s = this->storedIndex(record, side);
    if (s != Unstored)
    {
      return { this->Values.get() + s * this->SideStride, this->FrameStride, false };
    }
    const auto merged = this->Merged.find(record * 2 + static_cast<std::size_t>(side));
    if (merged == this->Merged.end())
    {
      return {};
    }
    return { const_cast<std::int64_t*>(this->MergedValues.data()) + merged->second, Channels,
      false };
  }

  /// One frame's channels of a summed() run, in the values' units.
  void read(const SlotRun& run, std::size_t frame, double* out) const
  {
    for (int c = 0; c < Channels; ++c)
    {
      out[c] = run.base
        ? static_cast<double>(run.base[frame * run.frameStride + c]) * this->Quantum[c]
        : 0.0;
    }
  }

  /// Sides without slots that paths scored, over every worker.
  std::size_t overflowSides() const
  {
    std::vector<std::int64_t> flags(this->Records * 2, 0);
    this->markOverflow(flags);
    for (const auto& merged : this->Merged)
    {
      flags[merged.first] = 1;
    }
    return static_cast<std::size_t>(std::count(flags.begin(), flags.end(), 1));
  }

  /// Adds every worker's copy into the first and zeroes the others: the sums are unchanged,
  /// and the first copy (copySize() values) can then be summed over processes as a whole.
  /// The others' pages go back to the system, so the results the sums become can take their
  /// memory (MemoryPlan).
  std::int64_t* collapse()
  {
    std::int64_t* first = this->Values.get();
    for (std::size_t w = 1; w * this->Stride < this->Size; ++w)
    {
      const std::int64_t* copy = first + w * this->Stride;
      for (std::size_t i = 0; i < this->Stride; ++i)
      {
        first[i] += copy[i];
      }
    }
    if (this->Size > this->Stride)
    {
      zeroAndRelease(first + this->Stride, this->Size - this->Stride);
    }
    return first;
  }
  std::size_t copySize() const { return this->Stride; }

  /**
   * After collapse() and mergeOverflow(), once the sums of the records before `record` were
   * read for the last time: gives back the whole 2 MiB pages of the first copy that hold
   * theirs alone, where each side's frames are contiguous (FramesInner, or one frame; else
   * nothing), so that the results they become can take that memory (MemoryPlan). Records
   * are released in order; those pages read as zero afterwards.
   */
  void releaseBefore(std::size_t record)
  {
    if (this->SideStride != this->Frames * Channels && this->Frames != 1)
    {
      return;
    }
    const std::size_t limit = std::min(record, this->Records) * 2;
    for (; this->ReleaseKey < limit; ++this->ReleaseKey)
    {
      if (this->storedIndex(this->ReleaseKey / 2, static_cast<int>(this->ReleaseKey % 2)) !=
        Unstored)
      {
        ++this->ReleasedSides;
      }
    }
    const std::size_t bytes = this->ReleasedSides * this->SideStride * sizeof(std::int64_t);
    const std::size_t end = bytes / HugePageBytes * HugePageBytes;
    if (end > this->ReleasedBytes)
    {
#ifdef __linux__
      madvise(reinterpret_cast<char*>(this->Values.get()) + this->ReleasedBytes,
        end - this->ReleasedBytes, MADV_DONTNEED);
#endif
      this->ReleasedBytes = end;
    }
  }

  /// Bytes of `copies` copies (the worker count, or 1 when shared) with slots for both
  /// sides of `records` records.
  static std::uint64_t bytes(int copies, std::size_t records, std::size_t frames)
  {
    return storedBytes(copies, saturatingProduct({ records, 2 }), frames);
  }

  /// The same with slots for `sides` (record, side) pairs.
  static std::uint64_t storedBytes(int copies, std::uint64_t sides, std::size_t frames)
  {
    return saturatingProduct(
      { static_cast<std::uint64_t>(copies), sides, frames, Channels, sizeof(std::int64_t) });
  }

  /// What those copies allocate: bytes() rounded up to whole pages.
  static std::uint64_t allocatedBytes(int copies, std::size_t records, std::size_t frames)
  {
    return fixedPointBufferBytes(bytes(copies, records, frames));
  }

  /// storedBytes() rounded up to whole pages, and the index of the stored sides (4 bytes per
  /// record side).
  static std::uint64_t allocatedStoredBytes(
    int copies, std::size_t records, std::uint64_t sides, std::size_t frames)
  {
    return saturatingSum(fixedPointBufferBytes(storedBytes(copies, sides, frames)),
      saturatingProduct({ records, 2, sizeof(std::uint32_t) }));
  }

private:
  static constexpr std::uint32_t Unstored = 0xffffffffu;

  std::size_t storedIndex(std::size_t record, int side) const
  {
    const std::size_t key = record * 2 + static_cast<std::size_t>(side);
    return this->Slot.empty() ? key : (this->Slot[key] == Unstored ? Unstored : this->Slot[key]);
  }

  static std::size_t storedCount(const std::vector<std::uint8_t>& stored)
  {
    return static_cast<std::size_t>(
      std::count_if(stored.begin(), stored.end(), [](std::uint8_t s) { return s != 0; }));
  }

  static std::array<double, Channels> filled(double value)
  {
    std::array<double, Channels> a;
    a.fill(value);
    return a;
  }

  /// Zeroes `count` values: the whole pages among them are given back (they read as zero
  /// again, and take memory only when written), the rest are written.
  static void zeroAndRelease(std::int64_t* values, std::size_t count)
  {
    char* begin = reinterpret_cast<char*>(values);
    char* end = begin + count * sizeof(std::int64_t);
#ifdef __linux__
    constexpr std::uintptr_t Page = 4096;
    char* pagesBegin =
      reinterpret_cast<char*>((reinterpret_cast<std::uintptr_t>(begin) + Page - 1) / Page * Page);
    char* pagesEnd = reinterpret_cast<char*>(reinterpret_cast<std::uintptr_t>(end) / Page * Page);
    if (pagesBegin < pagesEnd && madvise(pagesBegin, pagesEnd - pagesBegin, MADV_DONTNEED) == 0)
    {
      std::memset(begin, 0, pagesBegin - begin);
      std::memset(pagesEnd, 0, end - pagesEnd);
      return;
    }
#endif
    std::memset(begin, 0, end - begin);
  }

  struct Free
  {
    std::size_t bytes = 0;
    void operator()(std::int64_t* p) const { unmapZeroed(p, this->bytes); }
  };

  /// Scores land on random records all over the buffer (megabytes per worker): with 4 KiB
  /// pages nearly every score misses the TLB. 2 MiB pages, where the kernel grants them, cut
  /// those misses by 512. The buffer is a mapping of its own (mapZeroed).
  static std::unique_ptr<std::int64_t[], Free> allocateZeroed(std::size_t count)
  {
    const std::size_t bytes = std::max<std::size_t>(count * sizeof(std::int64_t), 1);
    const std::size_t rounded = static_cast<std::size_t>(fixedPointBufferBytes(bytes));
    return std::unique_ptr<std::int64_t[], Free>(
      static_cast<std::int64_t*>(mapZeroed(rounded, HugePageBytes)), Free{ rounded });
  }

  std::size_t Records;
  std::size_t Frames;
  std::size_t StoredSides;
  std::size_t Stride;
  std::size_t SideStride;
  std::size_t FrameStride;
  std::array<double, Channels> Quantum;
  std::array<double, Channels> InverseQuantum;
  std::size_t CopyStride; ///< 0 when the copy is shared
  bool Shared;            ///< one copy for several workers: atomic adds
  std::size_t Size;
  std::unique_ptr<std::int64_t[], Free> Values;
  /// releaseBefore's progress: the next (record, side) key, the stored sides before it and
  /// the bytes given back.
  std::size_t ReleaseKey = 0, ReleasedSides = 0, ReleasedBytes = 0;
  /// The stored index of each record * 2 + side, Unstored for none; empty when all are.
  std::vector<std::uint32_t> Slot;
  /// Per worker, the frames of the sides without slots that it scored (node-based, so that
  /// the runs slots() hands out stay valid as entries are added).
  std::vector<std::unordered_map<std::size_t, std::vector<std::int64_t>>> Overflow;
  /// After mergeOverflow(): each overflowed side's offset in MergedValues.
  std::map<std::size_t, std::size_t> Merged;
  std::vector<std::int64_t> MergedValues;
};

} // namespace mlr
