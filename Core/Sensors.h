// Sensors: points with normals that receive light but neither block nor reflect it (a
// work plane, measuring points on a facade), their irradiance in every frame from the lights
// and the solved scene, and the daylight metrics over a run (Documentation/Method.md,
// "Sensors").
#pragma once

#include "LightSource.h"
#include "Rgb.h"
#include "Scene.h"
#include "Solution.h"
#include "SolverOptions.h"
#include "Vec3.h"

#include <cstddef>
#include <cstdint>
#include <functional>
#include <vector>

namespace mlr
{

/// Measuring points: each with the unit normal of the side it receives on.
struct SensorSet
{
  std::vector<Vec3> points;
  std::vector<Vec3> normals;

  std::size_t size() const { return this->points.size(); }
  bool empty() const { return this->points.empty(); }
};

/// How many rays each sensor casts.
struct SensorOptions
{
  /// Cosine-distributed rays over the hemisphere, one set reused for every frame: those that
  /// escape see the sky, those that hit a surface gather its radiosity.
  std::uint32_t hemisphereRays = 512;
  /// Points sampled on every area light (scene emitters included), in every frame.
  std::uint32_t areaLightSamples = 64;
};

/// The most sensors and rays per sensor accepted: beyond them a run would not finish.
constexpr std::uint64_t MaximumSensors = 100000000;
constexpr std::uint32_t MaximumSensorRays = 1000000;

/**
 * Throws mlr::Error naming the first sensor whose point is not finite or out of the
 * coordinate range, or whose normal is missing, zero or not finite, and the counts of
 * `options` outside 1 to MaximumSensorRays. Normals of any length but 0 are accepted and
 * normalised by normalizedSensors().
 */
void checkSensors(const SensorSet& sensors, const SensorOptions& options = {});

/// The sensors with unit normals, after checkSensors().
SensorSet normalizedSensors(const SensorSet& sensors, const SensorOptions& options = {});

/// The rays the sensors cast, counted exactly, and the time they took.
struct SensorStatistics
{
  /// Towards the directional, point and area lights (scene emitters included): one per
  /// frame and light (per sample and frame for area lights) wherever the light can reach the
  /// sensor's side, none where it cannot (behind the sensor, outside the light's beam, off).
  std::uint64_t shadowRays = 0;
  /// The hemisphere rays: sensors x SensorOptions::hemisphereRays, for all frames.
  std::uint64_t gatheringRays = 0;
  double seconds = 0;
};

/// Every sensor's irradiance (W/m^2, RGB) in every frame, and the part of it that comes
/// straight from the sun (the directional lights), which DirectSunHours counts.
class SensorSolution
{
public:
  SensorSolution() = default;
  SensorSolution(std::size_t frames, std::size_t sensors)
    : Frames(frames)
    , Sensors(sensors)
    , Irradiance(frames * sensors)
    , Sun(frames * sensors)
  {
  }

  std::size_t frameCount() const { return this->Frames; }
  std::size_t sensorCount() const { return this->Sensors; }
  /// All the light on the sensor: direct from every light, the sky, and the scene's.
  Rgb irradiance(std::size_t frame, std::size_t sensor) const
  {
    return this->Irradiance[sensor * this->Frames + frame];
  }
  /// Of irradiance(), what comes straight from directional lights.
  Rgb sunIrradiance(std::size_t frame, std::size_t sensor) const
  {
    return this->Sun[sensor * this->Frames + frame];
  }
  /// Sensor-major with frames innermost, as Solution.
  std::vector<FloatRgb>& irradianceData() { return this->Irradiance; }
  std::vector<FloatRgb>& sunData() { return this->Sun; }
  const SensorStatistics& statistics() const { return this->Statistics; }
  SensorStatistics& statistics() { return this->Statistics; }

private:
  std::size_t Frames = 0, Sensors = 0;
  std::vector<FloatRgb> Irradiance, Sun;
  SensorStatistics Statistics;
};

/**
 * Bytes solveSensors() allocates at its peak for `sensors` sensors over `frames` frames on a
 * scene of `elements` elements on `points` points lit by `rig` (and by its own emitters when
 * `sceneEmits`): the two results per sensor and frame, the unit sensors, the sensors' own ray
 * tracer, and every worker's per-frame sums and shadow-ray batch (the longest: an area
 * light's samples x frames).
 */
std::uint64_t estimateSensorMemory(std::size_t sensors, std::size_t frames, std::size_t elements,
  std::size_t points, const LightRig& rig, bool sceneEmits, const SolverOptions& options,
  const SensorOptions& sensorOptions);

/**
 * The irradiance of every sensor in every frame of `solution` (solved on `scene` lit by
 * `rig`): next-event estimation of every area light (its scene emitters too) and point light
 * with shadow rays per frame, one shadow ray per frame towards each directional light, and
 * one set of cosine-distributed hemisphere rays per sensor for all frames, whose escaping
 * rays weigh the skies' radiance and whose hits the patch radiosity of the surface hit.
 * Streams are keyed by options.seed and the sensor, and each sensor's sums run in a fixed
 * order, so the result does not depend on the thread count. `progress` gets the share done;
 * false cancels (mlr::Cancelled).
 */
SensorSolution solveSensors(const Scene& scene, const LightRig& rig, const Solution& solution,
  const SensorSet& sensors, const SolverOptions& options, const SensorOptions& sensorOptions = {},
  const std::function<bool(double fraction)>& progress = {});

/// Daylight metrics of one sensor over a run's time steps.
struct DaylightMetrics
{
  double autonomy = 0;       ///< share of time steps with at least the threshold
  double udiLow = 0;         ///< share below 100 lx
  double udiUseful = 0;      ///< share from 100 to 2000 lx
  double udiHigh = 0;        ///< share above 2000 lx
  double directSunHours = 0; ///< hours whose direct sun alone is over 1000 lx
};

/// Lux bounds of the metrics.
constexpr double UdiLowBound = 100, UdiHighBound = 2000, DirectSunBound = 1000;

/**
 * The metrics of `steps` illuminances (lx) and their direct-sun parts, each step lasting
 * `hoursPerStep` hours. Throws mlr::Error for a threshold or hours below 0 or not finite.
 */
DaylightMetrics daylightMetrics(const double* illuminance, const double* sunIlluminance,
  std::size_t steps, double threshold, double hoursPerStep);

/**
 * The hours one time step lasts, from the steps' times in hours: the median of the positive
 * spacings (the frames of a weather file may skip the nights), 1 for a single step.
 */
double hoursPerTimeStep(const std::vector<double>& times);

} // namespace mlr
