#include "Solution.h"

#include "Error.h"
#include "Parallel.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace mlr
{

Solution::Solution(std::size_t frames, std::size_t elements, std::size_t patches)
  : Frames(frames)
  , Elements(elements)
  , Patches(patches)
  , Direct(frames * elements * 2)
  , Patch(frames * patches * 2)
  , Reflectance(elements, Rgb(1))
  , LitSide(elements, Side::Front)
  , PatchLitSide(patches, Side::Front)
{
}

double Solution::storageScaleFor(double totalArea, double power)
{
  if (!(totalArea > 0) || !std::isfinite(totalArea))
  {
    return 1;
  }
  const double watts = power > 0 && std::isfinite(power) ? power : 1.0;
  return std::ldexp(1.0, static_cast<int>(std::lround(std::log2(watts) - std::log2(totalArea))));
}

void Solution::clearRadiosity()
{
  // Fresh arrays rather than zeros written: untouched, they take no memory until shot.
  this->Direct = StoredArray(this->Direct.size());
  this->Patch = StoredArray(this->Patch.size());
  StoredArray().swap(this->Indirect);
}

Solution::SideTotals Solution::elementTotals(std::size_t element) const
{
  SideTotals t;
  for (std::size_t f = 0; f < this->Frames; ++f)
  {
    t.front += this->total(f, element, Side::Front).sum();
    t.back += this->total(f, element, Side::Back).sum();
  }
  // The irradiance decides only for a surface black on both sides, whose every element is:
  // the others skip reading it again.
  if (t.front == 0 && t.back == 0)
  {
    for (std::size_t f = 0; f < this->Frames; ++f)
    {
      t.irradianceFront += this->irradiance(f, element, Side::Front).sum();
      t.irradianceBack += this->irradiance(f, element, Side::Back).sum();
    }
  }
  return t;
}

namespace
{
std::vector<Solution::SideTotals> surfaceTotalsOf(const Scene& scene, std::size_t patches,
  const std::function<Solution::SideTotals(std::size_t element)>& totals, int workers)
{
  // One element's estimate is noisy: where its two sides' totals are comparable, choosing
  // per element would follow the noise, speckle the surface and keep the elements whose
  // shown side came out high (a biased mean). A surface's pooled sums hardly move with any
  // one element. Each patch's sum is added in element order on one worker, and the
  // surfaces' sums in patch order on this thread: the same bits for any worker count.
  std::vector<Solution::SideTotals> patchTotals(patches);
  constexpr std::size_t PerTask = 2048;
  parallelFor((patches + PerTask - 1) / PerTask, workers,
    [&](std::size_t task, int)
    {
      for (std::size_t p = task * PerTask; p < std::min(patches, (task + 1) * PerTask); ++p)
      {
        Solution::SideTotals sum;
        for (std::size_t e = p * Scene::ElementsPerPatch; e < (p + 1) * Scene::ElementsPerPatch;
             ++e)
        {
          const Solution::SideTotals t = totals(e);
          const double area = scene.elementArea(e);
          sum +=
            { area * t.front, area * t.back, area * t.irradianceFront, area * t.irradianceBack };
        }
        patchTotals[p] = sum;
      }
    },
    [](std::size_t) { return true; });
  std::vector<Solution::SideTotals> surfaces(scene.regionCount());
  for (std::size_t p = 0; p < patches; ++p)
  {
    surfaces[scene.patchRegion(p)] += patchTotals[p];
  }
  return surfaces;
}
}

void Solution::chooseLitSides(const Scene& scene, int workers)
{
  this->chooseLitSides(
    scene, [this](std::size_t e) { return this->elementTotals(e); }, workers);
}

void Solution::chooseLitSides(
  const Scene& scene, const std::function<SideTotals(std::size_t element)>& totals, int workers)
{
  if (scene.elementCount() != this->Elements || scene.patchCount() != this->Patches)
  {
    throw Error("internal error: lit sides chosen for a scene of " +
      std::to_string(scene.patchCount()) + " patches and a solution of " +
      std::to_string(this->Patches));
  }
  const std::vector<SideTotals> surfaces = surfaceTotalsOf(scene, this->Patches, totals, workers);
  for (std::size_t p = 0; p < this->Patches; ++p)
  {
    const SideTotals& sum = surfaces[scene.patchRegion(p)];
    const Side side = litSideOf(sum.front, sum.back, sum.irradianceFront, sum.irradianceBack);
    this->PatchLitSide[p] = side;
    std::fill_n(this->LitSide.begin() + static_cast<std::ptrdiff_t>(p * Scene::ElementsPerPatch),
      Scene::ElementsPerPatch, side);
  }
}

std::vector<Solution::SideTotals> Solution::surfaceTotals(const Scene& scene, int workers) const
{
  return surfaceTotalsOf(
    scene, this->Patches, [this](std::size_t e) { return this->elementTotals(e); }, workers);
}

} // namespace mlr
