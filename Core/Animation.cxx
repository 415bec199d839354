#include "Animation.h"

#include "Error.h"
#include "ErrorEstimate.h"
#include "MemoryBudget.h"

#include <algorithm>
#include <optional>

namespace mlr
{

namespace
{
/// Share of the progress given to remeshing; the solve takes the rest.
constexpr double RemeshingShare = 0.05;

/// Share of the progress given to the sensors, when there are any.
constexpr double SensorShare = 0.05;

std::uint64_t outputBytes(const AnimationOptions& options, const LightRig& lights, bool emits,
  std::size_t elements, std::size_t points, std::size_t frames)
{
  const std::size_t sensors = options.sensors.size();
  return saturatingSum(saturatingSum(saturatingProduct(options.outputBytesPerElement, elements),
                         saturatingProduct(options.outputBytesPerPoint, points)),
    saturatingSum(estimateSensorMemory(sensors, frames, elements, points, lights, emits,
                    options.solver, options.sensorOptions),
      saturatingProduct({ options.outputBytesPerSensorFrame, sensors, frames })));
}

/// The bytes `soup` holds, which the solve's memory check counts: the caller keeps it
/// through the solve. Each polygon's indices are a heap block of their own (glibc: 16-byte
/// granules, 8 bytes of header, 32 at least).
std::uint64_t soupBytes(const PolygonSoup& soup)
{
  std::uint64_t bytes = soup.points.capacity() * sizeof(Vec3) +
    soup.polygons.capacity() * sizeof(soup.polygons[0]) +
    soup.materials.capacity() * sizeof(Material);
  for (const auto& polygon : soup.polygons)
  {
    if (polygon.capacity() > 0)
    {
      bytes += std::max<std::uint64_t>(
        32, (polygon.capacity() * sizeof(std::uint32_t) + 8 + 15) / 16 * 16);
    }
  }
  return bytes;
}

/// Ranks whose memory limits chose different chunks would add up different solves: every
/// rank's C is compared (the sums of C and C^2 agree with R C and R C^2 only when all are C).
void agreeOnChunks(const SolverOptions& options, std::size_t framesPerChunk)
{
  if (options.ranks <= 1)
  {
    return;
  }
  const auto c = static_cast<std::int64_t>(framesPerChunk);
  std::int64_t sums[2] = { c, c * c };
  options.sumAcrossRanks(sums, 2);
  if (sums[0] * sums[0] != options.ranks * sums[1])
  {
    throw Error("the ranks' memory limits chose different chunk lengths: give the frames per "
                "chunk (--frames-per-chunk, FramesPerChunk) so that every rank solves the same "
                "chunks");
  }
}
}

Animation solveAnimation(const PolygonSoup& soup, const LightRig& lights,
  const AnimationOptions& options, const ProgressCallback& progress)
{
  validateOptions(options.solver);
  if (!options.sensors.empty())
  {
    checkSensors(options.sensors, options.sensorOptions);
  }
  bool soupEmits = false;
  for (const Material& m : soup.materials)
  {
    soupEmits = soupEmits || m.emission.maxComponent() > 0;
  }
  const std::size_t frames = frameCount(lights, soupEmits);
  // The sources the solver shoots, the scene's emitters counted as one at least.
  const std::size_t lightCount = lights.areaLights.size() + lights.pointLights.size() +
    lights.directionalLights.size() + lights.skies.size() + (soupEmits ? 1 : 0);
  const bool streamed = static_cast<bool>(options.chunkFrames);
  if (streamed && !options.sensors.empty())
  {
    throw Error("sensors need every frame of the animation at once: solve them without "
                "streaming the frames chunk by chunk");
  }
  // The chunks' length, from the memory limit unless set, and the one memory check of the
  // solve in those chunks, with what lives beside it: the caller's outputs and input, the
  // scene and its patches.
  std::size_t framesPerChunk = frames;
  // The caller holds the soup and the rig through the solve: a year's sky tables are half a
  // GiB.
  std::uint64_t skyBytes = 0;
  for (const Sky& sky : lights.skies)
  {
    skyBytes = saturatingSum(skyBytes, sky.allocatedBytes());
  }
  const std::uint64_t input = saturatingSum(soupBytes(soup), skyBytes);
  std::uint64_t checkedBytes = 0;
  auto checkChunkedMemory = [&](std::size_t patches, std::size_t elements, std::size_t points,
                              bool approximate, const SolveSetup* setup = nullptr)
  {
    const std::vector<std::uint8_t>* reachable = setup ? &setup->reachable() : nullptr;
    const std::vector<std::uint8_t>* firstHits = setup ? &setup->firstHits() : nullptr;
    const std::uint64_t outputs =
      saturatingSum(saturatingSum(outputBytes(options, lights, soupEmits, elements, points, frames),
                      Scene::estimateMemory(patches, elements, points, soupEmits)),
        input);
    const std::size_t kept = streamed ? options.keptStreamedChunks : 0;
    framesPerChunk = chooseFramesPerChunk(patches, elements, points, frames, options.solver,
      lightCount, outputs, streamed, kept, reachable, firstHits);
    const std::size_t sensors = options.sensors.size();
    checkedBytes = estimateChunkedMemory(patches, elements, points, frames, framesPerChunk,
      options.solver, lightCount, outputs, streamed, kept, reachable, firstHits);
    // Streamed in chunks, a chunk's positions are held, not the frames.
    const bool chunked = streamed && framesPerChunk < frames;
    checkSolveMemory(checkedBytes, frames, patches, elements, options.solver, approximate, sensors,
      saturatingSum(estimateSensorMemory(sensors, frames, elements, points, lights, soupEmits,
                      options.solver, options.sensorOptions),
        saturatingProduct({ options.outputBytesPerSensorFrame, sensors, frames })),
      !streamed && sensors == 0 && options.solver.ranks <= 1 && frames > 2 * MinimumFramesPerChunk,
      skyBytes, chunked ? framesPerChunk : 0);
  };

  RemeshOptions remeshing = options.remeshing;
  remeshing.memoryLimitBytes = options.solver.memoryLimitBytes;
  // A solve that cannot fit is refused before remeshing does the work (CGAL may take a
  // while), with the patch count remeshing expects once the polygons are triangulated,
  // halved so that an estimate on the high side never refuses a solve that fits (the exact
  // check follows remeshing).
  remeshing.checkExpectedPatches = [&](std::size_t expected)
  {
    const std::size_t patches = expected / 2;
    checkChunkedMemory(patches, 4 * patches, 2 * patches, true);
  };
  ProgressCallback remeshProgress;
  if (progress)
  {
    remeshProgress = [&](double f) { return progress(RemeshingShare * f); };
  }
  // Ranks of a distributed solve remesh the same scene alike; they agree before solving, so
  // that one cancelled or over its memory limit stops them all.
  Animation animation;
  agreeAcrossRanks(options.solver,
    [&]
    {
      RemeshResult remeshed = remesh(soup, remeshing, remeshProgress);
      if (options.sceneWarning)
      {
        // Shown now: they often explain why the memory check below refuses the solve, or why
        // a run stopped before its end gave no result worth waiting for.
        for (const std::string& warning : remeshed.warnings)
        {
          options.sceneWarning(warning);
        }
      }
      else
      {
        animation.warnings = std::move(remeshed.warnings);
      }
      animation.remeshing = remeshed.statistics;
      animation.scene = Scene::fromPatchMesh(remeshed.mesh);
      animation.patches = std::move(remeshed.mesh);
      const Scene& scene = animation.scene;
      checkChunkedMemory(scene.patchCount(), scene.elementCount(), scene.points().size(), false);
    });
  const Scene& scene = animation.scene;

  // The tracer and the sides light can reach, built once for every chunk (SolveSetup); its
  // share of the solve's progress by its expected cost. Unless given, the chunks' length is chosen
  // again from the memory those sides take, less than the bound of every side checked above
  // (a quarter less in the large room of Performance.md): longer chunks, fewer seams.
  const double sensorShare = options.sensors.empty() ? 0.0 : SensorShare;
  const double solveShare = 1 - RemeshingShare - sensorShare;
  const double setupCost = SolveSetup::cost(scene, options.solver);
  const double setupShare =
    setupCost / (setupCost + chunksCost(scene, lights, options.solver, framesPerChunk));
  std::optional<SolveSetup> setup;
  agreeAcrossRanks(options.solver,
    [&]
    {
      setup.emplace(scene, lights, options.solver,
        [&](double f)
        { return !progress || progress(RemeshingShare + solveShare * setupShare * f); });
      if (options.solver.framesPerChunk == 0)
      {
        checkChunkedMemory(
          scene.patchCount(), scene.elementCount(), scene.points().size(), false, &*setup);
      }
    });
  agreeOnChunks(options.solver, framesPerChunk);
  // The last fraction reported, which the sensors' reads of a batch repeat to ask whether to
  // go on.
  double lastFraction = RemeshingShare + solveShare * setupShare;
  ProgressCallback solveProgress;
  if (progress)
  {
    solveProgress = [&](double f)
    {
      lastFraction = RemeshingShare + solveShare * (setupShare + (1 - setupShare) * f);
      return progress(lastFraction);
    };
  }
  ChunkFramesCallback onFrames;
  if (streamed)
  {
    onFrames = [&](std::size_t first, Solution& frames)
    {
      frames.statistics.patchEdgeLength = animation.remeshing.targetEdgeLength;
      options.chunkFrames(animation, first, frames);
    };
  }
  // With batches, the sensors read every batch through their hemisphere rays: the spread of
  // those reads is the solution's part of their standard error.
  SolverOptions solverOptions = options.solver;
  std::optional<SensorBatchSpread> sensorSpread;
  if (!options.sensors.empty() && estimatesError(options.solver))
  {
    sensorSpread.emplace(scene, options.sensors, options.solver, options.sensorOptions,
      frameCount(lights, scene.hasEmission()), framesPerChunk);
    solverOptions.batchSolved =
      [&](std::uint64_t batch, std::size_t firstFrame, const Solution& solution)
    {
      if (options.solver.batchSolved)
      {
        options.solver.batchSolved(batch, firstFrame, solution);
      }
      sensorSpread->add(
        batch, firstFrame, solution, [&] { return !progress || progress(lastFraction); });
    };
  }
  animation.solution = solveInChunks(scene, lights, solverOptions, framesPerChunk, solveProgress,
    onFrames, streamed ? options.firstChunkFigure : FirstChunkFigure(), &*setup);
  if (sensorSpread)
  {
    sensorSpread->finish();
  }
  animation.solution.statistics.secondsRemeshing = animation.remeshing.seconds;
  animation.solution.statistics.memoryCheckedBytes = checkedBytes;
  animation.solution.statistics.patchEdgeLength = animation.remeshing.targetEdgeLength;
  animation.warnings.insert(animation.warnings.end(), animation.solution.warnings.begin(),
    animation.solution.warnings.end());
  if (!options.sensors.empty())
  {
    ProgressCallback sensorProgress;
    if (progress)
    {
      sensorProgress = [&](double f) { return progress(1 - sensorShare + sensorShare * f); };
    }
    if (options.solver.log)
    {
      // The last stage of the progress, which may take seconds of its own: named.
      options.solver.log("sensors: " + std::to_string(options.sensors.size()) + " x " +
        std::to_string(options.sensorOptions.hemisphereRays) + " hemisphere rays over " +
        std::to_string(animation.solution.frameCount()) + " frames");
    }
    animation.sensors =
      solveSensors(scene, lights, animation.solution, options.sensors, options.solver,
        options.sensorOptions, sensorProgress, sensorSpread ? &*sensorSpread : nullptr);
  }
  return animation;
}

} // namespace mlr
