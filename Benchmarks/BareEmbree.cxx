#include "BareEmbree.h"

#include "Random.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>
#include <vector>

namespace mlr::bench
{

namespace
{
struct Ray
{
  float org[3];
  float dir[3];
};

/// The same Embree set-up as the solver's RayTracer: robust, high-quality BVH, float3
/// vertices, one triangle per element.
class BareScene
{
public:
  explicit BareScene(const Scene& scene)
  {
    this->Device = rtcNewDevice("verbose=0");
    this->Handle = rtcNewScene(this->Device);
    rtcSetSceneFlags(this->Handle, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(this->Handle, RTC_BUILD_QUALITY_HIGH);
    RTCGeometry g = rtcNewGeometry(this->Device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* v = static_cast<float*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), scene.points().size()));
    for (std::size_t i = 0; i < scene.points().size(); ++i)
    {
      for (int k = 0; k < 3; ++k)
      {
        v[3 * i + k] = static_cast<float>(scene.points()[i][k]);
      }
    }
    auto* ix = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      g, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(unsigned), scene.elementCount()));
    for (std::size_t e = 0; e < scene.elementCount(); ++e)
    {
      for (int k = 0; k < 3; ++k)
      {
        ix[3 * e + k] = scene.elementTriangles()[e][k];
      }
    }
    rtcCommitGeometry(g);
    rtcAttachGeometry(this->Handle, g);
    rtcReleaseGeometry(g);
    rtcCommitScene(this->Handle);
  }
  ~BareScene()
  {
    rtcReleaseScene(this->Handle);
    rtcReleaseDevice(this->Device);
  }
  RTCScene handle() const { return this->Handle; }

private:
  RTCDevice Device;
  RTCScene Handle;
};

Ray makeRay(const Vec3& o, const Vec3& d)
{
  return { { float(o.x), float(o.y), float(o.z) }, { float(d.x), float(d.y), float(d.z) } };
}

/// Runs work(begin, end) over [0, count) split evenly on `threads` threads; returns seconds.
template <typename Work>
double timeParallelOnce(std::size_t count, int threads, Work& work)
{
  const auto start = std::chrono::steady_clock::now();
  std::vector<std::thread> pool;
  for (int t = 0; t < threads; ++t)
  {
    pool.emplace_back([=] { work(count * t / threads, count * (t + 1) / threads); });
  }
  for (auto& t : pool)
  {
    t.join();
  }
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// Runs work(begin, end) over [0, count) split evenly on `threads` threads; returns the best
/// seconds of three runs (bare Embree's figure is its best case; the rays are the same).
template <typename Work>
double timeParallel(std::size_t count, int threads, Work work)
{
  double best = 1e300;
  for (int run = 0; run < 3; ++run)
  {
    best = std::min(best, timeParallelOnce(count, threads, work));
  }
  return best;
}

double traceNearest(RTCScene scene, const std::vector<Ray>& rays, int threads)
{
  std::vector<unsigned> sink(static_cast<std::size_t>(threads) * 16, 0);
  const double seconds = timeParallel(rays.size(), threads,
    [&](std::size_t begin, std::size_t end)
    {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      unsigned hits = 0;
      for (std::size_t i = begin; i < end; ++i)
      {
        RTCRayHit q;
        q.ray.org_x = rays[i].org[0];
        q.ray.org_y = rays[i].org[1];
        q.ray.org_z = rays[i].org[2];
        q.ray.dir_x = rays[i].dir[0];
        q.ray.dir_y = rays[i].dir[1];
        q.ray.dir_z = rays[i].dir[2];
        q.ray.tnear = 0;
        q.ray.tfar = 1e30f;
        q.ray.time = 0;
        q.ray.mask = ~0u;
        q.ray.id = 0;
        q.ray.flags = 0;
        q.hit.geomID = RTC_INVALID_GEOMETRY_ID;
        rtcIntersect1(scene, &context, &q);
        hits += q.hit.geomID != RTC_INVALID_GEOMETRY_ID;
      }
      sink[begin % sink.size()] = hits;
    });
  return double(rays.size()) / seconds;
}
}

BareRates measureBareEmbree(
  const Scene& scene, const MovingLight& light, int threads, std::size_t samples)
{
  BareScene bare(scene);
  BareRates rates;
  const double offset = 1e-5 * scene.diagonal();
  const std::size_t frames = light.frameCount();

  // Light rays: a uniform point of the light at a uniform position, cosine direction.
  std::vector<Ray> rays(samples);
  for (std::size_t i = 0; i < samples; ++i)
  {
    RandomStream r(1, StreamPurpose::Shooting, i);
    Vec3 x, n;
    light.samplePoint(r.uniform(), r.uniform(), r.uniform(), x, n);
    x += light.translation(std::min(frames - 1, std::size_t(r.uniform() * double(frames))));
    rays[i] = makeRay(x + n * offset, sampleCosineDirection(n, r));
  }
  rates.lightRays = traceNearest(bare.handle(), rays, threads);

  // Surface rays: a uniform element point (area-weighted), cosine around its normal.
  std::vector<double> cumulative(scene.elementCount());
  double area = 0;
  for (std::size_t e = 0; e < scene.elementCount(); ++e)
  {
    area += scene.elementArea(e);
    cumulative[e] = area;
  }
  auto surfacePoint = [&](RandomStream& r, Vec3& p, Vec3& n)
  {
    const auto it = std::upper_bound(cumulative.begin(), cumulative.end(), r.uniform() * area);
    const std::size_t e =
      std::min<std::size_t>(std::size_t(it - cumulative.begin()), scene.elementCount() - 1);
    const Triangle& t = scene.elementTriangles()[e];
    p = sampleTriangle(
      scene.points()[t[0]], scene.points()[t[1]], scene.points()[t[2]], r.uniform(), r.uniform());
    n = scene.elementNormal(e);
    p += n * offset;
  };
  for (std::size_t i = 0; i < samples; ++i)
  {
    RandomStream r(2, StreamPurpose::Gathering, i);
    Vec3 p, n;
    surfacePoint(r, p, n);
    rays[i] = makeRay(p, sampleCosineDirection(n, r));
  }
  rates.surfaceRays = traceNearest(bare.handle(), rays, threads);

  // Shadow rays: from a surface point to one light point at every position, 16 per packet.
  const std::size_t origins = std::max<std::size_t>(1, samples / frames);
  std::vector<Ray> targets(origins * frames);
  for (std::size_t i = 0; i < origins; ++i)
  {
    RandomStream r(3, StreamPurpose::Gathering, i);
    Vec3 p, n, x, nl;
    surfacePoint(r, p, n);
    light.samplePoint(r.uniform(), r.uniform(), r.uniform(), x, nl);
    for (std::size_t k = 0; k < frames; ++k)
    {
      targets[i * frames + k] = makeRay(p, x + light.translation(k) - p);
    }
  }
  std::vector<unsigned> sink(static_cast<std::size_t>(threads) * 16, 0);
  const double seconds = timeParallel(origins, threads,
    [&](std::size_t begin, std::size_t end)
    {
      RTCIntersectContext context;
      rtcInitIntersectContext(&context);
      context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
      alignas(64) RTCRay16 packet;
      alignas(64) int valid[16];
      unsigned visible = 0;
      for (std::size_t i = begin; i < end; ++i)
      {
        for (std::size_t first = 0; first < frames; first += 16)
        {
          for (std::size_t l = 0; l < 16; ++l)
          {
            const bool on = first + l < frames;
            const Ray& ray = targets[i * frames + std::min(first + l, frames - 1)];
            valid[l] = on ? -1 : 0;
            packet.org_x[l] = ray.org[0];
            packet.org_y[l] = ray.org[1];
            packet.org_z[l] = ray.org[2];
            packet.dir_x[l] = ray.dir[0];
            packet.dir_y[l] = ray.dir[1];
            packet.dir_z[l] = ray.dir[2];
            packet.tnear[l] = 0;
            packet.tfar[l] = 0.9999f;
            packet.time[l] = 0;
            packet.mask[l] = ~0u;
            packet.id[l] = unsigned(l);
            packet.flags[l] = 0;
          }
          rtcOccluded16(valid, bare.handle(), &context, &packet);
          for (std::size_t l = 0; l < 16; ++l)
          {
            visible += valid[l] && packet.tfar[l] >= 0;
          }
        }
      }
      sink[begin % sink.size()] = visible;
    });
  rates.shadowRays = double(origins * frames) / seconds;
  return rates;
}

double printShadowRays(const SolverStatistics& full, std::size_t frames, const BareRates& bare)
{
  const double possible = double(full.firstHits) * double(frames - 1);
  const double shadow = double(full.shadowRays);
  const double nearestSeconds = double(full.pathsCast) / bare.lightRays +
    double(full.shootingRays - full.pathsCast) / bare.surfaceRays;
  const double solverRate = shadow / (full.secondsShooting - nearestSeconds);
  std::printf("Shadow rays of full reuse: %.0f first hits x %zu other positions = %.3g possible; "
              "%.1f%% skipped (zero unoccluded kernel), %.3g cast, %.1f%% of them blocked\n",
    double(full.firstHits), frames - 1, possible, 100 * (1 - shadow / possible), shadow,
    100 * double(full.shadowRaysBlocked) / shadow);
  std::printf(
    "Shadow rays are %.1f%% of full reuse's rays. Their rate in the solver: %.1f M/s "
    "(shooting's %.2f s less %.2f s for its nearest-hit rays at bare speed, weights and "
    "scoring included); bare Embree's rtcOccluded16 on the same scene: %.1f M/s (%.2fx)\n",
    100 * shadow /
      double(full.shootingRays + full.shadowRays + full.gatheringRays + full.reachabilityRays),
    solverRate / 1e6, full.secondsShooting, nearestSeconds, bare.shadowRays / 1e6,
    bare.shadowRays / solverRate);
  return solverRate;
}

} // namespace mlr::bench
