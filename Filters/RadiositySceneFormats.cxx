#include "RadiositySceneFormats.h"

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

} // namespace mlr::scenefile
