#include "RayTracer.h"

#include "Error.h"

#include <embree3/rtcore.h>

#include <cmath>
#include <limits>
#include <mutex>
#include <string>

namespace mlr
{

namespace
{
// Embree reports errors through a callback on the calling thread; we keep the last one
// so that the boundary functions below can raise it as an mlr::Error.
thread_local std::string lastEmbreeError;

void onEmbreeError(void*, RTCError code, const char* message)
{
  lastEmbreeError = "Embree error " + std::to_string(static_cast<int>(code)) + ": " +
    (message ? message : "(no message)");
}

RTCDevice sharedDevice()
{
  static std::once_flag once;
  static RTCDevice device = nullptr;
  std::call_once(once, [] {
    device = rtcNewDevice("verbose=0");
    if (device)
    {
      rtcSetDeviceErrorFunction(device, onEmbreeError, nullptr);
    }
  });
  if (!device)
  {
    throw Error("Embree could not create a device (does this CPU support SSE2?)");
  }
  return device;
}

void raiseIfEmbreeFailed(const char* what)
{
  if (!lastEmbreeError.empty())
  {
    std::string message = std::string(what) + ": " + lastEmbreeError;
    lastEmbreeError.clear();
    throw Error(message);
  }
}
}

struct RayTracer::Embree
{
  RTCScene Scene = nullptr;
  ~Embree()
  {
    if (this->Scene)
    {
      rtcReleaseScene(this->Scene);
    }
  }
};

RayTracer::RayTracer(const Scene& scene)
  : SceneRef(scene)
  , Impl(std::make_unique<Embree>())
{
  RTCDevice device = sharedDevice();
  lastEmbreeError.clear();
  // Offsets must exceed float rounding at the scene's coordinates, and stay far below
  // any feature size.
  const Vec3 lo = scene.boundsMin(), hi = scene.boundsMax();
  const double magnitude = std::max({ std::abs(lo.x), std::abs(lo.y), std::abs(lo.z),
    std::abs(hi.x), std::abs(hi.y), std::abs(hi.z) });
  this->Offset = std::max(1e-5 * scene.diagonal(), 64 * 6e-8 * magnitude);

  this->Impl->Scene = rtcNewScene(device);
  rtcSetSceneFlags(this->Impl->Scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(this->Impl->Scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const auto& points = scene.points();
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX,
    0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), points.size()));
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(geometry,
    RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t),
    scene.elementCount()));
  raiseIfEmbreeFailed("building the ray-tracing scene");
  if (!vertices || !indices)
  {
    rtcReleaseGeometry(geometry);
    throw Error("Embree could not allocate the scene's buffers (out of memory?)");
  }
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    vertices[3 * i + 0] = static_cast<float>(points[i].x);
    vertices[3 * i + 1] = static_cast<float>(points[i].y);
    vertices[3 * i + 2] = static_cast<float>(points[i].z);
  }
  const auto& triangles = scene.elementTriangles();
  for (std::size_t e = 0; e < triangles.size(); ++e)
  {
    for (int k = 0; k < 3; ++k)
    {
      indices[3 * e + k] = triangles[e][k];
    }
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(this->Impl->Scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(this->Impl->Scene);
  raiseIfEmbreeFailed("building the ray-tracing scene");
}

RayTracer::~RayTracer() = default;

bool RayTracer::intersect(const Vec3& origin, const Vec3& direction, RayHit& hit) const
{
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit query;
  query.ray.org_x = static_cast<float>(origin.x);
  query.ray.org_y = static_cast<float>(origin.y);
  query.ray.org_z = static_cast<float>(origin.z);
  query.ray.dir_x = static_cast<float>(direction.x);
  query.ray.dir_y = static_cast<float>(direction.y);
  query.ray.dir_z = static_cast<float>(direction.z);
  query.ray.tnear = 0.0f;
  query.ray.tfar = std::numeric_limits<float>::infinity();
  query.ray.time = 0.0f;
  query.ray.mask = 0xFFFFFFFFu;
  query.ray.id = 0;
  query.ray.flags = 0;
  query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  query.hit.primID = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(this->Impl->Scene, &context, &query);
  if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID)
  {
    return false;
  }
  const std::uint32_t element = query.hit.primID;
  const Triangle& t = this->SceneRef.elementTriangles()[element];
  const auto& p = this->SceneRef.points();
  const double u = query.hit.u, v = query.hit.v;
  hit.element = element;
  hit.point = p[t[0]] * (1.0 - u - v) + p[t[1]] * u + p[t[2]] * v;
  hit.side = dot(direction, this->SceneRef.elementNormal(element)) < 0 ? Side::Front : Side::Back;
  hit.distance = static_cast<double>(query.ray.tfar) * length(direction);
  return true;
}

void RayTracer::visibleFrom(
  const Vec3& origin, const Vec3* targets, std::size_t count, std::uint8_t* visible) const
{
  constexpr std::size_t width = 16;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRay16 packet;
  alignas(64) int valid[width];
  // Stop a fixed fraction short of the target, because the light may sit just in front of a
  // surface. 2^-16 of a segment is at most the surface offset (segments are shorter than the
  // scene's diagonal, the offset is 1e-5 of it) and far above float rounding at t = 1; it
  // spares every lane a square root and a division.
  constexpr float shortOfTarget = 1.0f - 0x1.0p-16f;
  const float minimumSquared = static_cast<float>(this->Offset * this->Offset);
  for (std::size_t first = 0; first < count; first += width)
  {
    const std::size_t lanes = std::min(width, count - first);
    // Branch-free lane set-up: idle lanes repeat the last target and are switched off in
    // `valid`.
    for (std::size_t i = 0; i < width; ++i)
    {
      const Vec3& target = targets[first + std::min(i, lanes - 1)];
      const float dx = static_cast<float>(target.x - origin.x);
      const float dy = static_cast<float>(target.y - origin.y);
      const float dz = static_cast<float>(target.z - origin.z);
      valid[i] = i < lanes && dx * dx + dy * dy + dz * dz > minimumSquared ? -1 : 0;
      packet.org_x[i] = static_cast<float>(origin.x);
      packet.org_y[i] = static_cast<float>(origin.y);
      packet.org_z[i] = static_cast<float>(origin.z);
      packet.dir_x[i] = dx;
      packet.dir_y[i] = dy;
      packet.dir_z[i] = dz;
      packet.tnear[i] = 0.0f;
      packet.tfar[i] = shortOfTarget;
      packet.time[i] = 0.0f;
      packet.mask[i] = 0xFFFFFFFFu;
      packet.id[i] = static_cast<unsigned>(i);
      packet.flags[i] = 0;
    }
    rtcOccluded16(valid, this->Impl->Scene, &context, &packet);
    for (std::size_t i = 0; i < lanes; ++i)
    {
      // Embree sets tfar to -inf for an occluded ray; a target closer than the offset
      // has nothing in between.
      visible[first + i] = !valid[i] || packet.tfar[i] >= 0.0f ? 1 : 0;
    }
  }
}

} // namespace mlr
