#include "DirectionalLight.h"

#include "Error.h"

#include <sstream>

namespace mlr
{

DirectionalLight::DirectionalLight(const std::vector<Vec3>& towardsLight, const Rgb& irradiance,
  const std::vector<Rgb>& powerFactors)
  : Irradiance(irradiance)
{
  if (towardsLight.empty())
  {
    throw Error("the directional light has no direction: give one direction towards the light "
                "per frame");
  }
  if (!irradiance.isFinite() || !(irradiance.minComponent() >= 0) ||
    !(irradiance.maxComponent() > 0))
  {
    std::ostringstream s;
    s << "the irradiance (" << irradiance.r << ", " << irradiance.g << ", " << irradiance.b
      << ") W/m^2 must be finite, not negative and above 0 in some channel (1000 is the sun "
         "at noon)";
    throw Error(s.str());
  }
  if (!powerFactors.empty() && powerFactors.size() != towardsLight.size())
  {
    throw Error("the directional light has " + std::to_string(towardsLight.size()) +
      " directions but " + std::to_string(powerFactors.size()) +
      " power factors: give one per direction, or none");
  }
  for (std::size_t k = 0; k < towardsLight.size(); ++k)
  {
    const Vec3& d = towardsLight[k];
    const double norm = length(d);
    if (!isFinite(d) || !(norm > 1e-12) || !std::isfinite(norm))
    {
      std::ostringstream s;
      s << "direction " << k << " towards the light is (" << d.x << ", " << d.y << ", " << d.z
        << "): it must be finite and not zero";
      throw Error(s.str());
    }
    this->Directions.push_back(d / norm);
  }
  this->PowerFactors =
    powerFactors.empty() ? std::vector<Rgb>(towardsLight.size(), Rgb(1)) : powerFactors;
  for (std::size_t k = 0; k < this->PowerFactors.size(); ++k)
  {
    const Rgb& f = this->PowerFactors[k];
    if (!f.isFinite() || f.minComponent() < 0)
    {
      std::ostringstream s;
      s << "the power factor of direction " << k << " is (" << f.r << ", " << f.g << ", " << f.b
        << "): it must be finite and >= 0 (0 turns the light off)";
      throw Error(s.str());
    }
  }
}

} // namespace mlr
