#include "Sensors.h"

#include "Error.h"
#include "Gathering.h"
#include "MemoryBudget.h"
#include "Parallel.h"
#include "Random.h"
#include "RayTracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <string>

namespace mlr
{

namespace
{
constexpr std::size_t SensorsPerTask = 16;

std::string sensorName(std::size_t i)
{
  return "sensor " + std::to_string(i);
}

/// The pose index of a light with `positions` poses in frame `frame`.
std::size_t poseOf(std::size_t positions, std::size_t frame)
{
  return positions > 1 ? frame : 0;
}

/// One sensor's sums, per frame, kept in double and in one fixed order.
struct SensorScratch
{
  std::vector<Rgb> total, sun, gathered;
  std::vector<double> skySum;
  std::vector<std::size_t> hits, cells;
  std::vector<float> dx, dy, dz;
  std::vector<std::uint8_t> visible;
  std::vector<Rgb> values;
  std::vector<std::uint32_t> targets;
  std::vector<std::size_t> skyBase;
  /// The rays this worker cast (SensorStatistics).
  std::uint64_t shadowRays = 0, gatheringRays = 0;

  /// Room for every sensor's work, so that no vector grows (and memory is what
  /// estimateSensorMemory says): `batch` shadow rays at most per light.
  void reserve(std::size_t frames, std::size_t skyPositions, std::size_t skies, std::size_t rays,
    std::size_t batch)
  {
    for (std::vector<Rgb>* v : { &this->total, &this->sun, &this->gathered })
    {
      v->reserve(frames);
    }
    this->skySum.reserve(skyPositions);
    this->hits.reserve(rays);
    this->cells.reserve(rays * skies);
    for (std::vector<float>* v : { &this->dx, &this->dy, &this->dz })
    {
      v->reserve(batch);
    }
    this->visible.reserve(batch);
    this->values.reserve(batch);
    this->targets.reserve(batch);
    this->skyBase.reserve(skies);
  }
  /// The bytes reserve() takes.
  static std::uint64_t bytes(std::size_t frames, std::size_t skyPositions, std::size_t skies,
    std::size_t rays, std::size_t batch)
  {
    return saturatingSum(saturatingSum(saturatingProduct(3 * sizeof(Rgb), frames),
                           saturatingProduct(sizeof(double), skyPositions)),
      saturatingSum(saturatingProduct({ sizeof(std::size_t), rays, 1 + skies }),
        saturatingSum(
          saturatingProduct(
            3 * sizeof(float) + sizeof(std::uint8_t) + sizeof(Rgb) + sizeof(std::uint32_t), batch),
          saturatingProduct(sizeof(std::size_t), skies))));
  }

  void clearRays()
  {
    this->dx.clear();
    this->dy.clear();
    this->dz.clear();
    this->values.clear();
    this->targets.clear();
  }
  void addRay(const Vec3& d, const Rgb& value, std::size_t frame)
  {
    this->dx.push_back(static_cast<float>(d.x));
    this->dy.push_back(static_cast<float>(d.y));
    this->dz.push_back(static_cast<float>(d.z));
    this->values.push_back(value);
    this->targets.push_back(static_cast<std::uint32_t>(frame));
  }
};

/// Adds to `into` the values of the rays in `scratch` that are not blocked, in ray order.
void traceShadows(const RayTracer& tracer, const Vec3& origin, bool toInfinity,
  SensorScratch& scratch, std::vector<Rgb>& into)
{
  const std::size_t count = scratch.dx.size();
  if (count == 0)
  {
    return;
  }
  scratch.visible.assign(count, 0);
  scratch.shadowRays += count;
  if (toInfinity)
  {
    tracer.visibleAlong(origin, scratch.dx.data(), scratch.dy.data(), scratch.dz.data(), count,
      scratch.visible.data());
  }
  else
  {
    tracer.visibleFrom(origin, scratch.dx.data(), scratch.dy.data(), scratch.dz.data(), count,
      scratch.visible.data());
  }
  for (std::size_t i = 0; i < count; ++i)
  {
    if (scratch.visible[i])
    {
      into[scratch.targets[i]] += scratch.values[i];
    }
  }
}

/// f(w) of a light's distribution towards `towards` (unit, from the light) in pose `k`: the
/// Lambertian one from the sampled point's own normal, as the reuse kernel has it.
double emittedDensity(const IntensityDistribution& f, const PhotometricFrame& frame,
  const Vec3& normal, const Vec3& towards)
{
  if (f.isLambertian())
  {
    return std::max(0.0, dot(normal, towards)) / M_PI;
  }
  return f.density(frame.toLocal(towards));
}

void solveSensor(const Scene& scene, const RayTracer& tracer, const LightRig& rig,
  const std::vector<MovingLight>& emitters, const Solution& solution, const SensorSet& sensors,
  std::size_t s, const SolverOptions& options, const SensorOptions& sensorOptions,
  SensorScratch& scratch, SensorSolution& result)
{
  const std::size_t frames = solution.frameCount();
  const Vec3& p = sensors.points[s];
  const Vec3& n = sensors.normals[s];
  const Vec3 origin = tracer.liftOff(p, n);
  const double offset = tracer.surfaceOffset();
  scratch.total.assign(frames, Rgb());
  scratch.sun.assign(frames, Rgb());
  scratch.gathered.assign(frames, Rgb());

  // The hemisphere, once for all frames: sky visibility and the surface a ray reaches do not
  // depend on the frame, only the radiance found there does.
  std::size_t skyPositions = 0;
  std::vector<std::size_t>& skyBase = scratch.skyBase;
  skyBase.clear();
  for (const Sky& sky : rig.skies)
  {
    skyBase.push_back(skyPositions);
    skyPositions += sky.positions();
  }
  scratch.skySum.assign(skyPositions, 0.0);
  RandomStream random(options.seed, StreamPurpose::Sensors, s, 0);
  const std::uint32_t rays = sensorOptions.hemisphereRays;
  scratch.gatheringRays += rays;
  // What each ray found, as keys: an element side (2 element + side), or an escaped ray's sky
  // cell per sky. Sorted and counted, each distinct key costs one pass over the frames,
  // however many rays found it, and the sums run in key order.
  scratch.hits.clear();
  scratch.cells.clear();
  for (std::uint32_t r = 0; r < rays; ++r)
  {
    const Vec3 direction = sampleCosineDirection(n, random);
    std::uint32_t element = 0;
    Side side = Side::Front;
    if (!tracer.nearestSide(origin, direction, element, side))
    {
      for (std::size_t k = 0; k < rig.skies.size(); ++k)
      {
        const std::size_t cell = rig.skies[k].cell(direction);
        if (cell < Sky::Cells)
        {
          scratch.cells.push_back(k * Sky::Cells + cell);
        }
      }
    }
    else if (options.twoSided || side == Side::Front)
    {
      scratch.hits.push_back(
        2 * static_cast<std::size_t>(element) + static_cast<std::size_t>(side));
    }
  }
  std::sort(scratch.hits.begin(), scratch.hits.end());
  std::sort(scratch.cells.begin(), scratch.cells.end());
  for (std::size_t i = 0; i < scratch.hits.size();)
  {
    std::size_t end = i;
    while (end < scratch.hits.size() && scratch.hits[end] == scratch.hits[i])
    {
      ++end;
    }
    const double count = static_cast<double>(end - i);
    const std::size_t element = scratch.hits[i] / 2;
    const Side side = static_cast<Side>(scratch.hits[i] % 2);
    for (std::size_t f = 0; f < frames; ++f)
    {
      scratch.gathered[f] += gatheredRadiosity(scene, solution, f, element, side) * count;
    }
    i = end;
  }
  for (std::size_t i = 0; i < scratch.cells.size();)
  {
    std::size_t end = i;
    while (end < scratch.cells.size() && scratch.cells[end] == scratch.cells[i])
    {
      ++end;
    }
    const double count = static_cast<double>(end - i);
    const std::size_t k = scratch.cells[i] / Sky::Cells;
    const Sky& sky = rig.skies[k];
    const double* density = sky.densities(scratch.cells[i] % Sky::Cells);
    double* sum = scratch.skySum.data() + skyBase[k];
    for (std::size_t j = 0; j < sky.positions(); ++j)
    {
      sum[j] += density[j] * count;
    }
    i = end;
  }
  const double perRay = 1.0 / static_cast<double>(rays);
  for (std::size_t f = 0; f < frames; ++f)
  {
    scratch.total[f] += scratch.gathered[f] * perRay;
    // Cosine-distributed directions: L(w) cos / pdf = pi L(w), L = density Lambda.
    for (std::size_t k = 0; k < rig.skies.size(); ++k)
    {
      const Sky& sky = rig.skies[k];
      const std::size_t j = poseOf(sky.positions(), f);
      scratch.total[f] += Rgb(M_PI * sky.integral(j) * scratch.skySum[skyBase[k] + j] * perRay);
    }
  }

  // Directional lights: one shadow ray per frame.
  for (const DirectionalLight& light : rig.directionalLights)
  {
    scratch.clearRays();
    for (std::size_t f = 0; f < frames; ++f)
    {
      const std::size_t k = poseOf(light.frameCount(), f);
      const Vec3& towards = light.direction(k);
      const double cosine = dot(n, towards);
      const Rgb e = light.irradiance() * light.powerFactor(k) * cosine;
      if (cosine > 0 && e.maxComponent() > 0)
      {
        scratch.addRay(towards, e, f);
      }
    }
    traceShadows(tracer, origin, true, scratch, scratch.sun);
  }

  // Point lights: Phi s_k f_k(w) cos / r^2, one shadow ray per frame.
  for (const PointLight& light : rig.pointLights)
  {
    scratch.clearRays();
    for (std::size_t f = 0; f < frames; ++f)
    {
      const std::size_t k = poseOf(light.frameCount(), f);
      const Vec3 d = p - light.position(k);
      const double r2 = dot(d, d);
      const double r = std::sqrt(r2);
      const double cosine = r > 0 ? -dot(n, d) / r : 0;
      const Rgb power = light.power() * light.pose(k).power;
      if (!(cosine > 0) || !(power.maxComponent() > 0))
      {
        continue;
      }
      const Vec3 towards = d / r;
      const double density =
        light.distribution().density(light.photometricFrame(k).toLocal(towards));
      if (density > 0)
      {
        scratch.addRay(light.position(k) - origin, power * (density * cosine / r2), f);
      }
    }
    traceShadows(tracer, origin, false, scratch, scratch.total);
  }

  // Area lights and the scene's emitters: the same uniform points of the light in every
  // frame, posed there, each with its shadow ray.
  const std::uint32_t samples = sensorOptions.areaLightSamples;
  const std::size_t areaLights = rig.areaLights.size() + emitters.size();
  for (std::size_t i = 0; i < areaLights; ++i)
  {
    const MovingLight& light =
      i < rig.areaLights.size() ? rig.areaLights[i] : emitters[i - rig.areaLights.size()];
    const IntensityDistribution& f = light.distribution();
    RandomStream lightRandom(options.seed, StreamPurpose::Sensors, s, 1 + i);
    // A jittered grid: the largest m x m grid that the samples fill, one point in each cell
    // of the unit square, which samplePoint maps to equal areas of the light; the rest
    // independent. Each point is uniform on the light, so the estimate is unbiased, and the
    // light's smooth variation over its extent averages out instead of staying as noise.
    const auto side = static_cast<std::uint32_t>(std::sqrt(static_cast<double>(samples)));
    scratch.clearRays();
    for (std::uint32_t q = 0; q < samples; ++q)
    {
      double u = lightRandom.uniform(), v = lightRandom.uniform();
      if (q < side * side)
      {
        u = (q % side + u) / side;
        v = (q / side + v) / side;
      }
      Vec3 own, ownNormal;
      light.samplePoint(u, v, own, ownNormal);
      for (std::size_t frame = 0; frame < frames; ++frame)
      {
        const std::size_t k = poseOf(light.frameCount(), frame);
        const Rgb power = light.power() * light.pose(k).power;
        if (!(power.maxComponent() > 0))
        {
          continue;
        }
        const Vec3 x = light.place(k, own);
        const Vec3 normal = light.turn(k, ownNormal);
        const Vec3 d = p - x;
        const double r2 = dot(d, d);
        const double r = std::sqrt(r2);
        const double cosine = r > 0 ? -dot(n, d) / r : 0;
        if (!(cosine > 0))
        {
          continue;
        }
        const double density = emittedDensity(f, light.photometricFrame(k), normal, d / r);
        if (density > 0)
        {
          // The end lifted off the light on the sensor's side, as the reuse kernel's.
          const Vec3 end = x + normal * (dot(d, normal) < 0 ? -offset : offset);
          scratch.addRay(
            end - origin, power * (density * cosine / (r2 * static_cast<double>(samples))), frame);
        }
      }
    }
    traceShadows(tracer, origin, false, scratch, scratch.total);
  }

  for (std::size_t frame = 0; frame < frames; ++frame)
  {
    result.irradianceData()[s * frames + frame] =
      FloatRgb(scratch.total[frame] + scratch.sun[frame]);
    result.sunData()[s * frames + frame] = FloatRgb(scratch.sun[frame]);
  }
}
}

void checkSensors(const SensorSet& sensors, const SensorOptions& options)
{
  if (sensors.normals.size() != sensors.points.size())
  {
    throw Error("the sensors have " + std::to_string(sensors.points.size()) + " points but " +
      std::to_string(sensors.normals.size()) +
      " normals: give every sensor point a normal (point array Normals, 3 components), the "
      "direction its measuring side faces");
  }
  if (sensors.points.size() > MaximumSensors)
  {
    throw Error("there are " + std::to_string(sensors.points.size()) +
      " sensors, over the maximum of " + std::to_string(MaximumSensors) +
      ": use a coarser grid of sensors");
  }
  for (std::size_t i = 0; i < sensors.points.size(); ++i)
  {
    if (!isFinite(sensors.points[i]) || !isWithinCoordinateRange(sensors.points[i]))
    {
      throw Error(sensorName(i) +
        " has a point that is not finite or beyond +-1e15: give "
        "finite sensor coordinates");
    }
    const Vec3& normal = sensors.normals[i];
    const double m = std::max({ std::abs(normal.x), std::abs(normal.y), std::abs(normal.z) });
    if (!isFinite(normal) || !(m > 0))
    {
      throw Error(sensorName(i) +
        " has a zero or non-finite normal: give each sensor the direction its measuring "
        "side faces (any length but 0)");
    }
  }
  for (const auto& [count, what] : { std::make_pair(options.hemisphereRays, "hemisphere rays"),
         std::make_pair(options.areaLightSamples, "area light samples") })
  {
    if (count < 1 || count > MaximumSensorRays)
    {
      throw Error(std::string("the sensors' ") + what + " per sensor are " + std::to_string(count) +
        ": give 1 to " + std::to_string(MaximumSensorRays));
    }
  }
}

SensorSet normalizedSensors(const SensorSet& sensors, const SensorOptions& options)
{
  checkSensors(sensors, options);
  SensorSet unit = sensors;
  for (Vec3& normal : unit.normals)
  {
    // Scaled first, so that a normal near the largest double still has a finite length.
    const double m = std::max({ std::abs(normal.x), std::abs(normal.y), std::abs(normal.z) });
    normal = normalize(normal / m);
  }
  return unit;
}

namespace
{
/// The sky positions of a rig, all its skies together.
std::size_t skyPositionsOf(const LightRig& rig)
{
  std::size_t positions = 0;
  for (const Sky& sky : rig.skies)
  {
    positions += sky.positions();
  }
  return positions;
}

/// The most shadow rays one light casts from one sensor: one per frame for directional and
/// point lights, one per sample and frame for area lights and the scene's emitters.
std::size_t shadowBatch(
  const LightRig& rig, bool sceneEmits, std::size_t frames, const SensorOptions& sensorOptions)
{
  std::size_t batch = 0;
  if (!rig.directionalLights.empty() || !rig.pointLights.empty())
  {
    batch = frames;
  }
  if (!rig.areaLights.empty() || sceneEmits)
  {
    batch = std::max<std::size_t>(
      batch, saturatingProduct(std::max<std::uint32_t>(sensorOptions.areaLightSamples, 1), frames));
  }
  return batch;
}
}

std::uint64_t estimateSensorMemory(std::size_t sensors, std::size_t frames, std::size_t elements,
  std::size_t points, const LightRig& rig, bool sceneEmits, const SolverOptions& options,
  const SensorOptions& sensorOptions)
{
  if (sensors == 0)
  {
    return 0;
  }
  // The two results (a FloatRgb each) and the unit points and normals.
  const std::uint64_t results =
    saturatingSum(saturatingProduct({ 2 * sizeof(FloatRgb), sensors, frames }),
      saturatingProduct(2 * sizeof(Vec3), sensors));
  const auto workers = static_cast<std::uint64_t>(resolveThreadCount(options.threads));
  const std::uint64_t scratch = saturatingProduct(workers,
    SensorScratch::bytes(frames, skyPositionsOf(rig), rig.skies.size(),
      sensorOptions.hemisphereRays, shadowBatch(rig, sceneEmits, frames, sensorOptions)));
  // The scene's emitters as area lights: their triangles, generously per element.
  const std::uint64_t emitters = sceneEmits ? saturatingProduct(elements, 256) : 0;
  return saturatingSum(saturatingSum(results, scratch),
    saturatingSum(RayTracer::estimateMemory(elements, points), emitters));
}

SensorSolution solveSensors(const Scene& scene, const LightRig& rig, const Solution& solution,
  const SensorSet& given, const SolverOptions& options, const SensorOptions& sensorOptions,
  const std::function<bool(double fraction)>& progress)
{
  const auto started = std::chrono::steady_clock::now();
  const SensorSet sensors = normalizedSensors(given, sensorOptions);
  const std::size_t frames = solution.frameCount();
  SensorSolution result(frames, sensors.size());
  if (sensors.empty() || frames == 0)
  {
    return result;
  }
  const RayTracer tracer(scene);
  const std::vector<MovingLight> emitters = sceneEmitters(scene);
  const int workers = resolveThreadCount(options.threads);
  std::vector<SensorScratch> scratch(static_cast<std::size_t>(workers));
  const std::size_t batch = shadowBatch(rig, !emitters.empty(), frames, sensorOptions);
  for (SensorScratch& worker : scratch)
  {
    worker.reserve(
      frames, skyPositionsOf(rig), rig.skies.size(), sensorOptions.hemisphereRays, batch);
  }
  const std::size_t tasks = (sensors.size() + SensorsPerTask - 1) / SensorsPerTask;
  parallelFor(
    tasks, workers,
    [&](std::size_t task, int worker)
    {
      const std::size_t end = std::min(sensors.size(), (task + 1) * SensorsPerTask);
      for (std::size_t s = task * SensorsPerTask; s < end; ++s)
      {
        solveSensor(scene, tracer, rig, emitters, solution, sensors, s, options, sensorOptions,
          scratch[static_cast<std::size_t>(worker)], result);
      }
    },
    [&](std::size_t done)
    { return !progress || progress(static_cast<double>(done) / static_cast<double>(tasks)); });
  for (const SensorScratch& worker : scratch)
  {
    result.statistics().shadowRays += worker.shadowRays;
    result.statistics().gatheringRays += worker.gatheringRays;
  }
  result.statistics().seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

DaylightMetrics daylightMetrics(const double* illuminance, const double* sunIlluminance,
  std::size_t steps, double threshold, double hoursPerStep)
{
  if (!(threshold >= 0) || !std::isfinite(threshold))
  {
    throw Error("the daylight autonomy threshold is " + std::to_string(threshold) +
      " lx: give a finite illuminance of 0 or more (300 lx is typical)");
  }
  if (!(hoursPerStep >= 0) || !std::isfinite(hoursPerStep))
  {
    throw Error("a time step lasts " + std::to_string(hoursPerStep) +
      " hours: give the frames' times in hours, increasing");
  }
  DaylightMetrics m;
  if (steps == 0)
  {
    return m;
  }
  std::size_t autonomous = 0, low = 0, useful = 0, high = 0, sunny = 0;
  for (std::size_t i = 0; i < steps; ++i)
  {
    const double e = illuminance[i];
    autonomous += e >= threshold ? 1 : 0;
    low += e < UdiLowBound ? 1 : 0;
    high += e > UdiHighBound ? 1 : 0;
    useful += e >= UdiLowBound && e <= UdiHighBound ? 1 : 0;
    sunny += sunIlluminance[i] > DirectSunBound ? 1 : 0;
  }
  const double n = static_cast<double>(steps);
  m.autonomy = static_cast<double>(autonomous) / n;
  m.udiLow = static_cast<double>(low) / n;
  m.udiUseful = static_cast<double>(useful) / n;
  m.udiHigh = static_cast<double>(high) / n;
  m.directSunHours = static_cast<double>(sunny) * hoursPerStep;
  return m;
}

double hoursPerTimeStep(const std::vector<double>& times)
{
  std::vector<double> spacing;
  for (std::size_t i = 1; i < times.size(); ++i)
  {
    const double d = times[i] - times[i - 1];
    if (d > 0 && std::isfinite(d))
    {
      spacing.push_back(d);
    }
  }
  if (spacing.empty())
  {
    return 1.0;
  }
  const std::size_t middle = spacing.size() / 2;
  std::nth_element(
    spacing.begin(), spacing.begin() + static_cast<std::ptrdiff_t>(middle), spacing.end());
  return spacing[middle];
}

} // namespace mlr
