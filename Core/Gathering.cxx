#include "Gathering.h"

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

/**
 * What gathering reads at every element side and frame (gatheredRadiosity()), stored, for the
 * sides of the reachable patch sides (the others read zero and stay unwritten).
 */
StoredArray gatheredRows(
  const Scene& scene, const Solution& solution, const std::vector<std::uint8_t>& reachable)
{
  StoredArray rows(solution.directData().size());
  const std::size_t frames = solution.frameCount();
  for (std::size_t p = 0; p < scene.patchCount(); ++p)
  {
    for (const Side side : { Side::Front, Side::Back })
    {
      if (!reachable[2 * p + static_cast<std::size_t>(side)])
      {
        continue;
      }
      for (std::size_t f = 0; f < frames; ++f)
      {
        Rgb bounced[Scene::ElementsPerPatch];
        elementsBounced(scene, solution, f, p, side, bounced);
        for (std::size_t k = 0; k < Scene::ElementsPerPatch; ++k)
        {
          const std::size_t e = p * Scene::ElementsPerPatch + k;
          // In the solution's storage unit, as the rows are stored.
          const Rgb value = Rgb(solution.directData()[solution.elementIndex(f, e, side)]) *
              solution.reflectance(e) +
            bounced[k] * (1.0 / solution.storageScale());
          rows[solution.elementIndex(f, e, side)] = PackedRgb(value);
        }
      }
    }
  }
  return rows;
}

/**
 * Final gathering for one element side: `rays` cosine-distributed rays from uniform points
 * on it; each ray that reaches an element side adds the row of what it reads there
 * (gatheredRows). Their mean is the side's indirect irradiance (the Solution applies rho_e).
 * With reuse one set of rays serves every frame; otherwise each frame casts its own.
 */
void gather(const Scene& scene, const RayTracer& tracer, const SolverOptions& options,
  std::uint32_t elementSide, std::uint64_t rays, const StoredArray& readable, Solution& solution,
  std::vector<Rgb>& sum, WorkerCounters& counters)
{
  const std::size_t frames = solution.frameCount();
  const bool reuse = options.reuseGathering;
  const std::size_t element = elementSide / 2;
  const Side side = static_cast<Side>(elementSide % 2);
  const Triangle& t = scene.elementTriangles()[element];
  const auto& points = scene.points();
  const Vec3 normal = scene.elementSideNormal(element, side);
  sum.assign(frames, Rgb());

  // A hit's row is added after the next ray is traced: it was prefetched when the hit was
  // found, so the trace hides its cache misses.
  const std::size_t passes = reuse ? 1 : frames;
  const std::size_t rowLength = reuse ? frames : 1;
  for (std::size_t pass = 0; pass < passes; ++pass)
  {
    Rgb* into = reuse ? sum.data() : &sum[pass];
    const PackedRgb* pending = nullptr;
    auto addPending = [&]
    {
      if (pending)
      {
        for (std::size_t f = 0; f < rowLength; ++f)
        {
          into[f] += Rgb(pending[f]);
        }
        pending = nullptr;
      }
    };
    RandomStream random(options.seed, StreamPurpose::Gathering, elementSide, reuse ? 0 : pass + 1);
    for (std::uint64_t r = 0; r < rays; ++r)
    {
      const double u1 = random.uniform(), u2 = random.uniform();
      const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
      const Vec3 direction = sampleCosineDirection(normal, random);
      ++counters.gatheringRays;
      std::uint32_t hitElement = 0;
      Side hitSide = Side::Front;
      const bool found =
        tracer.nearestSide(tracer.liftOff(origin, normal), direction, hitElement, hitSide);
      addPending();
      if (!found)
      {
        ++counters.missedRays;
        continue;
      }
      if (!options.twoSided && hitSide == Side::Back)
      {
        continue;
      }
      pending = readable.data() + solution.elementIndex(reuse ? 0 : pass, hitElement, hitSide);
      const char* bytes = reinterpret_cast<const char*>(pending);
      for (std::size_t byte = 0; byte < rowLength * sizeof(PackedRgb); byte += 64)
      {
        __builtin_prefetch(bytes + byte);
      }
    }
    addPending();
  }
  const double perRay = 1.0 / static_cast<double>(rays);
  for (std::size_t f = 0; f < frames; ++f)
  {
    // The rows were read as stored, in the solution's storage unit, which the mean keeps.
    solution.indirectData()[solution.elementIndex(f, element, side)] = PackedRgb(sum[f] * perRay);
  }
}

}

Rgb gatheredRadiosity(
  const Scene& scene, const Solution& solution, std::size_t frame, std::size_t element, Side side)
{
  Rgb bounced[Scene::ElementsPerPatch];
  elementsBounced(scene, solution, frame, Scene::patchOfElement(element), side, bounced);
  return bounced[element % Scene::ElementsPerPatch] + solution.direct(frame, element, side);
}

std::vector<std::uint32_t> gatheringSides(const Scene& scene,
  const std::vector<std::uint8_t>& reachable, std::uint64_t& rays, std::uint64_t total)
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
    ? 0
    : static_cast<std::uint64_t>(std::max<long long>(
        1, std::llround(static_cast<double>(total) / static_cast<double>(sides.size()))));
  return sides;
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
  const std::function<bool(double fraction)>& fraction, double& secondsReducing, Solution& solution)
{
  std::uint64_t raysPerSide = 0;
  const auto total = static_cast<std::uint64_t>(
    std::llround(options.gatheringRatio * static_cast<double>(options.pathsPerFrame)));
  std::vector<std::uint32_t> sides = gatheringSides(scene, reachable, raysPerSide, total);
  // Black sides gather after the others, at their rate (they do not change it, so the others'
  // results do not depend on them), for their irradiance alone.
  const std::vector<std::uint32_t> black = blackSides(scene, reachable);
  if (sides.empty() && !black.empty())
  {
    raysPerSide = static_cast<std::uint64_t>(std::max<long long>(
      1, std::llround(static_cast<double>(total) / static_cast<double>(black.size()))));
  }
  sides.insert(sides.end(), black.begin(), black.end());
  const StoredArray readable = gatheredRows(scene, solution, reachable);
  std::vector<WorkerCounters> counters(static_cast<std::size_t>(workers));
  std::vector<std::vector<Rgb>> sums(static_cast<std::size_t>(workers));
  const std::size_t tasks = (sides.size() + GatheringSidesPerTask - 1) / GatheringSidesPerTask;
  runOnRanks(
    tasks, workers, options,
    [&](std::size_t task, int worker)
    {
      const std::size_t end = std::min(sides.size(), (task + 1) * GatheringSidesPerTask);
      for (std::size_t i = task * GatheringSidesPerTask; i < end; ++i)
      {
        gather(scene, tracer, options, sides[i], raysPerSide, readable, solution,
          sums[static_cast<std::size_t>(worker)], counters[static_cast<std::size_t>(worker)]);
      }
    },
    fraction, secondsReducing);
  // Each element side gathered on one rank and is exactly zero on the others, so the sum
  // over ranks is that rank's value, bit for bit.
  StoredArray& indirect = solution.indirectData();
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
