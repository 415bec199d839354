// Ray queries against the scene's elements, cast by Embree.
#pragma once

#include "Scene.h"
#include "Vec3.h"

#include <cstddef>
#include <cstdint>
#include <memory>

namespace mlr
{

/// The nearest surface point a ray reaches.
struct RayHit
{
  std::uint32_t element = 0;
  Side side = Side::Front; ///< the side facing the incoming ray
  Vec3 point;              ///< on the element's plane (from barycentrics, not origin + t dir)
  double distance = 0;
};

/**
 * Nearest-hit and visibility queries over a Scene's elements.
 *
 * Wraps one robust Embree scene (RTC_SCENE_FLAG_ROBUST) built on the process-wide Embree
 * device, whose error callback is registered once. Queries are thread-safe. Rays can slip
 * between two elements in rare cases (Embree's robust mode narrows this, it does not
 * close it): intersect() then reports a miss, and callers treat it as power leaving the
 * scene. The Scene must outlive the tracer.
 */
class RayTracer
{
public:
  explicit RayTracer(const Scene& scene);
  /// Bytes a tracer of `elements` triangles on `points` points holds at its build's peak,
  /// generously: Embree's BVH and buffers measure about 80 bytes per element once built
  /// and 140 during the build (Testing/Core/TestSolveMemory.cxx).
  static std::uint64_t estimateMemory(std::size_t elements, std::size_t points);
  ~RayTracer();
  RayTracer(const RayTracer&) = delete;
  RayTracer& operator=(const RayTracer&) = delete;

  /// Nearest hit of origin + t * direction for t > 0 (direction need not be unit).
  bool intersect(const Vec3& origin, const Vec3& direction, RayHit& hit) const;

  /// The element and side intersect() would report, without the hit point and distance:
  /// final gathering and the reachability probes need no more, and the point costs three
  /// scattered reads per ray.
  bool nearestSide(
    const Vec3& origin, const Vec3& direction, std::uint32_t& element, Side& side) const;

  /**
   * Visibility of the segments from `origin` to origin + (dx[i], dy[i], dz[i]) (endpoints
   * excluded), for `count` segments, written to visible[i]. The offsets come as a structure
   * of float arrays, the layout of Embree's 16-wide packets: coherent segments from one
   * origin are traced a packet at a time. Callers give ends lifted off their surfaces
   * (liftOff), the points rays start from, so that a segment is blocked exactly when a ray
   * between its ends would be. A segment shorter than the lift is visible.
   */
  void visibleFrom(const Vec3& origin, const float* dx, const float* dy, const float* dz,
    std::size_t count, std::uint8_t* visible) const;

  /// Visibility to infinity from `origin` along each of `count` directions, as visibleFrom.
  void visibleAlong(const Vec3& origin, const float* dx, const float* dy, const float* dz,
    std::size_t count, std::uint8_t* visible) const;

  /// The distance rays leaving a surface start above it, so that they do not hit it again:
  /// 1e-5 of the scene's diagonal, whatever the scene's distance from the origin (rays are
  /// traced in coordinates relative to the scene's centre).
  double surfaceOffset() const { return this->Offset; }

  /// The point `offset` above p on the side whose normal is n.
  Vec3 liftOff(const Vec3& p, const Vec3& n) const { return p + n * this->Offset; }

private:
  struct Embree;
  const Scene& SceneRef;
  std::unique_ptr<Embree> Impl;
  double Offset = 0;
  /// Embree holds single-precision coordinates relative to this point, the scene's centre:
  /// a room 10 km from the origin traces as accurately as one at the origin.
  Vec3 Centre;
};

} // namespace mlr
