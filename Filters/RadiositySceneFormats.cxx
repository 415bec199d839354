#include "RadiositySceneFormats.h"

#include "SceneText.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mlr::scenefile
{

std::array<double, 3> checkedReflectance(
  std::array<double, 3> rgb, const std::string& what, const Warn& warn)
{
  bool clamped = false;
  for (double& value : rgb)
  {
    if (!std::isfinite(value) || value < 0)
    {
      std::ostringstream s;
      s << what << " has the reflectance (" << rgb[0] << ", " << rgb[1] << ", " << rgb[2]
        << "): each component must be a number from 0 to 1";
      throw FileError(s.str());
    }
    if (value > MaxReflectance)
    {
      clamped = true;
    }
  }
  if (clamped)
  {
    std::ostringstream s;
    s << what << " has the reflectance (" << rgb[0] << ", " << rgb[1] << ", " << rgb[2]
      << "): components above " << MaxReflectance << " are clamped to " << MaxReflectance
      << " (a surface reflecting all the light it receives has no finite radiosity)";
    warn(s.str());
    for (double& value : rgb)
    {
      value = std::min(value, MaxReflectance);
    }
  }
  return rgb;
}

void checkOutputSize(const std::string& path, const std::string& format, std::uint64_t points,
  std::uint64_t triangles, const MemoryBudget& budget, bool fromFileSize)
{
  // A point is three doubles; a triangle three ids, an offset, a material id, a reflectance
  // and an emission (doubles), with a margin for the cell array's growth.
  constexpr std::uint64_t BytesPerPoint = 24, BytesPerTriangle = 112;
  const std::uint64_t bytes = saturatingSum(
    saturatingProduct(points, BytesPerPoint), saturatingProduct(triangles, BytesPerTriangle));
  if (!budget.fits(bytes))
  {
    throw FileError(budget.overLimitMessage(bytes, "the " + format + " file " + named(path),
      (fromFileSize ? "up to " : "") + std::to_string(points) + " points and " +
        (fromFileSize ? "up to " : "") + std::to_string(triangles) + " triangles" +
        (fromFileSize ? " (bounds from the file's size)" : ""),
      "simplify the model, or raise the memory limit (the reader's MemoryLimit, the command "
      "line's --memory-limit)"));
  }
}

} // namespace mlr::scenefile
