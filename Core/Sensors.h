// Sensors: points with normals that receive light but neither block nor reflect it (a
// work plane, measuring points on a facade), their irradiance in every frame from the lights
// and the solved scene, and the daylight metrics over a run (Documentation/Method.md,
// "Sensors").
#pragma once

#include "ErrorEstimate.h"
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
/// The fewest hemisphere rays: a standard error from fewer reads 0 too often, for a sensor
/// whose few rays all missed what lights it.
constexpr std::uint32_t MinimumHemisphereRays = 16;

/**
 * Throws mlr::Error naming the first sensor whose point is not finite or out of the
 * coordinate range, or whose normal is missing, zero or not finite, and the counts of
 * `options` outside MinimumHemisphereRays (hemisphere rays) or 1 (area light samples) to
 * MaximumSensorRays. Normals of any length but 0 are accepted and
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

/// Every sensor's irradiance (W/m^2, RGB) in every frame, the part of it that comes straight
/// from the sun (the directional lights), which DirectSunHours counts, and its standard error.
class SensorSolution
{
public:
  SensorSolution() = default;
  SensorSolution(std::size_t frames, std::size_t sensors)
    : Frames(frames)
    , Sensors(sensors)
    , Irradiance(frames * sensors)
    , Sun(frames * sensors)
    , StdError(frames * sensors)
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
  /**
   * The standard error of irradiance() (W/m^2, RGB): the sensor's own sampling (its
   * hemisphere rays and its points on area lights; point and directional lights are exact)
   * and, when solutionBatches() is 2 or more, the noise of the solution its hemisphere rays
   * read, from the spread of those reads over the solve's batches (SensorBatchSpread).
   */
  Rgb irradianceStdError(std::size_t frame, std::size_t sensor) const
  {
    return this->StdError.empty() ? Rgb() : Rgb(this->StdError[sensor * this->Frames + frame]);
  }
  /// The batches whose spread gave the solution's part of irradianceStdError() (the fewest of
  /// any chunk's); 0 when it has none, the solve having run without batches: the standard
  /// error is then the sensors' own sampling alone.
  std::uint64_t solutionBatches() const { return this->SolutionBatches; }
  void setSolutionBatches(std::uint64_t batches) { this->SolutionBatches = batches; }
  /// Sensor-major with frames innermost, as Solution.
  std::vector<FloatRgb>& irradianceData() { return this->Irradiance; }
  std::vector<FloatRgb>& sunData() { return this->Sun; }
  std::vector<FloatRgb>& stdErrorData() { return this->StdError; }
  const SensorStatistics& statistics() const { return this->Statistics; }
  SensorStatistics& statistics() { return this->Statistics; }

private:
  std::size_t Frames = 0, Sensors = 0;
  std::vector<FloatRgb> Irradiance, Sun, StdError;
  std::uint64_t SolutionBatches = 0;
  SensorStatistics Statistics;
};

/**
 * How the sensors use memory beyond their results, which any budget leaves the same bits: what
 * their rays read is held a block of frames at a time, and their hemisphere rays a group of
 * sensors at a time.
 */
struct SensorBudget
{
  /// The radiosity the rays read, a double RGB per element of every patch side reached and
  /// frame of a block, or one frame's when that takes more.
  std::uint64_t tableBytes = std::uint64_t(16) << 20;
  /// The most frames of a block: each worker's sums and shadow rays grow with them.
  std::size_t framesPerBlock = 1024;
  /// A group's hemisphere rays: while traced, a key per ray (its element side) and per ray and
  /// sky (its cell), and kept, a slot and a count per distinct key; or those of 16 sensors
  /// when they take more.
  std::uint64_t hemisphereBytes = std::uint64_t(64) << 20;
};

/**
 * The element sides some sensors' hemisphere rays reach, and a table of their radiosity
 * (gatheredRadiosities) read a block of frames at a time. Each patch side reached is a row of
 * its four elements, read with one reconstruction of its bounced light per frame however many
 * sensors and rays reach it; each sensor then sums its distinct element sides' entries, in the
 * order of their keys (2 element + side), weighed by its rays that reached them.
 */
class SensorReach
{
public:
  /// Room for `sensors` more sensors of `keys` distinct keys in all.
  void reserve(std::size_t sensors, std::size_t keys);
  /// Adds the next sensor's hits, keys 2 element + side sorted, on a scene of `patches`.
  void addSensor(const std::vector<std::size_t>& sortedHits, std::size_t patches);
  std::size_t sensorCount() const { return this->KeyBegin.size() - 1; }
  std::size_t rowCount() const { return this->PatchSides.size(); }
  /// The frames of one block within `budget`: at least 1, at most `frames` (when above 0).
  std::size_t framesPerBlock(std::size_t frames, const SensorBudget& budget) const;
  /// Fills `table` (rowCount() x 4 elements, `block` frames each) with frames `first` to
  /// `first + count` of `solution`, on `workers` threads; `keepGoing` false cancels.
  void read(const Scene& scene, const Solution& solution, std::size_t first, std::size_t count,
    std::size_t block, int workers, const std::function<bool()>& keepGoing,
    std::vector<Rgb>& table) const;
  /// Sensor `sensor`'s keys: key i's entries in read()'s table start at slot(i) x block.
  std::size_t keysBegin(std::size_t sensor) const { return this->KeyBegin[sensor]; }
  std::size_t keysEnd(std::size_t sensor) const { return this->KeyBegin[sensor + 1]; }
  std::size_t slot(std::size_t key) const { return this->KeySlot[key]; }
  double hits(std::size_t key) const { return static_cast<double>(this->KeyCount[key]); }

  /// Bytes per key kept.
  static constexpr std::uint64_t BytesPerKey = 2 * sizeof(std::uint32_t);
  /// The most bytes of a table within `budget` for `patches` patches (both sides reached)
  /// over `frames` frames.
  static std::uint64_t tableBytes(
    std::size_t patches, std::size_t frames, const SensorBudget& budget);
  /// The bytes of the rows' index over `patches` patches.
  static std::uint64_t indexBytes(std::size_t patches);

private:
  std::vector<std::size_t> KeyBegin{ 0 };
  std::vector<std::uint32_t> KeySlot, KeyCount;
  /// The rows: the patch sides reached (2 patch + side), in the order first reached.
  std::vector<std::uint32_t> PatchSides;
  /// Per patch side, its row or none.
  std::vector<std::uint32_t> RowOf;
};

/**
 * The solution's noise as the sensors read it. A sensor's hemisphere rays read the patch
 * solution (gatheredRadiosity()), whose error is correlated from element to element (the
 * elements of a patch share its bounced light, neighbours its gradient, walks cross many
 * patches), so the elements' standard errors do not give the error of the sensor's mean of
 * them. Instead, every batch of a batched solve (SolverOptions::batchSolved) is read through
 * the same rays solveSensors casts, and the spread of those reads over the batches is the
 * standard error of the read of their mean, as for the elements (Documentation/Method.md,
 * "Sensors and daylight metrics"). The rays are traced once, when it is made; each batch
 * costs one reconstruction of the patch sides the rays reach per frame and one sum per
 * sensor, distinct element side hit and frame.
 */
class SensorBatchSpread
{
public:
  /// For `sensors` (checked) on `scene`, read with the streams of `options.seed` and
  /// `sensorOptions`, over an animation of `frames` frames solved in chunks of
  /// `framesPerChunk` (0: one solve) overlapping by options.chunkOverlap, whose seams blend
  /// the chunks' errors.
  SensorBatchSpread(const Scene& scene, const SensorSet& sensors, const SolverOptions& options,
    const SensorOptions& sensorOptions, std::size_t frames, std::size_t framesPerChunk);

  /// Reads batch `batch` of the solve whose frame 0 is the animation's `firstFrame` (the
  /// arguments of SolverOptions::batchSolved). Batch 0 starts a new solve (a chunk).
  /// `keepGoing` is asked between tasks: false stops it with mlr::Cancelled (a year of
  /// frames over a thousand sensors reads for seconds).
  void add(std::uint64_t batch, std::size_t firstFrame, const Solution& solution,
    const std::function<bool()>& keepGoing = {});
  /// Ends the last solve: stdError() is then complete.
  void finish();

  std::size_t frameCount() const { return this->Frames; }
  std::size_t sensorCount() const { return this->Sensors; }
  /// The fewest batches of any solve read (0 before finish() or without two batches).
  std::uint64_t batches() const { return this->Batches; }
  /// The standard error (W/m^2, RGB) of what sensor `sensor`'s hemisphere rays read in
  /// `frame` from the batches' mean; at a chunk seam the blend of the two chunks' with their
  /// weights, taken as fully correlated.
  Rgb stdError(std::size_t frame, std::size_t sensor) const
  {
    return this->SolutionError[sensor * this->Frames + frame];
  }

  /// The bytes it holds at its peak on `workers` threads (its ray tracer, while it is made,
  /// aside): the element sides each sensor's rays reach (one per ray), the running mean and
  /// squared deviations of one solve's frames, the standard errors of every frame, a block of
  /// the reads of the patch sides the rays reach and each worker's sums over it.
  static std::uint64_t estimateMemory(std::size_t sensors, std::size_t frames,
    std::size_t framesPerChunk, std::uint64_t overlap, std::size_t patches,
    const SensorOptions& sensorOptions, int workers);

private:
  void fold();

  const Scene& SceneRef;
  int Workers = 1;
  std::uint32_t Rays = 0;
  std::size_t Frames = 0, Sensors = 0, FramesPerChunk = 0;
  std::uint64_t ChunkOverlap = 0; ///< SolverOptions::chunkOverlap
  SensorReach Reach;
  /// Of the solve being read: its first frame, frames, batches, and per sensor and frame the
  /// running mean and squared deviations of the reads.
  std::size_t SolveFirst = 0, SolveFrames = 0;
  std::uint64_t SolveBatches = 0;
  std::vector<FloatRgb> Mean, SquaredDeviations;
  std::vector<FloatRgb> SolutionError;
  std::uint64_t Batches = 0;
  bool AnySolve = false;
};

/**
 * Bytes solveSensors() allocates at its peak, at the default SensorBudget, for `sensors`
 * sensors over `frames` frames on a scene of `elements` elements on `points` points lit by
 * `rig` (and by its own emitters when `sceneEmits`): the three results per sensor and frame,
 * the unit sensors, the sensors' own ray tracer, one group's hemisphere rays, the table of
 * what they read with its index, and every worker's sums and shadow-ray batch over a block
 * of frames (the longest: an area light's samples x the block's frames) with its values per
 * sample and frame.
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
 * order, so the result does not depend on the thread count. The standard error adds to the
 * sampling variance of the sensor's own rays that of the solution, from `solutionSpread`
 * (finished, made with the same sensors, options and counts) when given. `progress` gets the
 * share done; false cancels (mlr::Cancelled).
 */
SensorSolution solveSensors(const Scene& scene, const LightRig& rig, const Solution& solution,
  const SensorSet& sensors, const SolverOptions& options, const SensorOptions& sensorOptions = {},
  const std::function<bool(double fraction)>& progress = {},
  const SensorBatchSpread* solutionSpread = nullptr, const SensorBudget& budget = {});

/**
 * The relative error of frame `frame` over its lit sensors, those whose irradiance (sum over
 * channels) is over LitFractionOfMean of the frame's mean over all sensors, as frameError()
 * has it for elements: per sensor the sum over channels of irradianceStdError() over that of
 * irradiance(); litElements counts the lit sensors.
 */
FrameError sensorFrameError(const SensorSolution& solution, std::size_t frame);

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
