// The lights a solve shoots from, behind one interface: area lights (moving or static
// lamps, and the scene's own emissive surfaces), point lights and directional lights (the
// sun). A light
// kind is one class here, with its path sampling and its reuse kernel; LightSource is the
// one place that dispatches on the kind.
#pragma once

#include "DirectionalLight.h"
#include "MovingLight.h"
#include "PointLight.h"
#include "Random.h"
#include "Rgb.h"
#include "Scene.h"
#include "Sky.h"
#include "Vec3.h"

#include <cstddef>
#include <cstdint>
#include <variant>
#include <vector>

namespace mlr
{

class RayTracer;

/**
 * Everything that emits in an animation besides the scene's own emissive surfaces (which
 * Scene::patchEmission gives). Lights with one pose or direction are static: solved once and
 * added to every frame. All moving lights must have the same number of poses: the frames.
 * Transport is linear, so every light is shot on its own and the results add up; gathering
 * then runs once on the sum.
 */
struct LightRig
{
  std::vector<MovingLight> areaLights;
  std::vector<PointLight> pointLights;
  std::vector<DirectionalLight> directionalLights;
  std::vector<Sky> skies;
  /// The frame of the whole animation that this rig's first pose is (sliceRig sets it): the
  /// random streams of a moving light's positions are keyed by their frame in the animation,
  /// so that a chunk solving a slice casts the same paths from a position as every other
  /// chunk that solves it.
  std::size_t firstFrame = 0;
};

/// The number of frames of a rig: the pose count of its moving lights, or 1 when nothing
/// moves. Throws mlr::Error when moving lights disagree or nothing can emit.
std::size_t frameCount(const LightRig& rig, bool sceneEmits);

/// A path's start: the point (lifted off the light) and direction, and the point and normal
/// in the light's own frame, which the reuse kernel of the other positions needs.
struct EmittedPath
{
  Vec3 start, direction;
  Vec3 ownPoint, ownNormal;
};

/// Per worker: the reuse kernel of one hit for every position, and the shadow rays that
/// decide the visibility of the positions still unknown.
struct KernelScratch
{
  std::vector<double> kernel;
  /// Float offsets (or directions) in the layout of Embree's packets.
  std::vector<float> dx, dy, dz;
  std::vector<std::uint32_t> targetFrames;
  std::vector<std::uint8_t> visible;

  void resize(std::size_t positions);
};

/// A disc perpendicular to `normal` (pointing towards the light) of `radius` about `centre`.
struct BoundingDisc
{
  Vec3 centre, normal;
  double radius = 0;
};

/**
 * An area light: a MovingLight, posed in each position, emitting from a uniform point with
 * its intensity distribution f_j posed in position j. G_j(y) = f_j(d / |d|) (-n_y.d) / |d|^3
 * with d = y - x_j; for the Lambertian distribution that is (n_j.d)(-n_y.d) / |d|^4, the pi
 * of f cancelling in the reuse weights.
 */
class AreaSource
{
public:
  explicit AreaSource(const MovingLight& light);

  std::size_t positions() const { return this->Light->frameCount(); }
  /// Phi: the power a whole path set carries.
  const Rgb& power() const { return this->Light->power(); }
  const Rgb& factor(std::size_t position) const { return this->Light->pose(position).power; }
  void emit(std::size_t position, RandomStream& random, double offset, EmittedPath& path) const;
  std::size_t kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny, std::size_t origin,
    const double* on, const RayTracer& tracer, KernelScratch& scratch) const;

private:
  const MovingLight* Light;
  /// The poses as a structure of arrays, for the vectorised kernel: x_j = R_j x + o_j and
  /// n_j = R_j n (rows of R_j in 0..8, o_j in 9..11).
  std::vector<std::vector<double>> Pose;
  /// The photometric frame of every position, for the distributions other than Lambertian.
  std::vector<PhotometricFrame> Frames;
};

/**
 * A point light at x_j in position j, emitting with its distribution f_j posed there.
 * G_j(y) = f_j(d / |d|) (-n_y.d) / |d|^3 with d = y - x_j: the first-hit density per unit
 * area of y (a solid angle d omega subtends the area r^2 d omega / cos theta_y).
 */
class PointSource
{
public:
  explicit PointSource(const PointLight& light);

  std::size_t positions() const { return this->Light->frameCount(); }
  const Rgb& power() const { return this->Light->power(); }
  const Rgb& factor(std::size_t position) const { return this->Light->pose(position).power; }
  void emit(std::size_t position, RandomStream& random, double offset, EmittedPath& path) const;
  std::size_t kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny, std::size_t origin,
    const double* on, const RayTracer& tracer, KernelScratch& scratch) const;

private:
  const PointLight* Light;
  std::vector<PhotometricFrame> Frames;
};

/**
 * A directional light: in position j parallel rays from s_j start uniformly on a disc that
 * covers the scene's bounding sphere, pushed out of it towards the light.
 * G_j(y) = max(0, n_y.s_j), with visibility towards s_j to infinity.
 */
class DirectionalSource
{
public:
  /// `centre` and `radius`: the scene's bounding sphere.
  DirectionalSource(const DirectionalLight& light, const Vec3& centre, double radius);

  std::size_t positions() const { return this->Light->frameCount(); }
  /// E times the disc's area.
  const Rgb& power() const { return this->Power; }
  const Rgb& factor(std::size_t position) const { return this->Light->powerFactor(position); }
  /// The disc paths of `position` start from, before the lift off the sphere (`offset`).
  BoundingDisc boundingDisc(std::size_t position, double offset = 0) const;
  void emit(std::size_t position, RandomStream& random, double offset, EmittedPath& path) const;
  std::size_t kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny, std::size_t origin,
    const double* on, const RayTracer& tracer, KernelScratch& scratch) const;

private:
  const DirectionalLight* Light;
  Vec3 Centre;
  double Radius = 0;
  Rgb Power;
  /// s_j as a structure of arrays.
  std::vector<std::vector<double>> Pose;
};

/**
 * A sky: in position j the radiance L_j(w) from the directions w above the horizon. Paths
 * start uniformly on a disc perpendicular to w that covers the scene's bounding sphere, with
 * w drawn from p_j = L_j / Lambda_j (Lambda_j: L_j over the solid angle). The disc depends
 * on w only, so a path is the same ray in every frame: G_j(y) = p_j(w), and a reused path
 * needs no shadow ray (Documentation/Method.md, "The sky").
 */
class SkySource
{
public:
  /// `centre` and `radius`: the scene's bounding sphere.
  SkySource(const Sky& sky, const Vec3& centre, double radius);

  std::size_t positions() const { return this->SkyRef->positions(); }
  /// pi r^2 times the largest Lambda_j.
  const Rgb& power() const { return this->Power; }
  const Rgb& factor(std::size_t position) const { return this->Factors[position]; }
  void emit(std::size_t position, RandomStream& random, double offset, EmittedPath& path) const;
  std::size_t kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny, std::size_t origin,
    const double* on, const RayTracer& tracer, KernelScratch& scratch) const;

private:
  const Sky* SkyRef;
  Vec3 Centre;
  double Radius = 0;
  Rgb Power;
  std::vector<Rgb> Factors;
};

/**
 * One light the solver shoots from. It has positions() poses; one pose is a static light,
 * added to every frame. The light it views must outlive it.
 */
class LightSource
{
public:
  using Kind = std::variant<AreaSource, PointSource, DirectionalSource, SkySource>;

  /// `stream` keys this source's random streams apart from the other sources' (0 for the
  /// first): lights of one rig are independent estimates, not the same numbers replayed.
  /// `firstFrame`: the animation's frame of position 0 (LightRig::firstFrame; 0 for a static
  /// light, which every frame shares).
  LightSource(Kind kind, std::uint64_t stream, std::size_t firstFrame = 0);

  std::size_t positions() const { return this->Positions; }
  bool isStatic() const { return this->Positions == 1; }
  /// The power a whole path set carries before weights: Phi for an area or point light, E
  /// times the disc's area for a directional one.
  const Rgb& power() const { return this->Power; }
  /// Per position, a factor on the power (0: that position is off and casts no path).
  const Rgb& factor(std::size_t position) const { return this->Factors[position]; }
  bool isActive(std::size_t position) const { return this->On[position] > 0; }
  /// The positions that emit, in order.
  const std::vector<std::size_t>& activePositions() const { return this->Active; }
  std::uint64_t stream() const { return this->Stream; }
  /// The key of the paths cast from `position` (the b of their RandomStream): the source's
  /// stream and the position's frame in the whole animation, so that path i of a frame is the
  /// same path in every chunk, and in a classic solve of that frame.
  std::uint64_t positionStream(std::size_t position) const
  {
    return this->Stream + (this->isStatic() ? 0 : this->FirstFrame) + position + 1;
  }
  const Kind& kind() const { return this->What; }

  /// A path's start at `position`, lifted `offset` off the light.
  void emit(std::size_t position, RandomStream& random, double offset, EmittedPath& path) const;

  /**
   * The reuse kernel of a path emitted as `path` whose first hit is y (normal ny towards the
   * side hit): the unoccluded kernel G_j(y) of every position into scratch.kernel (0 for the
   * positions that are off), and the shadow rays of the positions other than `origin` whose
   * kernel is not zero, traced into scratch.visible for scratch.targetFrames. Returns the
   * number of shadow rays. The loops are branch-free over the positions so that they
   * vectorise.
   */
  std::size_t kernel(const EmittedPath& path, const Vec3& y, const Vec3& ny, std::size_t origin,
    const RayTracer& tracer, KernelScratch& scratch) const;

private:
  Kind What;
  std::size_t Positions = 1;
  Rgb Power;
  std::vector<Rgb> Factors;
  /// 1 for the active positions, 0 for the others, as the kernel's loops read it.
  std::vector<double> On;
  std::vector<std::size_t> Active;
  std::uint64_t Stream = 0;
  std::size_t FirstFrame = 0;
};

/// The scene's emissive patches as static area lights, one per distinct emission (an area
/// light has one colour). They are part of the geometry too, so they occlude.
std::vector<MovingLight> sceneEmitters(const Scene& scene);

/// The sources of a solve: the rig's area lights, then `emitters`, then the rig's point
/// lights, then its directional lights, then its skies, streams numbered in that order.
/// They view the lights given.
std::vector<LightSource> lightSources(
  const Scene& scene, const LightRig& rig, const std::vector<MovingLight>& emitters);

} // namespace mlr
