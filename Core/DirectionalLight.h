// A distant light (the sun): parallel rays from a direction that changes every frame.
#pragma once

#include "Rgb.h"
#include "Vec3.h"

#include <cstddef>
#include <vector>

namespace mlr
{

/**
 * A light at infinity. In frame k it shines from the unit direction s_k (pointing towards the
 * light) with irradiance s_k-scaled E (RGB, W/m^2 on a surface facing it). Paths of frame k
 * start uniformly on a disc perpendicular to s_k that covers the scene's bounding sphere
 * (Documentation/Method.md, section 9). A light with one direction lights every frame alike.
 * The constructor throws mlr::Error naming what is wrong.
 */
class DirectionalLight
{
public:
  /// `towardsLight` need not be unit; `powerFactors` is empty (1 in every frame) or one
  /// factor per direction (0: the light is off in that frame, e.g. at night).
  DirectionalLight(const std::vector<Vec3>& towardsLight, const Rgb& irradiance,
    const std::vector<Rgb>& powerFactors = {});

  std::size_t frameCount() const { return this->Directions.size(); }
  /// The unit direction towards the light in frame `frame`.
  const Vec3& direction(std::size_t frame) const { return this->Directions[frame]; }
  const Rgb& irradiance() const { return this->Irradiance; }
  const Rgb& powerFactor(std::size_t frame) const { return this->PowerFactors[frame]; }

private:
  std::vector<Vec3> Directions;
  Rgb Irradiance;
  std::vector<Rgb> PowerFactors;
};

} // namespace mlr
