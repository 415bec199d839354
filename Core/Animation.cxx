#include "Animation.h"

#include "MemoryBudget.h"

namespace mlr
{

namespace
{
/// Share of the progress given to remeshing; the solve takes the rest.
constexpr double RemeshingShare = 0.05;

std::uint64_t outputBytes(const AnimationOptions& options, std::size_t elements, std::size_t points)
{
  return saturatingSum(saturatingProduct(options.outputBytesPerElement, elements),
    saturatingProduct(options.outputBytesPerPoint, points));
}
}

Animation solveAnimation(const PolygonSoup& soup, const LightRig& lights,
  const AnimationOptions& options, const ProgressCallback& progress)
{
  validateOptions(options.solver);
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
                       outputBytes(options, 4 * patches, 2 * patches)),
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
                         outputBytes(options, scene.elementCount(), scene.points().size())),
        frames, scene.patchCount(), scene.elementCount(), options.solver);
    });
  const Scene& scene = animation.scene;

  ProgressCallback solveProgress;
  if (progress)
  {
    solveProgress = [&](double f) { return progress(RemeshingShare + (1 - RemeshingShare) * f); };
  }
  animation.solution = solve(scene, lights, options.solver, solveProgress);
  animation.solution.statistics.secondsRemeshing = animation.remeshing.seconds;
  animation.warnings.insert(animation.warnings.end(), animation.solution.warnings.begin(),
    animation.solution.warnings.end());
  return animation;
}

} // namespace mlr
