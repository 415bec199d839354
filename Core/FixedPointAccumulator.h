// Power accumulators in 64-bit fixed point.
//
// Integer addition is associative, so the sums do not depend on which worker traced which
// path, nor in which order: with per-path random streams the solve is bit-identical for any
// thread count. While paths are scored, a slot's 64 bits are split: each worker adds to 32
// low bits of its own (plain adds), and carries into 32 high bits that all workers share
// (relaxed atomic adds, rare: the solver's quantum makes a typical add about 2^20 quanta,
// FixedPointTypicalAddBits, so a low word carries once in about 4,096 adds). Two workers
// then take 12 bytes a slot instead of the 16 of two 64-bit copies, a worker's scoring
// writes half the bytes, and the high words take memory only where a slot carried. Where even that
// is too much, the workers share the low words too (atomic adds: the memory does not grow with the
// core count; the locked adds make shooting 1.5x to 1.8x slower where the sums stay in cache, and
// the smaller footprint makes it faster where they do not). The solver picks per-worker low words
// when they fit in half the memory limit (MemoryPlan, planSolveMemory). Once shooting ends,
// collapse() adds the words into one 64-bit sum per slot.
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

/// The solver's quantum makes a typical add (one path's light in one frame) 2^20 to 2^21
/// quanta (quantumFor in Shooting.cxx): rounded to within 2^-21 of itself, far below what
/// the results keep (PackedRgb, 2^-10), and 4,096 such adds before a low word carries.
constexpr int FixedPointTypicalAddBits = 20;

/// The bytes a buffer of `bytes` takes once rounded up to whole pages (saturating):
/// FixedPointAccumulator's buffers are aligned to and allocated in whole huge pages
/// (allocateZeroed), and the last one is resident whole.
inline std::uint64_t fixedPointBufferBytes(std::uint64_t bytes)
{
  const std::uint64_t pages = bytes / HugePageBytes + (bytes % HugePageBytes != 0);
  return pages > UINT64_MAX / HugePageBytes ? UINT64_MAX : pages * HugePageBytes;
}

/// Where add() writes the frames of one (record, side): the low words of the worker (or of
/// all, shared) and the high words they carry into, slots `frameStride` apart.
struct SlotRun
{
  std::uint32_t* low = nullptr;
  std::uint32_t* high = nullptr;
  std::size_t frameStride = 0;
  bool atomicLow = false;  ///< the low words are shared by several workers
  bool atomicHigh = false; ///< the high words are shared by several workers
};

/// After collapse(): the 64-bit sums of one (record, side), frame f's channels at
/// base + f * frameStride; a null base for a side nothing scored.
struct SummedRun
{
  const std::int64_t* base = nullptr;
  std::size_t frameStride = 0;
};

/**
 * `Channels` (1 or 3) fixed-point sums for every (record, side, frame): low words per worker
 * (or one shared set) and shared high words while scoring, one 64-bit sum each once
 * collapsed. The caller picks the quantum: values are rounded to multiples of it, and a slot
 * holds up to 2^63 quanta. `stored` (record * 2 + side flags, or null for all) names the
 * sides that get slots; the others overflow into per-worker entries.
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
    , Copies(copyPerWorker ? std::max(workers, 1) : 1)
    , CopyStride(copyPerWorker ? Stride : 0)
    , SharedLow(!copyPerWorker && workers > 1)
    , SharedHigh(workers > 1)
    , Low(allocateWords<std::uint32_t>(static_cast<std::size_t>(Copies) * Stride))
    , High(allocateWords<std::uint32_t>(Stride))
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
  /// without slots gets (once) an overflow entry of the worker's own: its low words, then
  /// its high words.
  SlotRun slots(int worker, std::size_t record, int side)
  {
    const std::size_t s = this->storedIndex(record, side);
    if (s != Unstored)
    {
      const std::size_t offset = s * this->SideStride;
      return { this->Low.get() + static_cast<std::size_t>(worker) * this->CopyStride + offset,
        this->High.get() + offset, this->FrameStride, this->SharedLow, this->SharedHigh };
    }
    std::vector<std::uint32_t>& entry =
      this->Overflow[static_cast<std::size_t>(worker)][record * 2 + static_cast<std::size_t>(side)];
    if (entry.empty())
    {
      entry.assign(2 * this->Frames * Channels, 0);
    }
    return { entry.data(), entry.data() + this->Frames * Channels, Channels, false, false };
  }

  /// Adds non-negative values to one frame's slot (`values` has Channels entries).
  void add(const SlotRun& run, std::size_t frame, const double* values) const
  {
    std::uint32_t* low = run.low + frame * run.frameStride;
    std::uint32_t* high = run.high + frame * run.frameStride;
    for (int c = 0; c < Channels; ++c)
    {
      // Values are >= 0, so truncating x + 0.5 rounds to nearest.
      const auto quanta = static_cast<std::uint64_t>(values[c] * this->InverseQuantum[c] + 0.5);
      const auto part = static_cast<std::uint32_t>(quanta);
      auto carry = static_cast<std::uint32_t>(quanta >> 32);
      if (!run.atomicLow)
      {
        const std::uint32_t sum = low[c] + part;
        carry += sum < part;
        low[c] = sum;
      }
      else if (part != 0) // frames a path does not light cost no locked write
      {
        carry += __atomic_add_fetch(&low[c], part, __ATOMIC_RELAXED) < part;
      }
      if (carry == 0)
      {
        continue;
      }
      if (run.atomicHigh)
      {
        __atomic_fetch_add(&high[c], carry, __ATOMIC_RELAXED);
      }
      else
      {
        high[c] += carry;
      }
    }
  }

  /// Asks the cache for the low words add() will touch for frames [first, first + count), so
  /// that the miss overlaps work done before the add (the high words are rarely written).
  /// Always inlined: GCC's IPA finds a function that only prefetches free of side effects
  /// and deletes calls to it.
  [[gnu::always_inline]] void prefetch(
    const SlotRun& run, std::size_t first, std::size_t count) const
  {
    const std::uint32_t* begin = run.low + first * run.frameStride;
    if (run.frameStride == Channels)
    {
      const std::uint32_t* end = begin + count * Channels;
      for (const std::uint32_t* p = begin; p < end; p += 16)
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

  /// The sums of (record, side, frame) over workers, written to `out` (Channels entries),
  /// before or after collapse().
  void total(std::size_t record, int side, std::size_t frame, double* out) const
  {
    std::uint64_t sum[Channels] = {};
    const std::size_t s = this->storedIndex(record, side);
    const std::size_t key = record * 2 + static_cast<std::size_t>(side);
    if (s != Unstored)
    {
      const std::size_t i = s * this->SideStride + frame * this->FrameStride;
      for (int c = 0; c < Channels; ++c)
      {
        sum[c] = this->Summed ? static_cast<std::uint64_t>(this->Summed.get()[i + c])
                              : this->wordsAt(i + c);
      }
    }
    else
    {
      const auto merged = this->Merged.find(key);
      if (merged != this->Merged.end())
      {
        for (int c = 0; c < Channels; ++c)
        {
          sum[c] +=
            static_cast<std::uint64_t>(this->MergedValues[merged->second + frame * Channels + c]);
        }
      }
      for (const auto& worker : this->Overflow)
      {
        const auto entry = worker.find(key);
        if (entry != worker.end())
        {
          for (int c = 0; c < Channels; ++c)
          {
            sum[c] += entry->second[frame * Channels + c] +
              (std::uint64_t(entry->second[(this->Frames + frame) * Channels + c]) << 32);
          }
        }
      }
    }
    for (int c = 0; c < Channels; ++c)
    {
      out[c] = static_cast<double>(static_cast<std::int64_t>(sum[c])) * this->Quantum[c];
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

  /// Moves the workers' overflow entries into one block of 64-bit sums with an entry for
  /// every side whose flag is set (in side order, so that every process has the same
  /// block): returns it, of `count` values, to be summed over processes as a whole.
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
    const std::size_t n = this->Frames * Channels;
    for (auto& worker : this->Overflow)
    {
      for (const auto& entry : worker)
      {
        std::int64_t* into = this->MergedValues.data() + this->Merged.at(entry.first);
        for (std::size_t i = 0; i < n; ++i)
        {
          into[i] +=
            static_cast<std::int64_t>(entry.second[i] + (std::uint64_t(entry.second[n + i]) << 32));
        }
      }
      worker.clear();
    }
    count = this->MergedValues.size();
    return this->MergedValues.data();
  }

  /// After collapse() and mergeOverflow(): the sums of (record, side), or a null base for a
  /// side nothing scored.
  SummedRun summed(std::size_t record, int side) const
  {
    const std::size_t s = this->storedIndex(record, side);
    if (s != Unstored)
    {
      return { this->Summed.get() + s * this->SideStride, this->FrameStride };
    }
    const auto merged = this->Merged.find(record * 2 + static_cast<std::size_t>(side));
    if (merged == this->Merged.end())
    {
      return {};
    }
    return { this->MergedValues.data() + merged->second, Channels };
  }

  /// One frame's channels of a summed() run, in the values' units.
  void read(const SummedRun& run, std::size_t frame, double* out) const
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

  /**
   * Adds every worker's low words and the high words into one 64-bit sum per slot (the sums
   * are unchanged): returns them, copySize() values, to be summed over processes as a whole.
   * The words' pages go back to the system as they are added, so that the sums take their
   * memory: the peak stays that of the words (MemoryPlan). Later calls return the same sums.
   */
  std::int64_t* collapse()
  {
    if (this->Summed)
    {
      return this->Summed.get();
    }
    this->Summed = allocateWords<std::int64_t>(this->Stride);
    // A huge page of words at a time.
    constexpr std::size_t Block = HugePageBytes / sizeof(std::uint32_t);
    for (std::size_t begin = 0; begin < this->Stride; begin += Block)
    {
      const std::size_t end = std::min(this->Stride, begin + Block);
      for (std::size_t i = begin; i < end; ++i)
      {
        // Zeros are not written: the pages of sides nothing scored stay without memory.
        if (const std::uint64_t sum = this->wordsAt(i))
        {
          this->Summed.get()[i] = static_cast<std::int64_t>(sum);
        }
      }
      for (int copy = 0; copy < this->Copies; ++copy)
      {
        release(
          this->Low.get() + static_cast<std::size_t>(copy) * this->Stride + begin, end - begin);
      }
      release(this->High.get() + begin, end - begin);
    }
    this->Low.reset();
    this->High.reset();
    return this->Summed.get();
  }
  std::size_t copySize() const { return this->Stride; }

  /**
   * After collapse() and mergeOverflow(), once the sums of the records before `record` were
   * read for the last time: gives back the whole 2 MiB pages of the sums that hold theirs
   * alone, where each side's frames are contiguous (FramesInner, or one frame; else
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
      madvise(reinterpret_cast<char*>(this->Summed.get()) + this->ReleasedBytes,
        end - this->ReleasedBytes, MADV_DONTNEED);
#endif
      this->ReleasedBytes = end;
    }
  }

  /// Bytes of the words of `copies` low-word copies (the worker count, or 1 when shared) and
  /// the shared high words, with slots for both sides of `records` records.
  static std::uint64_t bytes(int copies, std::size_t records, std::size_t frames)
  {
    return storedBytes(copies, saturatingProduct({ records, 2 }), frames);
  }

  /// The same with slots for `sides` (record, side) pairs.
  static std::uint64_t storedBytes(int copies, std::uint64_t sides, std::size_t frames)
  {
    return saturatingProduct(
      { static_cast<std::uint64_t>(copies) + 1, sides, frames, Channels, sizeof(std::uint32_t) });
  }

  /// What those words allocate: each buffer rounded up to whole pages.
  static std::uint64_t allocatedBytes(int copies, std::size_t records, std::size_t frames)
  {
    return allocatedWords(copies, saturatingProduct({ records, 2 }), frames);
  }

  /// The same for `sides` stored sides, with their index (4 bytes per record side), and
  /// without the high words where `highWords` is false: they take memory only where a low
  /// word carried.
  static std::uint64_t allocatedStoredBytes(
    int copies, std::size_t records, std::uint64_t sides, std::size_t frames, bool highWords = true)
  {
    return saturatingSum(allocatedWords(copies, sides, frames, highWords),
      saturatingProduct({ records, 2, sizeof(std::uint32_t) }));
  }

  /**
   * Whether the high words of `sides` stored sides are likely to be written, with N `paths`
   * per frame scored by `workers` low-word copies (1 when shared): a slot's low word carries
   * after about 2^(32 - FixedPointTypicalAddBits) typical adds, and a slot takes N / sides of
   * them on average per frame (every frame's weights sum to about one per path). Below 1/16
   * of that on average, even slots 16 times as lit as the mean (under a light) rarely carry.
   */
  static bool highWordsWritten(std::uint64_t paths, int workers, std::uint64_t sides)
  {
    constexpr std::uint64_t AddsBeforeACarry = std::uint64_t(1) << (32 - FixedPointTypicalAddBits);
    return paths >=
      saturatingProduct({ AddsBeforeACarry / 16, static_cast<std::uint64_t>(std::max(workers, 1)),
        std::max<std::uint64_t>(sides, 1) });
  }

private:
  static constexpr std::uint32_t Unstored = 0xffffffffu;

  /// The low words of `copies` copies, and the high words when `highWords`, in whole pages.
  static std::uint64_t allocatedWords(
    int copies, std::uint64_t sides, std::size_t frames, bool highWords = true)
  {
    const std::uint64_t one = saturatingProduct({ sides, frames, Channels, sizeof(std::uint32_t) });
    return saturatingSum(
      fixedPointBufferBytes(saturatingProduct({ static_cast<std::uint64_t>(copies), one })),
      highWords ? fixedPointBufferBytes(one) : 0);
  }

  /// The sum of every copy's low word and the high word of slot i.
  std::uint64_t wordsAt(std::size_t i) const
  {
    std::uint64_t sum = std::uint64_t(this->High.get()[i]) << 32;
    for (int copy = 0; copy < this->Copies; ++copy)
    {
      sum += this->Low.get()[static_cast<std::size_t>(copy) * this->Stride + i];
    }
    return sum;
  }

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

  /// Gives the whole pages among `count` words back to the system: they are read no more.
  template <typename Word>
  static void release(Word* words, std::size_t count)
  {
#ifdef __linux__
    constexpr std::uintptr_t Page = 4096;
    const auto begin = reinterpret_cast<std::uintptr_t>(words);
    const auto end = reinterpret_cast<std::uintptr_t>(words + count);
    const std::uintptr_t pagesBegin = (begin + Page - 1) / Page * Page;
    const std::uintptr_t pagesEnd = end / Page * Page;
    if (pagesBegin < pagesEnd)
    {
      madvise(reinterpret_cast<void*>(pagesBegin), pagesEnd - pagesBegin, MADV_DONTNEED);
    }
#else
    (void)words;
    (void)count;
#endif
  }

  struct Free
  {
    std::size_t bytes = 0;
    void operator()(void* p) const { unmapZeroed(p, this->bytes); }
  };
  template <typename Word>
  using Words = std::unique_ptr<Word[], Free>;

  /// Scores land on random records all over the buffer (megabytes per worker): with 4 KiB
  /// pages nearly every score misses the TLB. 2 MiB pages, where the kernel grants them, cut
  /// those misses by 512. The buffer is a mapping of its own (mapZeroed), untouched (and
  /// taking no memory) until written.
  template <typename Word>
  static Words<Word> allocateWords(std::size_t count)
  {
    const std::size_t bytes = std::max<std::size_t>(count * sizeof(Word), 1);
    const std::size_t rounded = static_cast<std::size_t>(fixedPointBufferBytes(bytes));
    return Words<Word>(static_cast<Word*>(mapZeroed(rounded, HugePageBytes)), Free{ rounded });
  }

  std::size_t Records;
  std::size_t Frames;
  std::size_t StoredSides;
  std::size_t Stride;
  std::size_t SideStride;
  std::size_t FrameStride;
  std::array<double, Channels> Quantum;
  std::array<double, Channels> InverseQuantum;
  int Copies;             ///< copies of the low words: the workers, or 1 when shared
  std::size_t CopyStride; ///< 0 when the low words are shared
  bool SharedLow;         ///< one set of low words for several workers: atomic adds
  bool SharedHigh;        ///< several workers: atomic carries
  Words<std::uint32_t> Low, High;
  /// The 64-bit sums, once collapsed (and the words gone).
  Words<std::int64_t> Summed;
  /// releaseBefore's progress: the next (record, side) key, the stored sides before it and
  /// the bytes given back.
  std::size_t ReleaseKey = 0, ReleasedSides = 0, ReleasedBytes = 0;
  /// The stored index of each record * 2 + side, Unstored for none; empty when all are.
  std::vector<std::uint32_t> Slot;
  /// Per worker, the low and high words of the sides without slots that it scored
  /// (node-based, so that the runs slots() hands out stay valid as entries are added).
  std::vector<std::unordered_map<std::size_t, std::vector<std::uint32_t>>> Overflow;
  /// After mergeOverflow(): each overflowed side's offset in MergedValues.
  std::map<std::size_t, std::size_t> Merged;
  std::vector<std::int64_t> MergedValues;
};

} // namespace mlr
