#include "Sensors.h"

#include "Chunks.h"
#include "Error.h"
#include "Gathering.h"
#include "MemoryBudget.h"
#include "Parallel.h"
#include "Random.h"
#include "RayTracer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <string>
#include <tuple>

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
  /// The variance of the sensor's estimate per frame, and the sums it is made of: the squares
  /// of the hemisphere rays' values, and per point of an area light its values (point-major,
  /// frames innermost), their sum and squares and the strata's differences.
  std::vector<Rgb> variance, gatheredSquares, pointSum, pointSquares, strata;
  std::vector<Rgb> perPoint;
  std::vector<double> skySum, skySquares;
  std::vector<float> dx, dy, dz;
  std::vector<std::uint8_t> visible;
  std::vector<Rgb> values;
  std::vector<std::uint32_t> targets, points;
  std::vector<std::size_t> skyBase;
  /// The rays this worker cast (SensorStatistics).
  std::uint64_t shadowRays = 0, gatheringRays = 0;

  /// Room for every sensor's work on a block of `frames`, so that no vector grows (and memory
  /// is what estimateSensorMemory says): `skyEntries` sums over the skies' positions, `batch`
  /// shadow rays at most per light, and `pointFrames` values of an area light's points over
  /// the frames.
  void reserve(std::size_t frames, std::size_t skyEntries, std::size_t skies, std::size_t batch,
    std::size_t pointFrames)
  {
    for (std::vector<Rgb>* v : { &this->total, &this->sun, &this->gathered, &this->variance,
           &this->gatheredSquares, &this->pointSum, &this->pointSquares, &this->strata })
    {
      v->reserve(frames);
    }
    this->perPoint.reserve(pointFrames);
    this->skySum.reserve(skyEntries);
    this->skySquares.reserve(skyEntries);
    for (std::vector<float>* v : { &this->dx, &this->dy, &this->dz })
    {
      v->reserve(batch);
    }
    this->visible.reserve(batch);
    this->values.reserve(batch);
    this->targets.reserve(batch);
    this->points.reserve(batch);
    this->skyBase.reserve(skies);
  }
  /// The bytes reserve() takes.
  static std::uint64_t bytes(std::size_t frames, std::size_t skyEntries, std::size_t skies,
    std::size_t batch, std::size_t pointFrames)
  {
    return saturatingSum(saturatingSum(saturatingSum(saturatingProduct(8 * sizeof(Rgb), frames),
                                         saturatingProduct(2 * sizeof(double), skyEntries)),
                           saturatingProduct(sizeof(Rgb), pointFrames)),
      saturatingSum(saturatingProduct(3 * sizeof(float) + sizeof(std::uint8_t) + sizeof(Rgb) +
                        2 * sizeof(std::uint32_t),
                      batch),
        saturatingProduct(sizeof(std::size_t), skies)));
  }

  void clearRays()
  {
    this->dx.clear();
    this->dy.clear();
    this->dz.clear();
    this->values.clear();
    this->targets.clear();
    this->points.clear();
  }
  void addRay(const Vec3& d, const Rgb& value, std::size_t frame, std::uint32_t point = 0)
  {
    this->dx.push_back(static_cast<float>(d.x));
    this->dy.push_back(static_cast<float>(d.y));
    this->dz.push_back(static_cast<float>(d.z));
    this->values.push_back(value);
    this->targets.push_back(static_cast<std::uint32_t>(frame));
    this->points.push_back(point);
  }
};

/**
 * Casts sensor `s`'s hemisphere rays from `origin` about `n`, the streams of solveSensors
 * and SensorBatchSpread alike, so that both read through the same rays: each ray that reaches
 * an element side that gathers (front sides only when one-sided) goes to `hits` as
 * 2 element + side, in ray order; `onMiss` gets the direction of each ray that escapes.
 */
template <typename OnMiss>
void castHemisphere(const RayTracer& tracer, const Vec3& origin, const Vec3& n, std::size_t s,
  const SolverOptions& options, std::uint32_t rays, std::vector<std::size_t>& hits,
  const OnMiss& onMiss)
{
  RandomStream random(options.seed, StreamPurpose::Sensors, s, 0);
  for (std::uint32_t r = 0; r < rays; ++r)
  {
    const Vec3 direction = sampleCosineDirection(n, random);
    std::uint32_t element = 0;
    Side side = Side::Front;
    if (!tracer.nearestSide(origin, direction, element, side))
    {
      onMiss(direction);
    }
    else if (options.twoSided || side == Side::Front)
    {
      hits.push_back(2 * static_cast<std::size_t>(element) + static_cast<std::size_t>(side));
    }
  }
}

/// The variance of the mean of `n` independent values from their sum and sum of squares
/// (per channel); for a single value, its square, which bounds it.
Rgb varianceOfMean(const Rgb& sum, const Rgb& squares, double n)
{
  if (n < 2)
  {
    return squares;
  }
  const Rgb spread = squares - sum * sum * (1.0 / n);
  const double scale = 1.0 / (n * (n - 1));
  return Rgb(std::max(0.0, spread.r), std::max(0.0, spread.g), std::max(0.0, spread.b)) * scale;
}

/**
 * Adds to scratch.variance, per frame, the variance of an area light's estimate: the sum of
 * the values of its `count` points (scratch.perPoint, 0 where blocked or behind). The first
 * m x m points are a jittered grid, one in each cell, whose estimate's variance is the sum of
 * the cells' own, not the spread of the points over the light (their means differ, and the
 * grid takes that difference out). Each cell's variance is estimated from the second
 * difference of three cells next to each other along v (a - 2b + c: of variance
 * s_a^2 + 4 s_b^2 + s_c^2, and free of any trend of the light's values that is linear across
 * them; along v, since u picks the light's triangle and v moves within it), half its square
 * counting for the three. Left-over rows count as the rows measured, a grid of 2 x 2 takes the
 * differences of pairs (which keep the trend: an upper bound), and the points beyond the grid,
 * independent and uniform on the light, take the spread of all the points, each of which is
 * uniform on it.
 */
void addAreaLightVariance(std::uint32_t count, std::size_t frames, SensorScratch& scratch)
{
  const auto side = static_cast<std::uint32_t>(std::sqrt(static_cast<double>(count)));
  const std::size_t grid = side >= 2 ? static_cast<std::size_t>(side) * side : 0;
  const Rgb* v = scratch.perPoint.data();
  scratch.pointSum.assign(frames, Rgb());
  scratch.pointSquares.assign(frames, Rgb());
  scratch.strata.assign(frames, Rgb());
  for (std::uint32_t q = 0; q < count; ++q)
  {
    const Rgb* row = v + static_cast<std::size_t>(q) * frames;
    for (std::size_t f = 0; f < frames; ++f)
    {
      scratch.pointSum[f] += row[f];
      scratch.pointSquares[f] += row[f] * row[f];
    }
  }
  double scale = 1;
  if (side >= 3)
  {
    const std::uint32_t triples = side / 3;
    scale = static_cast<double>(side) / (3.0 * triples);
    for (std::uint32_t t = 0; t < triples; ++t)
    {
      for (std::uint32_t c = 0; c < side; ++c)
      {
        const std::size_t a = static_cast<std::size_t>(3 * t * side + c);
        const Rgb* va = v + a * frames;
        const Rgb* vb = va + static_cast<std::size_t>(side) * frames;
        const Rgb* vc = vb + static_cast<std::size_t>(side) * frames;
        for (std::size_t f = 0; f < frames; ++f)
        {
          const Rgb d = va[f] - vb[f] * 2.0 + vc[f];
          scratch.strata[f] += d * d * 0.5;
        }
      }
    }
  }
  else if (side == 2)
  {
    for (std::uint32_t c = 0; c < 2; ++c)
    {
      const Rgb* va = v + static_cast<std::size_t>(c) * frames;
      const Rgb* vb = va + 2 * frames;
      for (std::size_t f = 0; f < frames; ++f)
      {
        const Rgb d = va[f] - vb[f];
        scratch.strata[f] += d * d;
      }
    }
  }
  const double independent = static_cast<double>(count - grid);
  const double n = static_cast<double>(count);
  for (std::size_t f = 0; f < frames; ++f)
  {
    Rgb variance = scratch.strata[f] * scale;
    if (independent > 0)
    {
      // The variance of one point from all of them (varianceOfMean is that over n).
      variance += varianceOfMean(scratch.pointSum[f], scratch.pointSquares[f], n) *
        (n >= 2 ? n * independent : independent);
    }
    scratch.variance[f] += variance;
  }
}

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

/**
 * What a group of sensors' hemisphere rays found, the same for every frame: the element sides
 * they reach, as slots of a table of the solution's radiosity, and the sky cells of those that
 * escape, as keys sky x Sky::Cells + cell, each distinct key with its rays.
 */
struct Hemispheres
{
  SensorReach reach;
  std::vector<std::size_t> cellBegin{ 0 };
  std::vector<std::uint32_t> cellKey, cellCount;
};

/// Calls `f(value, count)` for each run of equal values of a sorted vector, in order.
template <typename F>
void forEachRun(const std::vector<std::size_t>& sorted, const F& f)
{
  for (std::size_t i = 0; i < sorted.size();)
  {
    std::size_t end = i;
    while (end < sorted.size() && sorted[end] == sorted[i])
    {
      ++end;
    }
    f(sorted[i], end - i);
    i = end;
  }
}

/// The number of distinct values of a sorted vector.
std::size_t distinctCount(const std::vector<std::size_t>& sorted)
{
  std::size_t runs = 0;
  forEachRun(sorted, [&](std::size_t, std::size_t) { ++runs; });
  return runs;
}

/**
 * The irradiance of sensor `s` (the group's `g`-th) in frames `first` to `first + count`,
 * into `result`: its hemisphere's reads from `hemispheres` and `table` (that block's
 * radiosity, `block` frames a row), and its shadow rays towards every light. Every sum of a
 * frame runs in the same order whatever the block, so the bits do not depend on it.
 */
void solveSensorFrames(const RayTracer& tracer, const LightRig& rig,
  const std::vector<MovingLight>& emitters, const SensorSet& sensors, std::size_t s, std::size_t g,
  const Hemispheres& hemispheres, const std::vector<Rgb>& table, std::size_t block,
  std::size_t first, std::size_t count, const SolverOptions& options,
  const SensorOptions& sensorOptions, const SensorBatchSpread* solutionSpread,
  SensorScratch& scratch, SensorSolution& result)
{
  const std::size_t frames = result.frameCount();
  const Vec3& p = sensors.points[s];
  const Vec3& n = sensors.normals[s];
  const Vec3 origin = tracer.liftOff(p, n);
  const double offset = tracer.surfaceOffset();
  for (std::vector<Rgb>* v : { &scratch.total, &scratch.sun, &scratch.gathered, &scratch.variance,
         &scratch.gatheredSquares })
  {
    v->assign(count, Rgb());
  }

  // The hemisphere: each distinct element side or sky cell costs one pass over the frames,
  // however many rays found it, in the order of the keys.
  const SensorReach& reach = hemispheres.reach;
  for (std::size_t i = reach.keysBegin(g); i < reach.keysEnd(g); ++i)
  {
    const Rgb* row = table.data() + reach.slot(i) * block;
    const double hits = reach.hits(i);
    for (std::size_t f = 0; f < count; ++f)
    {
      const Rgb& read = row[f];
      scratch.gathered[f] += read * hits;
      scratch.gatheredSquares[f] += read * read * hits;
    }
  }
  // Per sky, its sums over the block's positions, or over its one position.
  std::vector<std::size_t>& skyBase = scratch.skyBase;
  skyBase.clear();
  std::size_t skyEntries = 0;
  for (const Sky& sky : rig.skies)
  {
    skyBase.push_back(skyEntries);
    skyEntries += sky.positions() > 1 ? count : 1;
  }
  scratch.skySum.assign(skyEntries, 0.0);
  scratch.skySquares.assign(skyEntries, 0.0);
  for (std::size_t i = hemispheres.cellBegin[g]; i < hemispheres.cellBegin[g + 1]; ++i)
  {
    const double hits = static_cast<double>(hemispheres.cellCount[i]);
    const std::size_t k = hemispheres.cellKey[i] / Sky::Cells;
    const Sky& sky = rig.skies[k];
    const double* density = sky.densities(hemispheres.cellKey[i] % Sky::Cells);
    double* sum = scratch.skySum.data() + skyBase[k];
    double* squares = scratch.skySquares.data() + skyBase[k];
    const std::size_t entries = sky.positions() > 1 ? count : 1;
    const std::size_t from = sky.positions() > 1 ? first : 0;
    for (std::size_t j = 0; j < entries; ++j)
    {
      sum[j] += density[from + j] * hits;
      squares[j] += density[from + j] * density[from + j] * hits;
    }
  }
  const double perRay = 1.0 / static_cast<double>(sensorOptions.hemisphereRays);
  // An escaped ray's value is the sum of every sky's: with several skies the square of that
  // sum is bounded by their count times the sum of their squares (Cauchy-Schwarz).
  const double skyBound = static_cast<double>(std::max<std::size_t>(rig.skies.size(), 1));
  for (std::size_t f = 0; f < count; ++f)
  {
    Rgb sum = scratch.gathered[f];
    double skySquares = 0;
    // Cosine-distributed directions: L(w) cos / pdf = pi L(w), L = density Lambda.
    for (std::size_t k = 0; k < rig.skies.size(); ++k)
    {
      const Sky& sky = rig.skies[k];
      const std::size_t entry = skyBase[k] + (sky.positions() > 1 ? f : 0);
      const double weight = M_PI * sky.integral(poseOf(sky.positions(), first + f));
      sum += Rgb(weight * scratch.skySum[entry]);
      skySquares += weight * weight * scratch.skySquares[entry];
    }
    scratch.total[f] += sum * perRay;
    scratch.variance[f] +=
      varianceOfMean(sum, scratch.gatheredSquares[f] + Rgb(skyBound * skySquares),
        static_cast<double>(sensorOptions.hemisphereRays));
  }

  // Directional lights: one shadow ray per frame.
  for (const DirectionalLight& light : rig.directionalLights)
  {
    scratch.clearRays();
    for (std::size_t f = 0; f < count; ++f)
    {
      const std::size_t k = poseOf(light.frameCount(), first + f);
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
    for (std::size_t f = 0; f < count; ++f)
    {
      const std::size_t k = poseOf(light.frameCount(), first + f);
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
  // frame (drawn again for every block), posed there, each with its shadow ray.
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
      for (std::size_t frame = 0; frame < count; ++frame)
      {
        const std::size_t k = poseOf(light.frameCount(), first + frame);
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
          scratch.addRay(end - origin,
            power * (density * cosine / (r2 * static_cast<double>(samples))), frame, q);
        }
      }
    }
    traceShadows(tracer, origin, false, scratch, scratch.total);
    scratch.perPoint.assign(static_cast<std::size_t>(samples) * count, Rgb());
    for (std::size_t r = 0; r < scratch.visible.size() && r < scratch.values.size(); ++r)
    {
      if (scratch.visible[r])
      {
        scratch.perPoint[static_cast<std::size_t>(scratch.points[r]) * count + scratch.targets[r]] =
          scratch.values[r];
      }
    }
    addAreaLightVariance(samples, count, scratch);
  }

  for (std::size_t f = 0; f < count; ++f)
  {
    const std::size_t frame = first + f;
    result.irradianceData()[s * frames + frame] = FloatRgb(scratch.total[f] + scratch.sun[f]);
    result.sunData()[s * frames + frame] = FloatRgb(scratch.sun[f]);
    // The sensor's own sampling and the solution's noise are independent (different streams):
    // their variances add.
    Rgb variance = scratch.variance[f];
    if (solutionSpread)
    {
      const Rgb e = solutionSpread->stdError(frame, s);
      variance += e * e;
    }
    result.stdErrorData()[s * frames + frame] =
      FloatRgb(Rgb(std::sqrt(variance.r), std::sqrt(variance.g), std::sqrt(variance.b)));
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
  for (const auto& [count, least, what] :
    { std::make_tuple(options.hemisphereRays, MinimumHemisphereRays, "hemisphere rays"),
      std::make_tuple(options.areaLightSamples, std::uint32_t(1), "area light samples") })
  {
    if (count < least || count > MaximumSensorRays)
    {
      throw Error(std::string("the sensors' ") + what + " per sensor are " + std::to_string(count) +
        ": give " + std::to_string(least) + " to " + std::to_string(MaximumSensorRays) +
        (count < least && least > 1 ? " (fewer give a standard error that reads 0 when they all "
                                      "miss what lights the sensor)"
                                    : ""));
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

/// The values of an area light's points over the frames that a worker keeps: samples x frames
/// when any area light (or emitter) lights the sensors.
std::size_t pointFrames(
  const LightRig& rig, bool sceneEmits, std::size_t frames, const SensorOptions& sensorOptions)
{
  return rig.areaLights.empty() && !sceneEmits
    ? 0
    : saturatingProduct(std::max<std::uint32_t>(sensorOptions.areaLightSamples, 1), frames);
}

/// The most frames one solve of an animation in chunks of `framesPerChunk` overlapping by
/// chunkOverlap(framesPerChunk, `overlap`) reads.
std::size_t framesPerSolve(std::size_t frames, std::size_t framesPerChunk, std::uint64_t overlap)
{
  if (framesPerChunk == 0 || framesPerChunk >= frames)
  {
    return frames;
  }
  return std::min(frames, framesPerChunk + 2 * chunkOverlap(framesPerChunk, overlap));
}
}

void SensorReach::reserve(std::size_t sensors, std::size_t keys)
{
  this->KeyBegin.reserve(this->KeyBegin.size() + sensors);
  this->KeySlot.reserve(this->KeySlot.size() + keys);
  this->KeyCount.reserve(this->KeyCount.size() + keys);
}

void SensorReach::addSensor(const std::vector<std::size_t>& h, std::size_t patches)
{
  if (this->RowOf.empty())
  {
    this->RowOf.assign(2 * patches, std::numeric_limits<std::uint32_t>::max());
    this->PatchSides.reserve(2 * patches);
  }
  forEachRun(h,
    [&](std::size_t key, std::size_t count)
    {
      const std::size_t element = key / 2, side = key % 2;
      const std::size_t patchSide = 2 * Scene::patchOfElement(element) + side;
      if (this->RowOf[patchSide] == std::numeric_limits<std::uint32_t>::max())
      {
        this->RowOf[patchSide] = static_cast<std::uint32_t>(this->PatchSides.size());
        this->PatchSides.push_back(static_cast<std::uint32_t>(patchSide));
      }
      this->KeySlot.push_back(static_cast<std::uint32_t>(
        this->RowOf[patchSide] * Scene::ElementsPerPatch + element % Scene::ElementsPerPatch));
      this->KeyCount.push_back(static_cast<std::uint32_t>(count));
    });
  this->KeyBegin.push_back(this->KeySlot.size());
}

std::size_t SensorReach::framesPerBlock(std::size_t frames, const SensorBudget& budget) const
{
  const std::uint64_t row = this->PatchSides.size() * Scene::ElementsPerPatch * sizeof(Rgb);
  return static_cast<std::size_t>(
    std::clamp<std::uint64_t>(budget.tableBytes / std::max<std::uint64_t>(row, 1), 1,
      std::max<std::size_t>(std::min(frames, budget.framesPerBlock), 1)));
}

void SensorReach::read(const Scene& scene, const Solution& solution, std::size_t first,
  std::size_t count, std::size_t block, int workers, const std::function<bool()>& keepGoing,
  std::vector<Rgb>& table) const
{
  constexpr std::size_t PatchSidesPerTask = 64;
  table.resize(this->PatchSides.size() * Scene::ElementsPerPatch * block);
  parallelFor((this->PatchSides.size() + PatchSidesPerTask - 1) / PatchSidesPerTask, workers,
    [&](std::size_t task, int)
    {
      const std::size_t end = std::min(this->PatchSides.size(), (task + 1) * PatchSidesPerTask);
      for (std::size_t row = task * PatchSidesPerTask; row < end; ++row)
      {
        const std::size_t patch = this->PatchSides[row] / 2;
        const auto side = static_cast<Side>(this->PatchSides[row] % 2);
        Rgb* out = table.data() + row * Scene::ElementsPerPatch * block;
        for (std::size_t f = 0; f < count; ++f)
        {
          Rgb read[Scene::ElementsPerPatch];
          gatheredRadiosities(scene, solution, first + f, patch, side, read);
          for (std::size_t k = 0; k < Scene::ElementsPerPatch; ++k)
          {
            out[k * block + f] = read[k];
          }
        }
      }
    },
    [&](std::size_t) { return !keepGoing || keepGoing(); });
}

std::uint64_t SensorReach::tableBytes(
  std::size_t patches, std::size_t frames, const SensorBudget& budget)
{
  const std::uint64_t row =
    saturatingProduct({ 2 * Scene::ElementsPerPatch * sizeof(Rgb), patches });
  // A block is as many frames as the budget holds, or one frame when one row takes more.
  return std::min<std::uint64_t>(std::max(budget.tableBytes, row),
    saturatingProduct(row, std::max<std::size_t>(std::min(frames, budget.framesPerBlock), 1)));
}

std::uint64_t SensorReach::indexBytes(std::size_t patches)
{
  return saturatingProduct(2 * sizeof(std::uint32_t), 2 * patches);
}

namespace
{
std::uint64_t hemisphereBytesPerSensor(const LightRig& rig, const SensorOptions& sensorOptions)
{
  return saturatingSum(saturatingProduct({ sizeof(std::size_t) + SensorReach::BytesPerKey,
                         sensorOptions.hemisphereRays, 1 + rig.skies.size() }),
    2 * sizeof(std::vector<std::size_t>) + 2 * sizeof(std::size_t));
}

/// The sensors of a group: as many as the budget holds, in whole tasks, at least one task.
std::size_t sensorsPerGroup(std::size_t sensors, const LightRig& rig,
  const SensorOptions& sensorOptions, const SensorBudget& budget)
{
  const std::uint64_t fit = budget.hemisphereBytes / hemisphereBytesPerSensor(rig, sensorOptions);
  return std::min<std::size_t>(
    sensors, std::max<std::uint64_t>(SensorsPerTask, fit / SensorsPerTask * SensorsPerTask));
}

/// The sums over sky positions a sensor keeps for a block of `frames`: that many for a sky that
/// moves, one for a sky that does not.
std::size_t skyEntriesOf(const LightRig& rig, std::size_t frames)
{
  std::size_t entries = 0;
  for (const Sky& sky : rig.skies)
  {
    entries += sky.positions() > 1 ? frames : 1;
  }
  return entries;
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
  // The three results (a FloatRgb each) and the unit points and normals.
  const std::uint64_t results =
    saturatingSum(saturatingProduct({ 3 * sizeof(FloatRgb), sensors, frames }),
      saturatingProduct(2 * sizeof(Vec3), sensors));
  const auto workers = static_cast<std::uint64_t>(resolveThreadCount(options.threads));
  const SensorBudget budget;
  const std::size_t mostFrames = std::min(frames, budget.framesPerBlock);
  const std::uint64_t scratch = saturatingProduct(workers,
    SensorScratch::bytes(mostFrames, skyEntriesOf(rig, mostFrames), rig.skies.size(),
      shadowBatch(rig, sceneEmits, mostFrames, sensorOptions),
      pointFrames(rig, sceneEmits, mostFrames, sensorOptions)));
  // One group's hemispheres, and the table of what they read with its index.
  const std::size_t patches = elements / Scene::ElementsPerPatch;
  const std::uint64_t hemispheres =
    saturatingSum(saturatingProduct(sensorsPerGroup(sensors, rig, sensorOptions, budget),
                    hemisphereBytesPerSensor(rig, sensorOptions)),
      saturatingSum(
        SensorReach::tableBytes(patches, frames, budget), SensorReach::indexBytes(patches)));
  // The scene's emitters as area lights: their triangles, generously per element.
  const std::uint64_t emitters = sceneEmits ? saturatingProduct(elements, 256) : 0;
  // With batches, the reads of every batch (solveAnimation), the chunks' length unknown here
  // unless set.
  const std::uint64_t spread = estimatesError(options)
    ? SensorBatchSpread::estimateMemory(sensors, frames,
        static_cast<std::size_t>(options.framesPerChunk), options.chunkOverlap, patches,
        sensorOptions, static_cast<int>(workers))
    : 0;
  return saturatingSum(
    saturatingSum(saturatingSum(results, scratch), saturatingSum(spread, hemispheres)),
    saturatingSum(RayTracer::estimateMemory(elements, points), emitters));
}

SensorBatchSpread::SensorBatchSpread(const Scene& scene, const SensorSet& given,
  const SolverOptions& options, const SensorOptions& sensorOptions, std::size_t frames,
  std::size_t framesPerChunk)
  : SceneRef(scene)
  , Workers(resolveThreadCount(options.threads))
  , Rays(sensorOptions.hemisphereRays)
  , Frames(frames)
  , FramesPerChunk(framesPerChunk)
  , ChunkOverlap(options.chunkOverlap)
{
  const SensorSet sensors = normalizedSensors(given, sensorOptions);
  this->Sensors = sensors.size();
  this->SolutionError.assign(this->Sensors * this->Frames, FloatRgb());
  if (this->Sensors == 0 || this->Frames == 0)
  {
    return;
  }
  // The rays do not depend on the solution: traced once, each sensor's element sides sorted
  // and counted as solveSensors counts them.
  std::vector<std::vector<std::size_t>> hits(this->Sensors);
  {
    const RayTracer tracer(scene);
    const std::size_t tasks = (this->Sensors + SensorsPerTask - 1) / SensorsPerTask;
    parallelFor(
      tasks, this->Workers,
      [&](std::size_t task, int)
      {
        const std::size_t end = std::min(this->Sensors, (task + 1) * SensorsPerTask);
        for (std::size_t s = task * SensorsPerTask; s < end; ++s)
        {
          const Vec3 origin = tracer.liftOff(sensors.points[s], sensors.normals[s]);
          hits[s].reserve(this->Rays);
          castHemisphere(tracer, origin, sensors.normals[s], s, options, this->Rays, hits[s],
            [](const Vec3&) {});
          std::sort(hits[s].begin(), hits[s].end());
        }
      },
      [](std::size_t) { return true; });
  }
  std::size_t keys = 0;
  for (const std::vector<std::size_t>& h : hits)
  {
    keys += distinctCount(h);
  }
  this->Reach.reserve(this->Sensors, keys);
  for (std::size_t s = 0; s < this->Sensors; ++s)
  {
    this->Reach.addSensor(hits[s], scene.patchCount());
    std::vector<std::size_t>().swap(hits[s]);
  }
}

void SensorBatchSpread::add(std::uint64_t batch, std::size_t firstFrame, const Solution& solution,
  const std::function<bool()>& keepGoing)
{
  if (this->Sensors == 0 || this->Frames == 0)
  {
    return;
  }
  if (batch == 0)
  {
    this->fold();
    this->AnySolve = true;
    this->SolveFirst = firstFrame;
    this->SolveFrames = solution.frameCount();
    this->SolveBatches = 0;
    this->Mean.assign(this->Sensors * this->SolveFrames, FloatRgb());
    this->SquaredDeviations.assign(this->Sensors * this->SolveFrames, FloatRgb());
  }
  if (!this->AnySolve || solution.frameCount() != this->SolveFrames ||
    this->SolveFirst + this->SolveFrames > this->Frames)
  {
    throw Error("internal error: the sensors' batch spread got a batch of another solve");
  }
  ++this->SolveBatches;
  const double inverse = 1.0 / static_cast<double>(this->SolveBatches);
  const double perRay = 1.0 / static_cast<double>(this->Rays);
  const std::size_t block = this->Reach.framesPerBlock(this->SolveFrames, SensorBudget());
  std::vector<Rgb> table;
  std::vector<std::vector<Rgb>> sums(
    static_cast<std::size_t>(this->Workers), std::vector<Rgb>(block));
  for (std::size_t first = 0; first < this->SolveFrames; first += block)
  {
    const std::size_t count = std::min(block, this->SolveFrames - first);
    this->Reach.read(
      this->SceneRef, solution, first, count, block, this->Workers, keepGoing, table);
    parallelFor((this->Sensors + SensorsPerTask - 1) / SensorsPerTask, this->Workers,
      [&](std::size_t task, int worker)
      {
        std::vector<Rgb>& sum = sums[static_cast<std::size_t>(worker)];
        const std::size_t end = std::min(this->Sensors, (task + 1) * SensorsPerTask);
        for (std::size_t s = task * SensorsPerTask; s < end; ++s)
        {
          std::fill(sum.begin(), sum.begin() + static_cast<std::ptrdiff_t>(count), Rgb());
          for (std::size_t i = this->Reach.keysBegin(s); i < this->Reach.keysEnd(s); ++i)
          {
            const Rgb* row = table.data() + this->Reach.slot(i) * block;
            const double hits = this->Reach.hits(i);
            for (std::size_t f = 0; f < count; ++f)
            {
              sum[f] += row[f] * hits;
            }
          }
          // Welford's update, in batch order: the bits do not depend on the workers.
          for (std::size_t f = 0; f < count; ++f)
          {
            const std::size_t i = s * this->SolveFrames + first + f;
            const Rgb x = sum[f] * perRay;
            const Rgb before = this->Mean[i];
            const Rgb after = before + (x - before) * inverse;
            this->Mean[i] = FloatRgb(after);
            this->SquaredDeviations[i] =
              FloatRgb(Rgb(this->SquaredDeviations[i]) + (x - before) * (x - after));
          }
        }
      },
      [&](std::size_t) { return !keepGoing || keepGoing(); });
  }
}

void SensorBatchSpread::finish()
{
  this->fold();
}

void SensorBatchSpread::fold()
{
  if (!this->AnySolve)
  {
    return;
  }
  const ChunkPlan plan = planChunks(this->Frames, this->FramesPerChunk, this->ChunkOverlap);
  std::size_t chunk = 0;
  while (chunk < plan.chunks.size() && plan.chunks[chunk].solveBegin != this->SolveFirst)
  {
    ++chunk;
  }
  if (chunk == plan.chunks.size())
  {
    throw Error("internal error: the sensors' batch spread got a solve that is no chunk");
  }
  const double b = static_cast<double>(this->SolveBatches);
  const double scale = b >= 2 ? 1.0 / (b * (b - 1)) : 0.0;
  for (std::size_t s = 0; s < this->Sensors; ++s)
  {
    for (std::size_t f = 0; f < this->SolveFrames; ++f)
    {
      const std::size_t frame = this->SolveFirst + f;
      // The seams blend two chunks' estimates, which share the paths of the positions both
      // solve: taken as fully correlated, the blend's error is the blend of the errors.
      const double weight = plan.chunks.size() == 1 ? 1.0 : plan.weight(chunk, frame);
      const Rgb m2 = this->SquaredDeviations[s * this->SolveFrames + f];
      const Rgb error(std::sqrt(std::max(0.0, m2.r * scale)),
        std::sqrt(std::max(0.0, m2.g * scale)), std::sqrt(std::max(0.0, m2.b * scale)));
      FloatRgb& into = this->SolutionError[s * this->Frames + frame];
      into = FloatRgb(Rgb(into) + error * weight);
    }
  }
  this->Batches =
    this->Batches == 0 ? this->SolveBatches : std::min(this->Batches, this->SolveBatches);
  std::vector<FloatRgb>().swap(this->Mean);
  std::vector<FloatRgb>().swap(this->SquaredDeviations);
  this->AnySolve = false;
}

std::uint64_t SensorBatchSpread::estimateMemory(std::size_t sensors, std::size_t frames,
  std::size_t framesPerChunk, std::uint64_t overlap, std::size_t patches,
  const SensorOptions& sensorOptions, int workers)
{
  if (sensors == 0 || frames == 0)
  {
    return 0;
  }
  // The hits as they are traced (a size_t each) and as kept (a slot and a count).
  const std::uint64_t keys = saturatingSum(
    saturatingProduct(
      { sizeof(std::size_t) + 2 * sizeof(std::uint32_t), sensors, sensorOptions.hemisphereRays }),
    saturatingProduct(sizeof(std::size_t) + sizeof(std::vector<std::size_t>), sensors));
  const std::uint64_t running = saturatingProduct(
    { 2 * sizeof(FloatRgb), sensors, framesPerSolve(frames, framesPerChunk, overlap) });
  const std::uint64_t errors = saturatingProduct({ sizeof(FloatRgb), sensors, frames });
  const std::uint64_t table =
    SensorReach::tableBytes(patches, framesPerSolve(frames, framesPerChunk, overlap), {});
  // The patch sides' rows and their list, and every worker's sums over a block of frames.
  const std::uint64_t rows = saturatingSum(SensorReach::indexBytes(patches),
    saturatingProduct({ sizeof(Rgb), static_cast<std::size_t>(std::max(workers, 1)),
      framesPerSolve(frames, framesPerChunk, overlap) }));
  return saturatingSum(
    saturatingSum(keys, running), saturatingSum(errors, saturatingSum(table, rows)));
}

SensorSolution solveSensors(const Scene& scene, const LightRig& rig, const Solution& solution,
  const SensorSet& given, const SolverOptions& options, const SensorOptions& sensorOptions,
  const std::function<bool(double fraction)>& progress, const SensorBatchSpread* solutionSpread,
  const SensorBudget& budget)
{
  const auto started = std::chrono::steady_clock::now();
  const SensorSet sensors = normalizedSensors(given, sensorOptions);
  const std::size_t frames = solution.frameCount();
  SensorSolution result(frames, sensors.size());
  if (sensors.empty() || frames == 0)
  {
    return result;
  }
  if (solutionSpread &&
    (solutionSpread->frameCount() != frames || solutionSpread->sensorCount() != sensors.size()))
  {
    throw Error("internal error: the sensors' batch spread is of other sensors or frames");
  }
  if (solutionSpread && solutionSpread->batches() >= 2)
  {
    result.setSolutionBatches(solutionSpread->batches());
  }
  const RayTracer tracer(scene);
  const std::vector<MovingLight> emitters = sceneEmitters(scene);
  const int workers = resolveThreadCount(options.threads);
  std::vector<SensorScratch> scratch(static_cast<std::size_t>(workers));
  const std::size_t mostFrames = std::min(frames, std::max<std::size_t>(budget.framesPerBlock, 1));
  for (SensorScratch& worker : scratch)
  {
    worker.reserve(mostFrames, skyEntriesOf(rig, mostFrames), rig.skies.size(),
      shadowBatch(rig, !emitters.empty(), mostFrames, sensorOptions),
      pointFrames(rig, !emitters.empty(), mostFrames, sensorOptions));
  }
  // The sensors in groups, each traced once and then solved a block of frames at a time, in
  // which the radiosity their rays read is read once per patch side and frame.
  const std::size_t perGroup = sensorsPerGroup(sensors.size(), rig, sensorOptions, budget);
  // Progress in sensor-frames, tracing a sensor's hemisphere counting as solving its frames:
  // whole numbers, which never step back and end at 1 exactly.
  const std::uint64_t total = 2 * static_cast<std::uint64_t>(sensors.size()) * frames;
  std::uint64_t done = 0;
  const auto keepGoing = [&]
  { return !progress || progress(static_cast<double>(done) / static_cast<double>(total)); };
  for (std::size_t begin = 0; begin < sensors.size(); begin += perGroup)
  {
    const std::size_t group = std::min(perGroup, sensors.size() - begin);
    const std::size_t tasks = (group + SensorsPerTask - 1) / SensorsPerTask;
    const std::uint64_t before = 2 * static_cast<std::uint64_t>(begin) * frames;
    auto sensorsOf = [&](std::size_t tasksDone)
    { return static_cast<std::uint64_t>(std::min(group, tasksDone * SensorsPerTask)); };
    std::vector<std::vector<std::size_t>> hits(group), cells(group);
    parallelFor(
      tasks, workers,
      [&](std::size_t task, int worker)
      {
        const std::size_t end = std::min(group, (task + 1) * SensorsPerTask);
        for (std::size_t g = task * SensorsPerTask; g < end; ++g)
        {
          const std::size_t s = begin + g;
          hits[g].reserve(sensorOptions.hemisphereRays);
          cells[g].reserve(
            static_cast<std::size_t>(sensorOptions.hemisphereRays) * rig.skies.size());
          castHemisphere(tracer, tracer.liftOff(sensors.points[s], sensors.normals[s]),
            sensors.normals[s], s, options, sensorOptions.hemisphereRays, hits[g],
            [&](const Vec3& direction)
            {
              for (std::size_t k = 0; k < rig.skies.size(); ++k)
              {
                const std::size_t cell = rig.skies[k].cell(direction);
                if (cell < Sky::Cells)
                {
                  cells[g].push_back(k * Sky::Cells + cell);
                }
              }
            });
          std::sort(hits[g].begin(), hits[g].end());
          std::sort(cells[g].begin(), cells[g].end());
          scratch[static_cast<std::size_t>(worker)].gatheringRays += sensorOptions.hemisphereRays;
        }
      },
      [&](std::size_t tasksDone)
      {
        done = before + sensorsOf(tasksDone) * frames;
        return keepGoing();
      });
    Hemispheres hemispheres;
    std::size_t keys = 0, cellKeys = 0;
    for (std::size_t g = 0; g < group; ++g)
    {
      keys += distinctCount(hits[g]);
      cellKeys += distinctCount(cells[g]);
    }
    hemispheres.reach.reserve(group, keys);
    hemispheres.cellBegin.reserve(group + 1);
    hemispheres.cellKey.reserve(cellKeys);
    hemispheres.cellCount.reserve(cellKeys);
    for (std::size_t g = 0; g < group; ++g)
    {
      hemispheres.reach.addSensor(hits[g], scene.patchCount());
      forEachRun(cells[g],
        [&](std::size_t key, std::size_t count)
        {
          hemispheres.cellKey.push_back(static_cast<std::uint32_t>(key));
          hemispheres.cellCount.push_back(static_cast<std::uint32_t>(count));
        });
      hemispheres.cellBegin.push_back(hemispheres.cellKey.size());
      std::vector<std::size_t>().swap(hits[g]);
      std::vector<std::size_t>().swap(cells[g]);
    }
    const std::size_t block = hemispheres.reach.framesPerBlock(frames, budget);
    // Of this group's size: a table kept from a group before would grow to twice its own.
    std::vector<Rgb> table;
    for (std::size_t first = 0; first < frames; first += block)
    {
      const std::size_t count = std::min(block, frames - first);
      const std::uint64_t solved = before + static_cast<std::uint64_t>(group) * frames +
        static_cast<std::uint64_t>(group) * first;
      done = solved;
      hemispheres.reach.read(scene, solution, first, count, block, workers, keepGoing, table);
      parallelFor(
        tasks, workers,
        [&](std::size_t task, int worker)
        {
          const std::size_t end = std::min(group, (task + 1) * SensorsPerTask);
          for (std::size_t g = task * SensorsPerTask; g < end; ++g)
          {
            solveSensorFrames(tracer, rig, emitters, sensors, begin + g, g, hemispheres, table,
              block, first, count, options, sensorOptions, solutionSpread,
              scratch[static_cast<std::size_t>(worker)], result);
          }
        },
        [&](std::size_t tasksDone)
        {
          done = solved + sensorsOf(tasksDone) * count;
          return keepGoing();
        });
    }
  }
  for (const SensorScratch& worker : scratch)
  {
    result.statistics().shadowRays += worker.shadowRays;
    result.statistics().gatheringRays += worker.gatheringRays;
  }
  result.statistics().seconds =
    std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  return result;
}

FrameError sensorFrameError(const SensorSolution& solution, std::size_t frame)
{
  const std::size_t sensors = solution.sensorCount();
  double sum = 0;
  for (std::size_t s = 0; s < sensors; ++s)
  {
    sum += solution.irradiance(frame, s).sum();
  }
  const double threshold =
    LitFractionOfMean * sum / static_cast<double>(std::max<std::size_t>(sensors, 1));
  std::vector<double> relative;
  for (std::size_t s = 0; s < sensors; ++s)
  {
    const double e = solution.irradiance(frame, s).sum();
    if (e > threshold && e > 0)
    {
      relative.push_back(solution.irradianceStdError(frame, s).sum() / e);
    }
  }
  return relativeErrorFigures(relative);
}

DaylightMetrics daylightMetrics(const double* illuminance, const double* sunIlluminance,
  std::size_t steps, double threshold, double hoursPerStep)
{
  if (!(threshold >= 0) || !std::isfinite(threshold))
  {
    throw Error("the daylight autonomy threshold is " + formatNumber(threshold) +
      " lx: give a finite illuminance of 0 or more (300 lx is typical)");
  }
  if (!(hoursPerStep >= 0) || !std::isfinite(hoursPerStep))
  {
    throw Error("a time step lasts " + formatNumber(hoursPerStep) +
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
