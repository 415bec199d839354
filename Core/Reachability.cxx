#include "Reachability.h"

#include "Parallel.h"
#include "Random.h"
#include "RayTracer.h"

#include <algorithm>
#include <limits>

namespace mlr
{

namespace
{
/// Probe walks from each light (spread over its positions) that find the sides it lights
/// first; a fixed number, so that reachability does not depend on N or the seed.
constexpr std::uint64_t ReachabilityProbesPerLight = 16384;
/// The fixed seed of the reachability probes.
constexpr std::uint64_t ReachabilitySeed = 0x5eed;

constexpr std::size_t ReachabilityPatchesPerTask = 64;
}

std::vector<std::uint8_t> reachableSides(const Scene& scene, const RayTracer& tracer,
  const std::vector<LightSource>& sources, const SolverOptions& options, int workers,
  const std::function<bool(double)>& keepGoing, std::uint64_t& rays,
  std::vector<std::uint8_t>* firstHits)
{
  const std::size_t patches = scene.patchCount();
  const std::size_t sides = 2 * patches;
  const bool twoSided = options.twoSided;
  constexpr std::uint32_t None = std::numeric_limits<std::uint32_t>::max();
  auto sideOf = [&](std::uint32_t element, Side side) -> std::uint32_t
  {
    if (!twoSided && side == Side::Back)
    {
      return None;
    }
    return static_cast<std::uint32_t>(
      Scene::patchOfElement(element) * 2 + static_cast<std::size_t>(side));
  };

  // Seeds, one slot per probe so that the result does not depend on scheduling.
  std::vector<std::uint32_t> seeds;
  for (std::size_t l = 0; l < sources.size(); ++l)
  {
    const LightSource& source = sources[l];
    const std::vector<std::size_t>& active = source.activePositions();
    if (active.empty())
    {
      continue;
    }
    const std::uint64_t perPosition =
      std::max<std::uint64_t>(64, ReachabilityProbesPerLight / active.size());
    const std::uint64_t total = perPosition * active.size();
    const std::size_t first = seeds.size();
    seeds.resize(first + total, None);
    const std::uint64_t perTask = 1024;
    parallelFor((total + perTask - 1) / perTask, workers,
      [&](std::size_t task, int)
      {
        for (std::uint64_t i = task * perTask; i < std::min(total, (task + 1) * perTask); ++i)
        {
          RandomStream random(ReachabilitySeed + l, StreamPurpose::Reachability, i, 0);
          EmittedPath path;
          source.emit(active[i / perPosition], random, tracer.surfaceOffset(), path);
          std::uint32_t element = 0;
          Side side = Side::Front;
          if (tracer.nearestSide(path.start, path.direction, element, side))
          {
            seeds[first + i] = sideOf(element, side);
          }
        }
      },
      [&](std::size_t) { return keepGoing(0.0); });
    rays += total;
  }

  // Probes from every side.
  constexpr std::size_t K = ReachabilityProbesPerSide;
  std::vector<std::uint32_t> probe(sides * K, None);
  const auto& points = scene.points();
  const std::size_t tasks = (patches + ReachabilityPatchesPerTask - 1) / ReachabilityPatchesPerTask;
  parallelFor(
    tasks, workers,
    [&](std::size_t task, int)
    {
      for (std::size_t p = task * ReachabilityPatchesPerTask;
           p < std::min(patches, (task + 1) * ReachabilityPatchesPerTask); ++p)
      {
        const Triangle& t = scene.patchTriangles()[p];
        for (int s = 0; s < (twoSided ? 2 : 1); ++s)
        {
          const Vec3 normal = s == 0 ? scene.patchNormal(p) : -scene.patchNormal(p);
          const std::size_t side = 2 * p + static_cast<std::size_t>(s);
          RandomStream random(ReachabilitySeed, StreamPurpose::Reachability, side, 1);
          for (std::size_t r = 0; r < K; ++r)
          {
            const double u1 = random.uniform(), u2 = random.uniform();
            const Vec3 origin = sampleTriangle(points[t[0]], points[t[1]], points[t[2]], u1, u2);
            const Vec3 direction = sampleCosineDirection(normal, random);
            std::uint32_t element = 0;
            Side hitSide = Side::Front;
            if (tracer.nearestSide(tracer.liftOff(origin, normal), direction, element, hitSide))
            {
              probe[side * K + r] = sideOf(element, hitSide);
            }
          }
        }
      }
    },
    [&](std::size_t done)
    {
      return keepGoing(
        static_cast<double>(done) / static_cast<double>(std::max<std::size_t>(tasks, 1)));
    });
  rays += patches * (twoSided ? 2 : 1) * K;

  // Reverse edges (compressed rows), then a breadth-first search from the seeds over both.
  std::vector<std::uint32_t> reverseStart(sides + 1, 0);
  for (std::uint32_t to : probe)
  {
    if (to != None)
    {
      ++reverseStart[to + 1];
    }
  }
  for (std::size_t i = 0; i < sides; ++i)
  {
    reverseStart[i + 1] += reverseStart[i];
  }
  std::vector<std::uint32_t> reverse(reverseStart[sides]);
  {
    std::vector<std::uint32_t> fill(reverseStart.begin(), reverseStart.end() - 1);
    for (std::size_t from = 0; from < sides; ++from)
    {
      for (std::size_t r = 0; r < K; ++r)
      {
        const std::uint32_t to = probe[from * K + r];
        if (to != None)
        {
          reverse[fill[to]++] = static_cast<std::uint32_t>(from);
        }
      }
    }
  }
  std::vector<std::uint8_t> reached(sides, 0);
  std::vector<std::uint32_t> queue;
  auto visit = [&](std::uint32_t side)
  {
    if (side != None && !reached[side])
    {
      reached[side] = 1;
      queue.push_back(side);
    }
  };
  for (std::uint32_t s : seeds)
  {
    visit(s);
  }
  if (firstHits)
  {
    firstHits->assign(sides, 0);
    for (std::uint32_t s : seeds)
    {
      if (s != None)
      {
        (*firstHits)[s] = 1;
      }
    }
  }
  for (std::size_t head = 0; head < queue.size(); ++head)
  {
    const std::uint32_t side = queue[head];
    for (std::size_t r = 0; r < K; ++r)
    {
      visit(probe[side * K + r]);
    }
    for (std::uint32_t i = reverseStart[side]; i < reverseStart[side + 1]; ++i)
    {
      visit(reverse[i]);
    }
  }
  return reached;
}

} // namespace mlr
