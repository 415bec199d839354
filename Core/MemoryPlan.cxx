#include "MemoryPlan.h"

#include "Chunks.h"
#include "ErrorEstimate.h"
#include "FixedPointAccumulator.h"
#include "Gathering.h"

#include "Parallel.h"
#include "Plural.h"
#include "Reachability.h"
#include "Rgb.h"

#include <algorithm>
#include <string>

namespace mlr
{

namespace
{
/// The huge pages that written runs make resident in a fresh mapping aligned to them, the
/// runs added in increasing order of offset: each page is counted once.
class WrittenPages
{
public:
  void add(std::uint64_t begin, std::uint64_t bytes)
  {
    if (bytes == 0)
    {
      return;
    }
    const std::uint64_t first = std::max(begin / HugePageBytes, this->Next);
    const std::uint64_t last = (begin + bytes - 1) / HugePageBytes;
    if (last >= first)
    {
      this->Pages += last - first + 1;
      this->Next = last + 1;
    }
  }
  std::uint64_t bytes() const { return saturatingProduct({ this->Pages, HugePageBytes }); }

private:
  std::uint64_t Pages = 0, Next = 0;
};

/**
 * The bytes of `copies` copies (one after the other in one mapping) of the elements' shooting
 * sums, words of `wordBytes`, that direct light writes: the runs of `frames` words of the
 * element sides of the `firstHits` patch sides, among the stored (`reachable`) ones in their
 * order (FixedPointAccumulator, FramesInner).
 */
std::uint64_t writtenShareBytes(std::size_t patches, std::size_t frames,
  const std::vector<std::uint8_t>& reachable, const std::vector<std::uint8_t>& firstHits,
  std::uint64_t copies, std::uint64_t wordBytes)
{
  const std::uint64_t run = saturatingProduct({ frames, wordBytes });
  const std::uint64_t stored = saturatingProduct(
    { static_cast<std::uint64_t>(
        std::count_if(reachable.begin(), reachable.end(), [](std::uint8_t r) { return r != 0; })),
      Scene::ElementsPerPatch });
  const std::uint64_t whole = fixedPointBufferBytes(saturatingProduct({ copies, stored, run }));
  if (whole == UINT64_MAX)
  {
    return whole;
  }
  WrittenPages pages;
  for (std::uint64_t copy = 0; copy < copies; ++copy)
  {
    std::uint64_t index = copy * stored;
    for (std::size_t e = 0; e < patches * Scene::ElementsPerPatch; ++e)
    {
      for (std::size_t s = 0; s < 2; ++s)
      {
        const std::size_t key = Scene::patchOfElement(e) * 2 + s;
        if (reachable[key])
        {
          if (firstHits[key])
          {
            pages.add(index * run, run);
          }
          ++index;
        }
      }
    }
  }
  return std::min(whole, pages.bytes());
}
}

std::uint64_t writtenResultBytes(std::size_t patches, std::size_t recordsPerPatch,
  std::size_t frames, const std::vector<std::uint8_t>* reachable, std::size_t valueBytes)
{
  // One patch side's records, contiguous.
  const std::uint64_t run = saturatingProduct({ recordsPerPatch, frames, valueBytes });
  const std::uint64_t whole = saturatingProduct({ patches, 2, run });
  if (!reachable || reachable->size() != 2 * patches || run == 0 || whole == UINT64_MAX)
  {
    return whole;
  }
  // Offsets grow with (side, patch).
  WrittenPages pages;
  for (std::size_t s = 0; s < 2; ++s)
  {
    for (std::size_t p = 0; p < patches; ++p)
    {
      if ((*reachable)[2 * p + s])
      {
        pages.add((s * patches + p) * run, run);
      }
    }
  }
  return std::min(whole, pages.bytes());
}

MemoryPlan planSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights,
  const std::vector<std::uint8_t>* reachable, const std::vector<std::uint8_t>* firstHits)
{
  const std::uint64_t workers = static_cast<std::uint64_t>(resolveThreadCount(options.threads));
  MemoryPlan plan;
  // Results are written for the reachable sides alone (and the few sides of the overflow,
  // not counted), into the pages of those sides' runs: the patches where paths bounce, the
  // indirect light where gathering runs, the direct light where first hits land. Those the
  // probes from the lights found are a sample of the last: a side lit only by chance, in a
  // page no probe found, is not counted.
  const bool perPatch = elements == patches * Scene::ElementsPerPatch;
  const bool lit = firstHits && reachable && firstHits->size() == reachable->size();
  const std::uint64_t direct = perPatch
    ? writtenResultBytes(patches, Scene::ElementsPerPatch, frames, lit ? firstHits : reachable)
    : saturatingProduct({ frames, elements, 2, sizeof(PackedRgb) });
  const std::uint64_t patch = writtenResultBytes(patches, 1, frames, reachable);
  const std::uint64_t indirect =
    perPatch ? writtenResultBytes(patches, Scene::ElementsPerPatch, frames, reachable) : direct;
  plan.results = saturatingSum(saturatingSum(direct, patch), indirect);
  // The accumulators of `copies` copies, for elements and for patches: a scalar share per
  // element side and RGB power per patch side, for every frame, each buffer in whole pages;
  // once reachability is known, for the reachable sides alone, with an index of the sides.
  // The overflow of sides the probes missed is not counted: a few sides at most.
  struct Accumulators
  {
    std::uint64_t elements = 0, patches = 0;
    std::uint64_t all() const { return saturatingSum(elements, patches); }
  };
  // `collapsed`: the one 64-bit sum per slot that the words become once shooting ends (the
  // same bytes as one copy of the words with its high words).
  const auto accumulators = [&](std::uint64_t copies, bool collapsed = false)
  {
    const int c = static_cast<int>(copies);
    if (!reachable)
    {
      return Accumulators{ FixedPointAccumulator<1>::allocatedBytes(c, elements, frames),
        FixedPointAccumulator<3>::allocatedBytes(c, patches, frames) };
    }
    const std::uint64_t patchSides = std::min<std::uint64_t>(
      static_cast<std::uint64_t>(std::count(reachable->begin(), reachable->end(), 1)), 2 * patches);
    const std::uint64_t elementSides = elements == 0
      ? 0
      : saturatingProduct({ patchSides, elements / std::max<std::size_t>(patches, 1) });
    const std::uint64_t paths = options.pathsPerFrame;
    const bool highWords =
      collapsed || FixedPointAccumulator<1>::highWordsWritten(paths, c, elementSides);
    // Frames innermost, the words of the sides no first hit lands on stay unwritten; but over
    // several ranks the collapsed sums are summed in place, every slot written.
    std::uint64_t shares = 0;
    if (lit && perPatch && options.reuseShooting && frames > 1 && !(collapsed && options.ranks > 1))
    {
      // The low words (or the 64-bit sums once collapsed), the high words, the index.
      shares = saturatingSum(
        saturatingSum(writtenShareBytes(patches, frames, *reachable, *firstHits,
                        collapsed ? 1 : copies, collapsed ? 8 : 4),
          !collapsed && highWords ? writtenShareBytes(patches, frames, *reachable, *firstHits, 1, 4)
                                  : 0),
        saturatingProduct({ elements, 2, sizeof(std::uint32_t) }));
    }
    else
    {
      shares = FixedPointAccumulator<1>::allocatedStoredBytes(
        c, elements, elementSides, frames, highWords);
    }
    return Accumulators{ saturatingSum(
                           shares, saturatingProduct({ elements, 2 })), // the element sides' flags
      FixedPointAccumulator<3>::allocatedStoredBytes(c, patches, patchSides, frames,
        collapsed || FixedPointAccumulator<3>::highWordsWritten(paths, c, patchSides)) };
  };
  // Per worker: the weights, targets, frames and visibility of one path, and a gathering row.
  const std::uint64_t scratch = saturatingProduct({ workers, frames,
    sizeof(double) + 3 * sizeof(float) + sizeof(std::uint32_t) + sizeof(std::uint8_t) +
      sizeof(Rgb) });
  // Embree's BVH and buffers, the emission, reflectance and lit side of every element. The
  // ray tracer measured 3 MiB for 11,328 elements and 34 MiB for 421,680 (a fixed 2 MiB and
  // 75 bytes an element): counted as 4 MiB and 128 bytes an element.
  const std::uint64_t tracing =
    saturatingSum(saturatingSum(std::uint64_t(4) << 20, saturatingProduct({ elements, 128 })),
      saturatingProduct({ points, 16 }));
  const std::uint64_t perElement = saturatingProduct({ elements, 2 * sizeof(Rgb) + sizeof(Side) });
  // Reachability: the probes' hits and their reverse edges (gone before gathering rays).
  const std::uint64_t reachability =
    saturatingProduct({ patches, 2, 2 * ReachabilityProbesPerSide + 2, sizeof(std::uint32_t) });
  // Per frame and light: its pose copied into the rig (120 bytes), its power factor (24) and
  // the shooting run's pose coefficients and path counts (112), measured.
  const std::uint64_t lightData =
    saturatingProduct({ frames, std::max<std::uint64_t>(lights, 1), 256 });
  // A batched solve's running mean and squared deviations live through every batch; its
  // standard errors are allocated after the last batch, when no accumulators are left.
  plan.errorEstimate = errorEstimateBytes(patches, elements, frames, options, reachable);
  const std::uint64_t standardErrors = plan.errorEstimate > 0 ? indirect : 0;
  const std::uint64_t base = saturatingSum(
    saturatingSum(saturatingSum(scratch, tracing), saturatingSum(perElement, lightData)),
    plan.errorEstimate - standardErrors);
  plan.other = saturatingSum(base, reachability);
  // Gathering holds, beside the indirect light, what its rays read for a block of frames (a
  // row per element side, written where the indirect light is) and, with reuse over several
  // blocks, the element sides a group of sides' rays reached (Gathering.h): up to the default
  // budget, less when the limit leaves less room, a frame of rows at least.
  const std::uint64_t gatheringResults = saturatingSum(
    saturatingSum(saturatingSum(direct, patch), saturatingSum(indirect, reachability)),
    standardErrors);
  const std::uint64_t gatheringHeld = saturatingSum(gatheringResults, base);
  const std::uint64_t limit = memoryLimitBytes(options);
  const GatheringBudget full;
  const std::uint64_t room = limit > gatheringHeld ? limit - gatheringHeld : 0;
  const std::uint64_t budget = std::min(saturatingSum(full.rowBytes, full.hitBytes), room);
  plan.gathering.rowBytes = budget / 3 * 2;
  plan.gathering.hitBytes = budget / 3;
  const std::size_t blockFrames = gatheringBlockFrames(elements, frames, plan.gathering.rowBytes);
  const std::uint64_t readRows = perPatch
    ? writtenResultBytes(patches, Scene::ElementsPerPatch, blockFrames, reachable)
    : saturatingProduct({ blockFrames, elements, 2, sizeof(PackedRgb) });
  const auto rays = static_cast<std::uint64_t>(
    std::max(0.0, options.gatheringRatio * static_cast<double>(options.pathsPerFrame)));
  const std::uint64_t gatheringRays = options.reuseGathering && blockFrames < frames
    ? std::min<std::uint64_t>(plan.gathering.hitBytes, saturatingProduct({ rays, 4 }))
    : 0;
  // The standard errors are allocated once the last batch has gathered, its rows and rays
  // freed: they take the room of those, not more.
  const std::uint64_t gathering = saturatingSum(gatheringResults - standardErrors,
    std::max(saturatingSum(readRows, gatheringRays), standardErrors));
  // Shooting: the direct light and the patches take memory only once written (ZeroedAllocator
  // in Solution.h), when a source's sums are turned into them, after the workers' copies were
  // collapsed into one and the others' pages given back. With one source that is the larger
  // of its copies while it shoots and what the conversion holds: where each side's frames
  // are contiguous in the sums (reuse, or one frame) their pages are given back as they are
  // read (FixedPointAccumulator::releaseBefore), so the elements' sums shrink as the direct
  // light grows, then the patches' as the patches grow; else one copy beside the results.
  // A later source shoots beside the results of the ones before.
  const bool released = frames == 1 || options.reuseShooting;
  const auto peakWith = [&](std::uint64_t copies)
  {
    const std::uint64_t results = saturatingSum(direct, patch);
    const Accumulators shooting = accumulators(copies), one = accumulators(1, true);
    std::uint64_t peak = saturatingSum(results, shooting.all());
    if (lights <= 1 && released)
    {
      peak = std::max({ shooting.all(), saturatingSum(one.patches, std::max(one.elements, direct)),
        saturatingSum(direct, std::max(one.patches, patch)) });
    }
    else if (lights <= 1)
    {
      peak = std::max(shooting.all(), saturatingSum(one.all(), results));
    }
    return saturatingSum(base, std::max(peak, gathering));
  };
  plan.accumulatorCopyPerWorker =
    workers == 1 || peakWith(workers) <= memoryLimitBytes(options) / 2;
  const std::uint64_t copies = plan.accumulatorCopyPerWorker ? workers : 1;
  plan.accumulators = accumulators(copies).all();
  plan.peak = peakWith(copies);
  return plan;
}

std::uint64_t estimateSolveMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights)
{
  return planSolveMemory(patches, elements, points, frames, options, lights).peak;
}

std::uint64_t estimateSolveMemory(
  const Scene& scene, std::size_t frames, const SolverOptions& options, std::size_t lights)
{
  return estimateSolveMemory(
    scene.patchCount(), scene.elementCount(), scene.points().size(), frames, options, lights);
}

std::uint64_t estimateChunkedMemory(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, std::size_t framesPerChunk, const SolverOptions& options, std::size_t lights,
  std::uint64_t fixedBytes, bool streamed, std::size_t keptChunks,
  const std::vector<std::uint8_t>* reachable, const std::vector<std::uint8_t>* firstHits)
{
  if (framesPerChunk == 0 || framesPerChunk >= frames)
  {
    return saturatingSum(
      planSolveMemory(patches, elements, points, frames, options, lights, reachable, firstHits)
        .peak,
      fixedBytes);
  }
  const std::size_t m = chunkOverlap(framesPerChunk, options.chunkOverlap);
  // The frames a Solution holds outside a solve: direct and indirect irradiance and the
  // patches, and the standard errors of a batched solve.
  const std::uint64_t perFrame = saturatingProduct(
    { 2 * elements * (errorEstimateBytes(patches, elements, 1, options) > 0 ? 3 : 2) + 2 * patches,
      sizeof(PackedRgb) });
  const std::uint64_t solving = planSolveMemory(patches, elements, points,
    std::min(frames, framesPerChunk + 2 * m), options, lights, reachable, firstHits)
                                  .peak;
  std::size_t finished = streamed ? framesPerChunk : frames;
  if (streamed && keptChunks > 0)
  {
    const std::size_t chunks =
      planChunks(frames, framesPerChunk, options.chunkOverlap).chunks.size();
    const auto ranks = static_cast<std::size_t>(std::max(options.ranks, 1));
    const std::size_t received = chunks >= ranks ? (chunks + ranks - 1) / ranks : chunks;
    finished = std::min(frames, std::min(keptChunks, received) * framesPerChunk);
  }
  const std::uint64_t held = saturatingProduct(perFrame, 2 * m + finished);
  return saturatingSum(saturatingSum(solving, held), fixedBytes);
}

std::size_t chooseFramesPerChunk(std::size_t patches, std::size_t elements, std::size_t points,
  std::size_t frames, const SolverOptions& options, std::size_t lights, std::uint64_t fixedBytes,
  bool streamed, std::size_t keptChunks, const std::vector<std::uint8_t>* reachable,
  const std::vector<std::uint8_t>* firstHits)
{
  if (options.framesPerChunk > 0)
  {
    return static_cast<std::size_t>(std::min<std::uint64_t>(options.framesPerChunk, frames));
  }
  const std::uint64_t limit = memoryLimitBytes(options);
  auto fits = [&](std::size_t c)
  {
    return estimateChunkedMemory(patches, elements, points, frames, c, options, lights, fixedBytes,
             streamed, keptChunks, reachable, firstHits) <= limit;
  };
  if (frames <= MinimumFramesPerChunk || fits(frames))
  {
    return frames;
  }
  // The estimate grows with C: the largest C that fits, by bisection.
  std::size_t lo = MinimumFramesPerChunk, hi = frames - 1;
  if (!fits(lo))
  {
    return lo;
  }
  while (lo < hi)
  {
    const std::size_t mid = lo + (hi - lo + 1) / 2;
    if (fits(mid))
    {
      lo = mid;
    }
    else
    {
      hi = mid - 1;
    }
  }
  return lo;
}

std::uint64_t memoryLimitBytes(const SolverOptions& options)
{
  return MemoryBudget(options.memoryLimitBytes).limitBytes();
}

void checkSolveMemory(std::uint64_t estimate, std::size_t frames, std::size_t patches,
  std::size_t elements, const SolverOptions& options, bool approximate, std::size_t sensors,
  std::uint64_t sensorBytes, bool couldStream, std::uint64_t skyBytes, std::size_t framesPerChunk)
{
  const std::string about = approximate ? "about " : "";
  const std::size_t overlap =
    framesPerChunk > 0 ? chunkOverlap(framesPerChunk, options.chunkOverlap) : 0;
  std::string detail =
    (framesPerChunk > 0 ? countOf(std::min(frames, framesPerChunk + 2 * overlap), "position") +
          " (a chunk of " + countOf(framesPerChunk, "frame") + " and " + std::to_string(overlap) +
          " more on each side)"
                        : countOf(frames, "frame")) +
    " x (" + about + std::to_string(patches) + " patches + " + about + std::to_string(elements) +
    " elements) x 2 sides x RGB, plus per-thread buffers";
  std::string advice = couldStream
    ? "use fewer frames or a larger patch size, keep fewer frames in memory (the filter's "
      "CachedChunks: the others are solved again when shown), or raise the limit"
    : "use fewer frames or a larger patch size, or raise the limit";
  if (framesPerChunk > MinimumFramesPerChunk && options.framesPerChunk > 0)
  {
    advice = "use fewer frames per chunk (FramesPerChunk, --frames-per-chunk; 0 lets the "
             "memory limit choose) or a larger patch size, or raise the limit";
  }
  else if (framesPerChunk > 0)
  {
    // The shortest chunks, given or chosen by the limit: fewer frames would not help.
    advice = "even chunks of " + countOf(framesPerChunk, "frame") +
      " do not fit: use a larger patch size (fewer elements), or raise the limit";
  }
  if (sensors > 0)
  {
    detail += ", and " + countOf(sensors, "sensor") + " (" + gibibytes(sensorBytes) + ")";
    if (sensorBytes > estimate / 2)
    {
      advice = "use fewer sensors (a coarser grid) or fewer sensor rays (SensorRays, "
               "--sensor-rays), or raise the limit";
    }
  }
  if (skyBytes > 0)
  {
    detail += ", and the sky's tables (" + gibibytes(skyBytes) + ")";
    if (skyBytes > estimate / 2)
    {
      advice = "solve fewer frames of a sky that changes (fewer dates or hours), or raise the "
               "limit";
    }
  }
  MemoryBudget(options.memoryLimitBytes).check(estimate, "the solve", detail, advice);
}

} // namespace mlr
