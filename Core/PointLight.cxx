#include "PointLight.h"

#include <cmath>

namespace mlr
{

PointLight::PointLight(const Rgb& power, const std::vector<LightPose>& poses,
  const IntensityDistribution& distribution, const Vec3& up)
  : Power(power)
  , Distribution(distribution)
  , Poses(poses)
{
  checkLightPower(power);
  checkPoses(poses, power);
  const Vec3 nadir = -up;
  const bool alongX = std::abs(nadir.x) > 0 && nadir.y == 0 && nadir.z == 0;
  this->OwnFrame = PhotometricFrame::fromNadir(nadir, alongX ? Vec3(0, 1, 0) : Vec3(1, 0, 0));
}

} // namespace mlr
