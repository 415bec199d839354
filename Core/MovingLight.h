// The moving light: emitting polygons posed (moved, turned, dimmed) in every frame.
#pragma once

#include "Photometry.h"
#include "Rgb.h"
#include "Rotation.h"
#include "Vec3.h"

#include <array>
#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace mlr
{

/// One triangle of the light, in the light's own frame (before translation).
struct LightTriangle
{
  Vec3 a, b, c;
  Vec3 normal; ///< unit, right-hand rule: the emitting side
  double area = 0;
};

/// Where a light is in one frame: a rigid motion about its area centroid c and a power factor.
struct LightPose
{
  /// The light's area centroid in this frame.
  Vec3 position;
  /// The turn about the centroid, relative to the light as given: x -> R (x - c) + position.
  Rotation rotation;
  /// A factor on the light's power in this frame, per channel; 0 is a light that is off.
  Rgb power{ 1, 1, 1 };
};

/**
 * A planar polygonal light (one or more simple polygons, convex or concave) with total power
 * Phi (RGB, W), posed in every frame: frame k maps a point x of the light as given to
 * R_k (x - c) + p_k and its normal n to R_k n, and emits s_k Phi. Power is spread uniformly
 * over the area (exitance Phi/A_L); every point emits with the light's intensity
 * distribution in its photometric frame, diffusely from the front side of each polygon
 * unless another distribution is set. The light does not occlude. A light with one pose
 * does not move: it lights every frame alike.
 * The constructors throw mlr::Error naming what is wrong.
 */
class MovingLight
{
public:
  MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
    const std::vector<LightPose>& poses);
  /// A light that only translates: frame k moves it by translations[k], at full power.
  MovingLight(const std::vector<std::vector<Vec3>>& polygons, const Rgb& power,
    const std::vector<Vec3>& translations);

  const Rgb& power() const { return this->Power; }
  double area() const { return this->Area; }
  /// Area centroid of the light as given (frame-independent reference point).
  const Vec3& centroid() const { return this->Centroid; }
  const std::vector<LightTriangle>& triangles() const { return this->Triangles; }
  /// The polygons as given (the light's own frame).
  const std::vector<std::vector<Vec3>>& polygons() const { return this->Polygons; }

  std::size_t frameCount() const { return this->Poses.size(); }
  const LightPose& pose(std::size_t frame) const { return this->Poses[frame]; }
  const std::vector<LightPose>& poses() const { return this->Poses; }
  /// Replaces the poses (e.g. with their TILT factors, Core/LuminaireTilt.h). Throws
  /// mlr::Error as the constructor does for bad poses.
  void setPoses(const std::vector<LightPose>& poses);
  /// How far frame `frame` moves the centroid: p_k - c.
  Vec3 translation(std::size_t frame) const { return this->Poses[frame].position - this->Centroid; }
  /// Frame `frame` as a rigid motion x -> R x + t of a point x of the light as given: this
  /// t, p - R c.
  Vec3 rigidTranslation(std::size_t frame) const
  {
    return this->Poses[frame].position - this->Poses[frame].rotation.apply(this->Centroid);
  }
  /// True when some frame turns the light.
  bool rotates() const { return this->Rotates; }

  /// A point of the light as given, placed in frame `frame`.
  Vec3 place(std::size_t frame, const Vec3& x) const
  {
    return this->Poses[frame].rotation.apply(x - this->Centroid) + this->Poses[frame].position;
  }
  /// A direction of the light as given (a normal), turned as in frame `frame`.
  Vec3 turn(std::size_t frame, const Vec3& n) const { return this->Poses[frame].rotation.apply(n); }

  /// A uniformly distributed point on the light (own frame) and the normal there.
  void samplePoint(double u0, double u1, double u2, Vec3& point, Vec3& normal) const;
  /// The same from two numbers, by a map that keeps areas: `u` picks the triangle by area and
  /// what is left of it places the point with `v`, so that equal cells of the unit square are
  /// equal areas of the light and stratified (u, v) are stratified points.
  void samplePoint(double u, double v, Vec3& point, Vec3& normal) const;

  /// How every point of the light spreads its power over directions (Lambertian unless set).
  const IntensityDistribution& distribution() const { return this->Distribution; }
  void setDistribution(const IntensityDistribution& distribution)
  {
    this->Distribution = distribution;
  }
  /// The photometric frame of the light as given: nadir the first polygon's normal, C = 0
  /// along its first edge.
  const PhotometricFrame& ownPhotometricFrame() const { return this->OwnFrame; }
  /// The photometric frame turned as in frame `frame`.
  PhotometricFrame photometricFrame(std::size_t frame) const
  {
    const PhotometricFrame& own = this->OwnFrame;
    return { this->turn(frame, own.x), this->turn(frame, own.y), this->turn(frame, own.z) };
  }

private:
  /// The triangle in which the cumulative area `area` falls (the last one past the end).
  std::size_t triangleAt(double area) const;
  Rgb Power;
  double Area = 0;
  Vec3 Centroid;
  std::vector<LightTriangle> Triangles;
  std::vector<std::vector<Vec3>> Polygons;
  std::vector<double> CumulativeArea;
  std::vector<LightPose> Poses;
  bool Rotates = false;
  IntensityDistribution Distribution = IntensityDistribution::lambertian();
  PhotometricFrame OwnFrame;
};

/// Throws mlr::Error when a light's power is negative or not finite.
void checkLightPower(const Rgb& power);

/// Throws mlr::Error naming the first pose that is not finite, out of the coordinate range,
/// not a rotation, of a negative power factor or of one that takes the light's `power` over
/// MaximumLightPower, or when there is no pose.
void checkPoses(const std::vector<LightPose>& poses, const Rgb& power);

/// What users give for a light in one frame (a Trajectory point and its arrays).
struct PoseInput
{
  Vec3 position; ///< the light's area centroid in this frame
  bool hasNormal = false;
  Vec3 normal; ///< the emission direction in this frame (any length but 0)
  bool hasOrientation = false;
  std::array<double, 4> orientation{ 1, 0, 0, 0 }; ///< quaternion w, x, y, z (any length but 0)
  Rgb power{ 1, 1, 1 };                            ///< factor on the light's power
};

/// The area-weighted mean of the polygons' unit normals, normalised: the direction a light
/// emits in as given, which a frame's Normal turns. Throws when it is zero (a light whose
/// polygons face opposite ways must be posed with Orientation).
Vec3 meanNormal(const std::vector<std::vector<Vec3>>& polygons);

/**
 * Poses from users' per-frame inputs. An orientation (a quaternion, normalised with a
 * warning appended to `warnings` when it is not unit) wins over a normal; a normal turns the
 * light about its centroid by the smallest rotation from meanNormal(polygons) to it.
 * Throws mlr::Error naming the frame for a zero normal or quaternion.
 */
std::vector<LightPose> posesFromInputs(const std::vector<std::vector<Vec3>>& polygons,
  const std::vector<PoseInput>& inputs, std::vector<std::string>& warnings);

/**
 * Aims a light at `target` in every frame: each input's Normal becomes the direction from its
 * position to the target, so that posesFromInputs turns the light about its centroid by the
 * smallest rotation from meanNormal(polygons) to it (a target straight behind the light gets
 * the half turn of Rotation::between). An Orientation still wins. A light at the target has
 * no direction to face it: returns the first frame without an Orientation whose position is
 * there (its Normal is then zero, which posesFromInputs refuses), none when every frame can
 * face it.
 */
std::optional<std::size_t> aimAt(std::vector<PoseInput>& inputs, const Vec3& target);

} // namespace mlr
