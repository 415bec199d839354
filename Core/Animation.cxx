#include "Animation.h"

#include "MemoryBudget.h"

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
  const std::size_t lightCount = lights.areaLights.size() + lights.pointLights.size() +
    lights.directionalLights.size() + lights.skies.size();

  RemeshOptions remeshing = options.remeshing;
  remeshing.memoryLimitBytes = options.solver.memoryLimitBytes;
  // A solve that cannot fit is refused before remeshing does the work (CGAL may take a
  // while), with the patch count remeshing expects once the polygons are triangulated,
  // halved so that an estimate on the high side never refuses a solve that fits (the exact
  // check follows remeshing).
  remeshing.checkExpectedPatches = [&](std::size_t expected)
  {
    const std::size_t patches = expected / 2;
    checkSolveMemory(saturatingSum(estimateSolveMemory(patches, 4 * patches, 2 * patches, frames,
                                     options.solver, lightCount),
                       outputBytes(options, lights, soupEmits, 4 * patches, 2 * patches, frames)),
      frames, patches, 4 * patches, options.solver, true);
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

      animation.warnings = std::move(remeshed.warnings);
      animation.remeshing = remeshed.statistics;
      animation.scene = Scene::fromPatchMesh(remeshed.mesh);
      animation.patches = std::move(remeshed.mesh);
      const Scene& scene = animation.scene;
      checkSolveMemory(saturatingSum(estimateSolveMemory(scene, frames, options.solver, lightCount),
                         outputBytes(options, lights, soupEmits, scene.elementCount(),
                           scene.points().size(), frames)),
        frames, scene.patchCount(), scene.elementCount(), options.solver);
    });
  const Scene& scene = animation.scene;

  const double sensorShare = options.sensors.empty() ? 0.0 : SensorShare;
  const double solveShare = 1 - RemeshingShare - sensorShare;
  ProgressCallback solveProgress;
  if (progress)
  {
    solveProgress = [&](double f) { return progress(RemeshingShare + solveShare * f); };
  }
  animation.solution = solve(scene, lights, options.solver, solveProgress);
  animation.solution.statistics.secondsRemeshing = animation.remeshing.seconds;
  animation.warnings.insert(animation.warnings.end(), animation.solution.warnings.begin(),
    animation.solution.warnings.end());
  if (!options.sensors.empty())
  {
    ProgressCallback sensorProgress;
    if (progress)
    {
      sensorProgress = [&](double f) { return progress(1 - sensorShare + sensorShare * f); };
    }
    animation.sensors = solveSensors(scene, lights, animation.solution, options.sensors,
      options.solver, options.sensorOptions, sensorProgress);
  }
  return animation;
}

} // namespace mlr
