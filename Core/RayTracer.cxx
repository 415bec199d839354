#include "RayTracer.h"

#include "Error.h"
#include "MemoryBudget.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <cstring>
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
  std::call_once(once,
    []
    {
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
  // Offsets must exceed float rounding at the (centred) coordinates, and stay far below
  // any feature size.
  const Vec3 lo = scene.boundsMin(), hi = scene.boundsMax();
  this->Centre = (lo + hi) * 0.5;
  const Vec3 half = (hi - lo) * 0.5;
  const double magnitude = std::max({ std::abs(half.x), std::abs(half.y), std::abs(half.z) });
  this->Offset = std::max(1e-5 * scene.diagonal(), 64 * 6e-8 * magnitude);
  if (!(this->Offset > 0))
  {
    this->Offset = 1e-9 * std::max(1.0, length(this->Centre)); // a single degenerate point
  }

  this->Impl->Scene = rtcNewScene(device);
  rtcSetSceneFlags(this->Impl->Scene, RTC_SCENE_FLAG_ROBUST);
  rtcSetSceneBuildQuality(this->Impl->Scene, RTC_BUILD_QUALITY_HIGH);
  RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
  const auto& points = scene.points();
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
    geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), points.size()));
  auto* indices = static_cast<std::uint32_t*>(rtcSetNewGeometryBuffer(geometry,
    RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(std::uint32_t), scene.elementCount()));
  raiseIfEmbreeFailed("building the ray-tracing scene");
  if (!vertices || !indices)
  {
    rtcReleaseGeometry(geometry);
    throw Error("Embree could not allocate the scene's buffers (out of memory?)");
  }
  for (std::size_t i = 0; i < points.size(); ++i)
  {
    const Vec3 p = points[i] - this->Centre;
    vertices[3 * i + 0] = static_cast<float>(p.x);
    vertices[3 * i + 1] = static_cast<float>(p.y);
    vertices[3 * i + 2] = static_cast<float>(p.z);
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

std::uint64_t RayTracer::estimateMemory(std::size_t elements, std::size_t points)
{
  return saturatingSum(saturatingProduct({ elements, 256 }), saturatingProduct({ points, 16 }));
}

namespace
{
/// The nearest hit of one ray from `origin` (relative to the tracer's centre): false on a miss.
bool traceNearest(RTCScene scene, const Vec3& origin, const Vec3& direction, RTCRayHit& query)
{
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
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
  rtcIntersect1(scene, &context, &query);
  return query.hit.geomID != RTC_INVALID_GEOMETRY_ID;
}
}

bool RayTracer::intersect(const Vec3& origin, const Vec3& direction, RayHit& hit) const
{
  RTCRayHit query;
  if (!traceNearest(this->Impl->Scene, origin - this->Centre, direction, query))
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

bool RayTracer::nearestSide(
  const Vec3& origin, const Vec3& direction, std::uint32_t& element, Side& side) const
{
  RTCRayHit query;
  if (!traceNearest(this->Impl->Scene, origin - this->Centre, direction, query))
  {
    return false;
  }
  element = query.hit.primID;
  side = dot(direction, this->SceneRef.elementNormal(element)) < 0 ? Side::Front : Side::Back;
  return true;
}

namespace
{
/// Traces `count` occlusion rays from one origin in 16-wide packets, lane i along
/// (dx[i], dy[i], dz[i]) up to tfar; a lane whose offset is not longer than `shortest` is
/// visible without tracing.
void occludedPackets(RTCScene scene, const Vec3& origin, const float* dx, const float* dy,
  const float* dz, std::size_t count, float tfar, float shortest, std::uint8_t* visible)
{
  constexpr std::size_t width = 16;
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRay16 packet;
  alignas(64) int valid[width];
  const float shortestSquared = shortest * shortest;
  for (std::size_t i = 0; i < width; ++i)
  {
    // The same in every packet.
    packet.org_x[i] = static_cast<float>(origin.x);
    packet.org_y[i] = static_cast<float>(origin.y);
    packet.org_z[i] = static_cast<float>(origin.z);
    packet.time[i] = 0.0f;
    packet.mask[i] = 0xFFFFFFFFu;
    packet.id[i] = static_cast<unsigned>(i);
    packet.flags[i] = 0;
    packet.tnear[i] = 0.0f; // Embree writes only tfar
  }
  for (std::size_t first = 0; first < count; first += width)
  {
    const std::size_t lanes = std::min(width, count - first);
    if (lanes == width)
    {
      // A full packet, the common case: straight copies and a test the compiler vectorises
      // (the lane set-up was a tenth of the solve's time when done lane by lane).
      std::memcpy(packet.dir_x, dx + first, sizeof(packet.dir_x));
      std::memcpy(packet.dir_y, dy + first, sizeof(packet.dir_y));
      std::memcpy(packet.dir_z, dz + first, sizeof(packet.dir_z));
      for (std::size_t i = 0; i < width; ++i)
      {
        const float x = packet.dir_x[i], y = packet.dir_y[i], z = packet.dir_z[i];
        valid[i] = x * x + y * y + z * z > shortestSquared ? -1 : 0;
        packet.tfar[i] = tfar;
      }
    }
    else
    {
      // Idle lanes repeat the last ray and are switched off in `valid`.
      for (std::size_t i = 0; i < width; ++i)
      {
        const std::size_t k = first + std::min(i, lanes - 1);
        const float x = dx[k], y = dy[k], z = dz[k];
        valid[i] = i < lanes && x * x + y * y + z * z > shortestSquared ? -1 : 0;
        packet.dir_x[i] = x;
        packet.dir_y[i] = y;
        packet.dir_z[i] = z;
        packet.tfar[i] = tfar;
      }
    }
    rtcOccluded16(valid, scene, &context, &packet);
    for (std::size_t i = 0; i < lanes; ++i)
    {
      // Embree sets tfar to -inf for an occluded ray; a switched-off lane (a target closer
      // than the offset) has nothing in between.
      visible[first + i] = !valid[i] || packet.tfar[i] >= 0.0f ? 1 : 0;
    }
  }
}
}

void RayTracer::visibleFrom(const Vec3& origin, const float* dx, const float* dy, const float* dz,
  std::size_t count, std::uint8_t* visible) const
{
  // The targets are lifted off their surfaces, as the rays that start there are: the whole
  // segment up to t = 1 is tested, with nothing to stop short of.
  occludedPackets(this->Impl->Scene, origin - this->Centre, dx, dy, dz, count, 1.0f,
    static_cast<float>(this->Offset), visible);
}

void RayTracer::visibleAlong(const Vec3& origin, const float* dx, const float* dy, const float* dz,
  std::size_t count, std::uint8_t* visible) const
{
  occludedPackets(this->Impl->Scene, origin - this->Centre, dx, dy, dz, count,
    std::numeric_limits<float>::infinity(), 0.0f, visible);
}

} // namespace mlr
