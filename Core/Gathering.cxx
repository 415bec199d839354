#include "Gathering.h"

#include "Parallel.h"
#include "Random.h"
#include "Ranks.h"
#include "RayTracer.h"

#include <algorithm>
#include <cmath>

namespace mlr
{

namespace
{
constexpr std::size_t GatheringSidesPerTask = 32;

/// The four elements' reconstructed bounced light (LinearStencil::elementValues) of side
/// `side` of `patch` in `frame`.
void elementsBounced(const Scene& scene, const Solution& solution, std::size_t frame,
  std::size_t patch, Side side, Rgb* out)
{
  const LinearStencil& stencil = scene.patchStencil(patch);
  const Side other = side == Side::Front ? Side::Back : Side::Front;
  const Rgb own = solution.patchBounced(frame, patch, side);
  Rgb neighbours[LinearStencil::MaxNeighbours];
  for (int i = 0; i < stencil.count; ++i)
  {
    const auto n = static_cast<std::size_t>(i);
    neighbours[i] =
      solution.patchBounced(frame, stencil.neighbour[n], stencil.flipped[n] ? other : side);
  }
  stencil.elementValues(own, neighbours, out);
}

/// What gathering reads (gatheredRadiosity()) for frames [begin, begin + length): each
/// element side's row of `length` values, laid out as the results are (the front sides, then
/// the back sides), so that the memory plan counts their written pages alike.
struct ReadRows
{
  std::size_t elements = 0, begin = 0, length = 0;
  StoredArray values;
  std::size_t index(std::size_t element, std::size_t side) const
  {
    return (side * this->elements + element) * this->length;
  }
  const PackedRgb* row(std::uint32_t elementSide) const
  {
    return this->values.data() + this->index(elementSide / 2, elementSide % 2);
  }
};

/// Fills `rows` for its frames, for the sides of the reachable patch sides (the others read
/// zero and stay unwritten), in the solution's storage unit.
void readRows(const Scene& scene, const Solution& solution,
  const std::vector<std::uint8_t>& reachable, int workers, ReadRows& rows)
{
  rows.values = StoredArray(2 * scene.elementCount() * rows.length);
  constexpr std::size_t PatchesPerTask = 256;
  const double unit = 1.0 / solution.storageScale();
  auto readPatchSide = [&](std::size_t p, Side side)
  {
    for (std::size_t f = 0; f < rows.length; ++f)
    {
      Rgb bounced[Scene::ElementsPerPatch];
      elementsBounced(scene, solution, rows.begin + f, p, side, bounced);
      for (std::size_t k = 0; k < Scene::ElementsPerPatch; ++k)
      {
        const std::size_t e = p * Scene::ElementsPerPatch + k;
        // In the solution's storage unit, as the rows are read.
        const Rgb value =
          Rgb(solution.directData()[solution.elementIndex(rows.begin + f, e, side)]) *
            solution.reflectance(e) +
          bounced[k] * unit;
        rows.values[rows.index(e, static_cast<std::size_t>(side)) + f] = PackedRgb(value);
      }
    }
  };
  parallelFor((scene.patchCount() + PatchesPerTask - 1) / PatchesPerTask, workers,
    [&](std::size_t task, int)
    {
      for (std::size_t p = task * PatchesPerTask;
           p < std::min(scene.patchCount(), (task + 1) * PatchesPerTask); ++p)
      {
        for (const Side side : { Side::Front, Side::Back })
        {
          if (reachable[2 * p + static_cast<std::size_t>(side)])
          {
            readPatchSide(p, side);
          }
        }
      }
    },
    [](std::size_t) { return true; });
}

/// Appends the element sides (2 element + side) that one side's `rays` rays reach, in ray
/// order, from the gathering stream `stream` (0 with reuse: one set of rays serves every
/// frame; 1 + frame without).
void castRays(const Scene& scene, const RayTracer& tracer, const SolverOptions& options,
  std::uint32_t elementSide, std::uint64_t rays, std::uint64_t stream,
  std::vector<std::uint32_t>& hits, WorkerCounters& counters)
{
  const std::size_t element = elementSide / 2;
  const Side side = static_cast<Side>(elementSide % 2);
  const Triangle& t = scene.elementTriangles()[element];
  const auto& points = scene.points();
  const Vec3 normal = scene.elementSideNormal(element, side);
  RandomStream random(options.seed, StreamPurpose::Gathering, elementSide, stream);
  for (std::uint64_t r = 0; r < rays; ++r)
  {
    const double u1 = random.uniform(), u2 = random.uniform();
    const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
    const Vec3 direction = sampleCosineDirection(normal, random);
    ++counters.gatheringRays;
    std::uint32_t hitElement = 0;
    Side hitSide = Side::Front;
    if (!tracer.nearestSide(tracer.liftOff(origin, normal), direction, hitElement, hitSide))
    {
      ++counters.missedRays;
      continue;
    }
    if (!options.twoSided && hitSide == Side::Back)
    {
      continue;
    }
    hits.push_back(2 * hitElement + static_cast<std::uint32_t>(hitSide));
  }
}

/// Adds the rows of `count` hits, frames [first, first + frames) of the rows' block, into
/// `sum` (one Rgb per frame). Rows are prefetched a few hits ahead, so that their cache
/// misses overlap the adding of the rows before them.
void addRows(const ReadRows& rows, const std::uint32_t* hits, std::size_t count, std::size_t first,
  std::size_t frames, Rgb* sum)
{
  constexpr std::size_t Ahead = 16;
  auto prefetch = [&](std::size_t h)
  {
    const char* bytes = reinterpret_cast<const char*>(rows.row(hits[h]) + first);
    for (std::size_t byte = 0; byte < frames * sizeof(PackedRgb); byte += 64)
    {
      __builtin_prefetch(bytes + byte);
    }
  };
  for (std::size_t h = 0; h < std::min(count, Ahead); ++h)
  {
    prefetch(h);
  }
  for (std::size_t h = 0; h < count; ++h)
  {
    if (h + Ahead < count)
    {
      prefetch(h + Ahead);
    }
    const PackedRgb* row = rows.row(hits[h]) + first;
    for (std::size_t f = 0; f < frames; ++f)
    {
      sum[f] += Rgb(row[f]);
    }
  }
}

}

std::size_t gatheringBlockFrames(std::size_t elements, std::size_t frames, std::uint64_t rowBytes)
{
  const std::uint64_t perFrame = std::max<std::uint64_t>(2 * elements * sizeof(PackedRgb), 1);
  return static_cast<std::size_t>(
    std::clamp<std::uint64_t>(rowBytes / perFrame, 1, std::max<std::size_t>(frames, 1)));
}

Rgb gatheredRadiosity(
  const Scene& scene, const Solution& solution, std::size_t frame, std::size_t element, Side side)
{
  Rgb bounced[Scene::ElementsPerPatch];
  elementsBounced(scene, solution, frame, Scene::patchOfElement(element), side, bounced);
  return bounced[element % Scene::ElementsPerPatch] + solution.direct(frame, element, side);
}

void gatheredRadiosities(const Scene& scene, const Solution& solution, std::size_t frame,
  std::size_t patch, Side side, Rgb* out)
{
  elementsBounced(scene, solution, frame, patch, side, out);
  for (std::size_t k = 0; k < Scene::ElementsPerPatch; ++k)
  {
    out[k] += solution.direct(frame, patch * Scene::ElementsPerPatch + k, side);
  }
}

std::vector<std::uint32_t> gatheringSides(
  const Scene& scene, const std::vector<std::uint8_t>& reachable, double& rays, std::uint64_t total)
{
  std::vector<std::uint32_t> sides;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    if (!(scene.patchReflectance(p).maxComponent() > 0))
    {
      continue;
    }
    for (int s = 0; s < 2; ++s)
    {
      if (reachable[2 * p + static_cast<std::size_t>(s)])
      {
        for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch;
             ++e)
        {
          sides.push_back(static_cast<std::uint32_t>(e * 2 + static_cast<std::size_t>(s)));
        }
      }
    }
  }
  std::sort(sides.begin(), sides.end());
  rays = sides.empty()
    ? 0.0
    : std::max(1.0, static_cast<double>(total) / static_cast<double>(sides.size()));
  return sides;
}

std::uint64_t raysOfSide(double raysPerSide, std::uint64_t seed, std::uint32_t elementSide)
{
  const double whole = std::floor(raysPerSide);
  // A stream of its own: the rays' streams have b = 0 (reuse) or 1 + frame.
  RandomStream dither(seed, StreamPurpose::Gathering, elementSide, ~std::uint64_t(0));
  return static_cast<std::uint64_t>(whole) + (dither.uniform() < raysPerSide - whole ? 1 : 0);
}

std::vector<std::uint32_t> blackSides(
  const Scene& scene, const std::vector<std::uint8_t>& reachable)
{
  std::vector<std::uint32_t> sides;
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    if (scene.patchReflectance(p).maxComponent() > 0)
    {
      continue;
    }
    for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch; ++e)
    {
      for (std::size_t s = 0; s < 2; ++s)
      {
        if (reachable[2 * p + s])
        {
          sides.push_back(static_cast<std::uint32_t>(e * 2 + s));
        }
      }
    }
  }
  return sides;
}

GatheringResult gatherIndirect(const Scene& scene, const RayTracer& tracer,
  const SolverOptions& options, const std::vector<std::uint8_t>& reachable, int workers,
  const std::function<bool(double fraction)>& fraction, double& secondsReducing, Solution& solution,
  const GatheringBudget& budget)
{
  double raysPerSide = 0;
  const auto total = static_cast<std::uint64_t>(
    std::llround(options.gatheringRatio * static_cast<double>(options.pathsPerFrame)));
  std::vector<std::uint32_t> sides = gatheringSides(scene, reachable, raysPerSide, total);
  // Black sides gather after the others, at their rate (they do not change it, so the others'
  // results do not depend on them), for their irradiance alone.
  const std::vector<std::uint32_t> black = blackSides(scene, reachable);
  if (sides.empty() && !black.empty())
  {
    raysPerSide = std::max(1.0, static_cast<double>(total) / static_cast<double>(black.size()));
  }
  sides.insert(sides.end(), black.begin(), black.end());
  const std::size_t frames = solution.frameCount();
  const bool reuse = options.reuseGathering;
  const std::size_t tasks = (sides.size() + GatheringSidesPerTask - 1) / GatheringSidesPerTask;
  std::vector<WorkerCounters> counters(static_cast<std::size_t>(workers));
  // The rows of what rays read are held for a block of frames at a time, so that they take
  // a bounded share of memory (MemoryPlan). With reuse and several blocks, a group of sides
  // casts its rays once and keeps the element side each reached (4 bytes a ray, at most
  // budget.hitBytes), then adds the rows block by block; with one block nothing is kept.
  const std::size_t block = gatheringBlockFrames(scene.elementCount(), frames, budget.rowBytes);
  const std::size_t blocks = (frames + block - 1) / block;
  const bool keepHits = reuse && blocks > 1;
  const std::size_t tasksPerGroup = keepHits
    ? std::max<std::size_t>(1,
        budget.hitBytes /
          std::max<std::uint64_t>(1,
            static_cast<std::uint64_t>(std::ceil(raysPerSide)) * GatheringSidesPerTask *
              sizeof(std::uint32_t)))
    : std::max<std::size_t>(tasks, 1);
  const std::size_t groups = (tasks + tasksPerGroup - 1) / tasksPerGroup;
  std::vector<std::vector<Rgb>> sums(static_cast<std::size_t>(workers));
  std::vector<std::vector<std::uint32_t>> scratchHits(static_cast<std::size_t>(workers));
  StoredArray& indirect = solution.indirectData();
  ReadRows rows;
  rows.elements = scene.elementCount();
  bool held = false;
  auto holdBlock = [&](std::size_t b)
  {
    if (held && rows.begin == b * block)
    {
      return;
    }
    rows.begin = b * block;
    rows.length = std::min(block, frames - rows.begin);
    readRows(scene, solution, reachable, workers, rows);
    held = true;
  };
  for (std::size_t g = 0; g < groups; ++g)
  {
    const std::size_t first = g * tasksPerGroup;
    const std::size_t count = std::min(tasksPerGroup, tasks - first);
    // Progress: the groups in turn; in a group that keeps its hits, casting is most of it.
    const double castShare = keepHits ? 0.8 : 0.0;
    auto progress = [&](double inGroup)
    { return fraction((static_cast<double>(g) + inGroup) / static_cast<double>(groups)); };
    std::vector<std::vector<std::uint32_t>> hits(keepHits ? count : 0);
    std::vector<std::vector<std::uint32_t>> hitEnds(keepHits ? count : 0);
    if (keepHits)
    {
      runOnRanks(
        count, workers, options,
        [&](std::size_t j, int worker)
        {
          const std::size_t task = first + j;
          const std::size_t end = std::min(sides.size(), (task + 1) * GatheringSidesPerTask);
          for (std::size_t i = task * GatheringSidesPerTask; i < end; ++i)
          {
            castRays(scene, tracer, options, sides[i],
              raysOfSide(raysPerSide, options.seed, sides[i]), 0, hits[j],
              counters[static_cast<std::size_t>(worker)]);
            hitEnds[j].push_back(static_cast<std::uint32_t>(hits[j].size()));
          }
        },
        [&](double done) { return progress(castShare * done); }, secondsReducing);
    }
    for (std::size_t b = 0; b < blocks; ++b)
    {
      holdBlock(b);
      runOnRanks(
        count, workers, options,
        [&](std::size_t j, int worker)
        {
          const std::size_t task = first + j;
          const auto w = static_cast<std::size_t>(worker);
          std::vector<Rgb>& sum = sums[w];
          const std::size_t end = std::min(sides.size(), (task + 1) * GatheringSidesPerTask);
          for (std::size_t i = task * GatheringSidesPerTask; i < end; ++i)
          {
            const std::uint32_t side = sides[i];
            const std::uint64_t rays = raysOfSide(raysPerSide, options.seed, side);
            sum.assign(rows.length, Rgb());
            if (keepHits)
            {
              const std::size_t k = i - task * GatheringSidesPerTask;
              const std::size_t from = k == 0 ? 0 : hitEnds[j][k - 1];
              addRows(
                rows, hits[j].data() + from, hitEnds[j][k] - from, 0, rows.length, sum.data());
            }
            else
            {
              // With reuse one set of rays (stream 0) for every frame; without, each frame
              // casts its own (stream 1 + frame).
              for (std::size_t f = 0; f < (reuse ? 1 : rows.length); ++f)
              {
                scratchHits[w].clear();
                castRays(scene, tracer, options, side, rays, reuse ? 0 : rows.begin + f + 1,
                  scratchHits[w], counters[w]);
                addRows(rows, scratchHits[w].data(), scratchHits[w].size(), reuse ? 0 : f,
                  reuse ? rows.length : 1, &sum[reuse ? 0 : f]);
              }
            }
            // The rows were read as stored, in the solution's storage unit, which the mean
            // keeps.
            for (std::size_t f = 0; f < rows.length; ++f)
            {
              indirect[solution.elementIndex(rows.begin + f, side / 2,
                static_cast<Side>(side % 2))] = PackedRgb(sum[f] / static_cast<double>(rays));
            }
          }
        },
        [&](double done)
        {
          return progress(castShare +
            (1 - castShare) * (static_cast<double>(b) + done) / static_cast<double>(blocks));
        },
        secondsReducing);
    }
  }
  // Each element side gathered on one rank and is exactly zero on the others, so the sum
  // over ranks is that rank's value, bit for bit.
  sumStoredAcrossRanks(options, indirect.data(), indirect.size(), secondsReducing);
  GatheringResult result;
  result.sides = sides.size();
  for (const WorkerCounters& c : counters)
  {
    result.counters += c;
  }
  return result;
}

void indirectFromPatches(const Scene& scene, Solution& solution)
{
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    const Rgb& rho = scene.patchReflectance(p);
    // As irradiance: a channel the patch does not reflect shows none of its indirect light.
    const auto irradiance = [](double bounced, double reflectance)
    { return reflectance > 0 ? bounced / reflectance : 0.0; };
    for (int s = 0; s < 2; ++s)
    {
      for (std::size_t f = 0; f < solution.frameCount(); ++f)
      {
        const Rgb b = solution.patchBounced(f, p, static_cast<Side>(s));
        if (b.r == 0 && b.g == 0 && b.b == 0)
        {
          continue; // the zeros are there: a side light cannot reach stays unwritten
        }
        const Rgb rest(irradiance(b.r, rho.r), irradiance(b.g, rho.g), irradiance(b.b, rho.b));
        for (std::size_t e = p * 4; e < p * 4 + 4; ++e)
        {
          solution.indirectData()[solution.elementIndex(f, e, static_cast<Side>(s))] =
            solution.store(rest);
        }
      }
    }
  }
}

} // namespace mlr
