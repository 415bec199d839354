// The point light: a luminaire small against its distances, posed (moved, turned, dimmed)
// in every frame.
#pragma once

#include "MovingLight.h"
#include "Photometry.h"
#include "Rgb.h"
#include "Vec3.h"

#include <cstddef>
#include <vector>

namespace mlr
{

/**
 * A point of power Phi (RGB, W) that emits with an intensity distribution in its
 * photometric frame, posed in every frame: frame k puts it at p_k, turns its frame by R_k
 * and emits s_k Phi. Before posing the nadir is minus `up` and C = 0 is +x made orthogonal
 * to it (+y when up is along x). It does not occlude. A light with one pose does not move:
 * it lights every frame alike. The constructor throws mlr::Error naming what is wrong.
 */
class PointLight
{
public:
  PointLight(const Rgb& power, const std::vector<LightPose>& poses,
    const IntensityDistribution& distribution = IntensityDistribution::lambertian(),
    const Vec3& up = Vec3(0, 0, 1));

  const Rgb& power() const { return this->Power; }
  const IntensityDistribution& distribution() const { return this->Distribution; }
  std::size_t frameCount() const { return this->Poses.size(); }
  const LightPose& pose(std::size_t frame) const { return this->Poses[frame]; }
  const std::vector<LightPose>& poses() const { return this->Poses; }
  /// Replaces the poses (e.g. with their TILT factors, Core/LuminaireTilt.h). Throws
  /// mlr::Error for bad poses.
  void setPoses(const std::vector<LightPose>& poses)
  {
    checkPoses(poses, this->Power);
    this->Poses = poses;
  }
  const Vec3& position(std::size_t frame) const { return this->Poses[frame].position; }
  /// The photometric frame before posing.
  const PhotometricFrame& ownPhotometricFrame() const { return this->OwnFrame; }
  /// The photometric frame turned as in frame `frame`.
  PhotometricFrame photometricFrame(std::size_t frame) const
  {
    const Rotation& r = this->Poses[frame].rotation;
    const PhotometricFrame& own = this->OwnFrame;
    return { r.apply(own.x), r.apply(own.y), r.apply(own.z) };
  }

private:
  Rgb Power;
  IntensityDistribution Distribution;
  PhotometricFrame OwnFrame;
  std::vector<LightPose> Poses;
};

} // namespace mlr
