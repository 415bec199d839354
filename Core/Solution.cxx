#include "Solution.h"

#include "Parallel.h"

#include <algorithm>
#include <cmath>

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

void Solution::chooseLitSides(int workers)
{
  // Every element and patch decides alone, over all its frames: blocks of them run on every
  // worker (the choice does not depend on which).
  constexpr std::size_t PerTask = 2048;
  parallelFor((this->Elements + PerTask - 1) / PerTask, workers,
    [&](std::size_t task, int)
    {
      for (std::size_t e = task * PerTask; e < std::min(this->Elements, (task + 1) * PerTask); ++e)
      {
        double front = 0, back = 0, irradianceFront = 0, irradianceBack = 0;
        for (std::size_t f = 0; f < this->Frames; ++f)
        {
          front += this->total(f, e, Side::Front).sum();
          back += this->total(f, e, Side::Back).sum();
        }
        if (front == 0 && back == 0)
        {
          // A black element: the side light arrives on is the one its irradiance is shown for.
          for (std::size_t f = 0; f < this->Frames; ++f)
          {
            irradianceFront += this->irradiance(f, e, Side::Front).sum();
            irradianceBack += this->irradiance(f, e, Side::Back).sum();
          }
        }
        this->LitSide[e] = litSideOf(front, back, irradianceFront, irradianceBack);
      }
    },
    [](std::size_t) { return true; });
  parallelFor((this->Patches + PerTask - 1) / PerTask, workers,
    [&](std::size_t task, int)
    {
      for (std::size_t p = task * PerTask; p < std::min(this->Patches, (task + 1) * PerTask); ++p)
      {
        double front = 0, back = 0;
        for (std::size_t f = 0; f < this->Frames; ++f)
        {
          front += this->patchRadiosity(f, p, Side::Front).sum();
          back += this->patchRadiosity(f, p, Side::Back).sum();
        }
        this->PatchLitSide[p] = back > front ? Side::Back : Side::Front;
      }
    },
    [](std::size_t) { return true; });
}

} // namespace mlr
