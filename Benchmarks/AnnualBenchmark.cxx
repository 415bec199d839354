#include "AnnualBenchmark.h"

#include "Error.h"
#include "MemoryPlan.h"
#include "ProcessMeasures.h"
#include "RigBenchmarks.h"
#include "Sensors.h"
#include "Sky.h"
#include "Solver.h"
#include "TownScenes.h"
#include "WeatherFile.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#ifndef MLR_SOURCE_DIR
#define MLR_SOURCE_DIR "."
#endif

namespace mlr::bench
{
namespace
{
using Clock = std::chrono::steady_clock;

double secondsSince(Clock::time_point start)
{
  return std::chrono::duration<double>(Clock::now() - start).count();
}

void parseDates(const std::string& text, WeatherSelection& s)
{
  if (text.empty())
  {
    return;
  }
  if (std::sscanf(
        text.c_str(), "%d-%d,%d-%d", &s.firstMonth, &s.firstDay, &s.lastMonth, &s.lastDay) != 4)
  {
    throw Error("--dates is '" + text + "': give MM-DD,MM-DD, e.g. 06-01,08-31");
  }
}

/// The sun and the Perez sky of `frames` (a subset of the weather frames, by index).
LightRig daylightRig(const std::vector<WeatherFrame>& weather,
  const std::vector<std::size_t>& frames, const Vec3& up, int threads)
{
  std::vector<Vec3> directions;
  std::vector<Rgb> power;
  std::vector<SkyFrame> sky;
  for (std::size_t f : frames)
  {
    const WeatherFrame& w = weather[f];
    directions.push_back(w.sun.direction);
    power.push_back(Rgb(w.directNormal));
    sky.push_back(SkyFrame{ w.sun.direction, w.diffuseHorizontal, w.directNormal, w.dayOfYear });
  }
  LightRig rig;
  rig.directionalLights.emplace_back(directions, Rgb(1.0), power);
  rig.skies.emplace_back(SkyModel::Perez, up, sky, threads);
  return rig;
}

/// A work plane 0.8 m above the free ground: the lattice (i + 1/2) spacing, facing up, left
/// out under the buildings and within half a spacing of their walls.
SensorSet workPlane(const scenes::TownBlock& town, double spacing)
{
  SensorSet sensors;
  const scenes::AxisBox& g = town.ground;
  for (double y = g.lo.y + spacing / 2; y < g.hi.y; y += spacing)
  {
    for (double x = g.lo.x + spacing / 2; x < g.hi.x; x += spacing)
    {
      bool free = true;
      for (const scenes::Building& b : town.buildings)
      {
        const double margin = spacing / 2;
        free = free &&
          !(x > b.box.lo.x - margin && x < b.box.hi.x + margin && y > b.box.lo.y - margin &&
            y < b.box.hi.y + margin);
      }
      if (free)
      {
        sensors.points.push_back({ x, y, 0.8 });
        sensors.normals.push_back(town.up);
      }
    }
  }
  return sensors;
}

/// Every sensor's illuminance (lx) and its direct sun's in every frame, with the Perez
/// efficacies of the frame's sun and sky, weighted as the filter weighs them.
struct Illuminances
{
  std::vector<double> total, sun; ///< [sensor][frame]
};

Illuminances illuminances(const SensorSolution& s, const std::vector<WeatherFrame>& weather,
  const std::vector<std::size_t>& frames, const Vec3& up)
{
  const std::size_t n = frames.size();
  std::vector<double> efficacy(n), sunEfficacy(n);
  for (std::size_t f = 0; f < n; ++f)
  {
    const WeatherFrame& w = weather[frames[f]];
    const SkyFrame frame{ w.sun.direction, w.diffuseHorizontal, w.directNormal, w.dayOfYear };
    const DaylightEfficacy k = perezEfficacy(frame, up);
    const double direct = w.directNormal * std::max(0.0, dot(w.sun.direction, up));
    const double all = direct + w.diffuseHorizontal;
    efficacy[f] = all > 0 ? (k.direct * direct + k.diffuse * w.diffuseHorizontal) / all : k.diffuse;
    sunEfficacy[f] = k.direct;
  }
  Illuminances out;
  out.total.resize(s.sensorCount() * n);
  out.sun.resize(s.sensorCount() * n);
  for (std::size_t i = 0; i < s.sensorCount(); ++i)
  {
    for (std::size_t f = 0; f < n; ++f)
    {
      out.total[i * n + f] = efficacy[f] * luminance(s.irradiance(f, i));
      out.sun[i * n + f] = sunEfficacy[f] * luminance(s.sunIrradiance(f, i));
    }
  }
  return out;
}

std::string label(const WeatherFrame& w)
{
  static const char* months[] = { "Jan", "Feb", "Mar", "Apr", "May", "Jun", "Jul", "Aug", "Sep",
    "Oct", "Nov", "Dec" };
  char text[32];
  // Day of the year to month and day, in the file's calendar (no leap day needed here: only
  // for the label).
  int day = w.dayOfYear, month = 0;
  static const int lengths[] = { 31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31 };
  while (month < 11 && day > lengths[month])
  {
    day -= lengths[month++];
  }
  std::snprintf(text, sizeof text, "%s %d %02d:30", months[month], day, w.clockHour);
  return text;
}
} // namespace

std::string runAnnual(const AnnualCaseOptions& c)
{
  const Clock::time_point started = Clock::now();
  if (c.classicFrames < 1)
  {
    throw Error("--classic-frames must be at least 1");
  }
  if (!(c.sensorSpacing > 0))
  {
    throw Error("the sensor spacing must be above 0");
  }
  const scenes::TownBlock town = scenes::townBlock();
  const Scene scene = Scene::fromPatchMesh(town.mesh);
  const SensorSet sensors = workPlane(town, c.sensorSpacing);
  SolverOptions options;
  options.pathsPerFrame = c.paths;
  options.threads = c.threads;
  options.gatheringRatio = 1;
  options.firstBounceSurvival = 0.25;
  options.seed = 1;
  const SensorOptions sensorOptions;
  const std::uint64_t baseline = statusBytes("VmRSS");

  // The year, full reuse, end to end: the weather file, the sky's tables, the solve, the
  // sensors and their metrics.
  Clock::time_point t = Clock::now();
  const std::string path =
    c.weather.empty() ? std::string(MLR_SOURCE_DIR) + "/Data/paris_synthetic.epw" : c.weather;
  const WeatherFile file = readWeatherFile(path);
  WeatherSelection selection;
  selection.north = town.north;
  selection.up = town.up;
  parseDates(c.dates, selection);
  const std::vector<WeatherFrame> weather = weatherFrames(file, selection);
  const double secondsReading = secondsSince(t);
  const std::size_t frames = weather.size();
  std::vector<std::size_t> all(frames);
  for (std::size_t f = 0; f < frames; ++f)
  {
    all[f] = f;
  }
  const std::size_t k = std::min(c.classicFrames, frames);

  std::printf("\n=== A year of daylight on the town block ===\nTown block: %zu buildings, %zu "
              "patches, %zu elements; %zu work-plane sensors 0.8 m above the free ground, "
              "%.2f m apart, facing up; %zu hemisphere rays and 1 sun shadow ray per frame each\n"
              "Weather: %s (%s, %.2f N, %.2f E, UTC%+g): %zu daylit hours (%s to %s), sun from "
              "libnova at the middle of each hour, its direct normal irradiance, a Perez sky "
              "from its diffuse horizontal irradiance\nN = %llu, k = %g, lambda = %g; classic "
              "timed on %zu evenly spread frames\n",
    town.buildings.size(), scene.patchCount(), scene.elementCount(), sensors.size(),
    c.sensorSpacing, static_cast<std::size_t>(sensorOptions.hemisphereRays), path.c_str(),
    file.city.c_str(), file.latitude, file.longitude, file.timeZoneHours, frames,
    label(weather.front()).c_str(), label(weather.back()).c_str(),
    static_cast<unsigned long long>(options.pathsPerFrame), options.gatheringRatio,
    options.firstBounceSurvival, k);
  std::fflush(stdout);

  t = Clock::now();
  const LightRig year = daylightRig(weather, all, town.up, c.threads);
  const double secondsSky = secondsSince(t);
  const double skyBytes = double(year.skies.front().allocatedBytes());

  SolverOptions reuse = options;
  reuse.reuseShooting = true;
  reuse.reuseGathering = true;
  t = Clock::now();
  const Solution solution = solve(scene, year, reuse);
  const double secondsSolving = secondsSince(t);
  t = Clock::now();
  const SensorSolution yearSensors =
    solveSensors(scene, year, solution, sensors, reuse, sensorOptions);
  const double secondsSensors = secondsSince(t);
  t = Clock::now();
  const Illuminances lux = illuminances(yearSensors, weather, all, town.up);
  double autonomy = 0, udiUseful = 0, sunHours = 0;
  const double hours = hoursPerTimeStep(
    [&]
    {
      std::vector<double> times;
      for (const WeatherFrame& w : weather)
      {
        times.push_back(w.seriesHour);
      }
      return times;
    }());
  for (std::size_t i = 0; i < sensors.size(); ++i)
  {
    const DaylightMetrics m = daylightMetrics(
      lux.total.data() + i * frames, lux.sun.data() + i * frames, frames, 300, hours);
    autonomy += m.autonomy / double(sensors.size());
    udiUseful += m.udiUseful / double(sensors.size());
    sunHours += m.directSunHours / double(sensors.size());
  }
  const double secondsMetrics = secondsSince(t);
  const double secondsYear =
    secondsReading + secondsSky + secondsSolving + secondsSensors + secondsMetrics;
  const std::uint64_t peak = lifetimePeakResidentBytes();
  const SolverStatistics& ys = solution.statistics;
  const SensorStatistics& ss = yearSensors.statistics();
  // The solve's own estimate, made with what its reachability probes found; the bound it
  // checked the limit against before them is printed beside it.
  const std::uint64_t solveEstimate = ys.memoryEstimateBytes;
  const std::uint64_t solveBound = estimateSolveMemory(scene, frames, reuse, 2);
  const std::uint64_t sensorEstimate = estimateSensorMemory(sensors.size(), frames,
    scene.elementCount(), scene.points().size(), year, false, reuse, sensorOptions);
  const double estimate = double(solveEstimate) + double(sensorEstimate) + skyBytes;

  std::printf("\nFull reuse, the whole year (%zu frames), %d threads: %.1f s end to end = "
              "reading %.2f s + sky tables %.2f s + solve %.1f s (shooting %.1f, gathering %.1f) "
              "+ sensors %.1f s + metrics %.2f s; %.1f ms per frame\n",
    frames, ys.threads, secondsYear, secondsReading, secondsSky, secondsSolving, ys.secondsShooting,
    ys.secondsGathering, secondsSensors, secondsMetrics, 1000 * secondsYear / double(frames));
  std::printf("  rays: %llu nearest-hit, %llu shadow, %llu gathering (solve); sensors %llu "
              "shadow, %llu gathering\n",
    static_cast<unsigned long long>(ys.shootingRays),
    static_cast<unsigned long long>(ys.shadowRays),
    static_cast<unsigned long long>(ys.gatheringRays + ys.reachabilityRays),
    static_cast<unsigned long long>(ss.shadowRays),
    static_cast<unsigned long long>(ss.gatheringRays));
  std::printf("  work plane over the year: mean daylight autonomy (300 lx) %.2f, UDI 100-2000 lx "
              "%.2f, direct sun over 1000 lx %.0f h\n",
    autonomy, udiUseful, sunHours);
  std::printf("  memory: estimate %.2f GiB (solve %.2f, its bound before reachability %.2f; "
              "sensors %.3f, sky tables %.3f) against "
              "a measured peak resident set of %.2f GiB (%.2f GiB above the %.0f MiB resident "
              "before the year): peak / estimate %.2f\n",
    estimate / 1073741824.0, double(solveEstimate) / 1073741824.0,
    double(solveBound) / 1073741824.0, double(sensorEstimate) / 1073741824.0,
    skyBytes / 1073741824.0, double(peak) / 1073741824.0, double(peak - baseline) / 1073741824.0,
    double(baseline) / 1048576.0, double(peak) / estimate);
  std::fflush(stdout);

  // Classic: each of K evenly spread frames solved alone, with the same sensors.
  std::vector<std::size_t> sample;
  for (std::size_t i = 0; i < k; ++i)
  {
    sample.push_back(static_cast<std::size_t>((double(i) + 0.5) * double(frames) / double(k)));
  }
  const LightRig sampled = daylightRig(weather, sample, town.up, c.threads);
  SolverOptions classic = options;
  classic.reuseShooting = false;
  classic.reuseGathering = false;
  t = Clock::now();
  const Solution classicSolution = solve(scene, sampled, classic);
  const double classicSolving = secondsSince(t);
  t = Clock::now();
  const SensorSolution classicSensors =
    solveSensors(scene, sampled, classicSolution, sensors, classic, sensorOptions);
  const double classicSensorSeconds = secondsSince(t);
  const double perFrame = (classicSolving + classicSensorSeconds) / double(k);
  const double classicYear =
    secondsReading + secondsSky + perFrame * double(frames) + secondsMetrics;
  const SolverStatistics& cs = classicSolution.statistics;
  std::printf("\nClassic, %zu evenly spread frames solved alone: solve %.1f s + sensors %.2f s "
              "= %.0f ms per frame; extrapolated to the year with the same reading, sky tables "
              "and metrics: %.0f s (%.1f min)\n",
    k, classicSolving, classicSensorSeconds, 1000 * perFrame, classicYear, classicYear / 60);
  std::printf("  rays on the %zu frames: %llu nearest-hit, %llu shadow, %llu gathering; x %.1f "
              "for the year\n",
    k, static_cast<unsigned long long>(cs.shootingRays),
    static_cast<unsigned long long>(cs.shadowRays),
    static_cast<unsigned long long>(cs.gatheringRays + cs.reachabilityRays),
    double(frames) / double(k));
  const double speedup = classicYear / secondsYear;
  std::printf("Full reuse is %.1fx faster than classic over the year (%.1f s against %.0f s, "
              "classic extrapolated from %zu frames)\n",
    speedup, secondsYear, classicYear, k);
  std::fflush(stdout);

  // The error at equal N on the sampled frames: the year's reuse frames and classic's against
  // classic with referenceFactor x N.
  RigCaseOptions referenceOptions;
  referenceOptions.paths = c.paths;
  referenceOptions.threads = c.threads;
  referenceOptions.referenceFactor = c.referenceFactor;
  referenceOptions.cacheDirectory = c.cacheDirectory;
  std::vector<std::size_t> own(k);
  for (std::size_t i = 0; i < k; ++i)
  {
    own[i] = i;
  }
  const ReferenceErrors errors =
    referenceErrors("annual-" + std::to_string(frames), town.mesh, scene, sampled, options,
      referenceOptions, { { &classicSolution, own }, { &solution, sample } });
  const std::vector<double>& classicMse = errors.mse[0];
  const std::vector<double>& reuseMse = errors.mse[1];
  double meanRatio = 0, meanClassic = 0, meanReuse = 0;
  std::size_t worst = 0, best = 0;
  std::printf("\nMSE (W/m^2)^2 per sampled frame: frame, reference mean B, classic, full reuse, "
              "ratio\n");
  for (std::size_t i = 0; i < k; ++i)
  {
    const double ratio = reuseMse[i] / classicMse[i];
    meanRatio += ratio / double(k);
    meanClassic += classicMse[i] / double(k);
    meanReuse += reuseMse[i] / double(k);
    worst = ratio > reuseMse[worst] / classicMse[worst] ? i : worst;
    best = ratio < reuseMse[best] / classicMse[best] ? i : best;
    std::printf("  %-14s %8.1f %10.4g %10.4g %6.2f\n", label(weather[sample[i]]).c_str(),
      errors.referenceMeanRadiosity[i], classicMse[i], reuseMse[i], ratio);
  }
  std::printf("MSE of full reuse / classic at equal N over the %zu frames: mean of the ratios "
              "%.2f, worst %.2f (%s), best %.2f (%s); ratio of the mean MSEs %.2f. Time x MSE "
              "gain of full reuse: %.1fx (with the mean MSEs)\n",
    k, meanRatio, reuseMse[worst] / classicMse[worst], label(weather[sample[worst]]).c_str(),
    reuseMse[best] / classicMse[best], label(weather[sample[best]]).c_str(),
    meanReuse / meanClassic, speedup * meanClassic / meanReuse);
  std::printf("MSE against classic at %dx N (seed 12345), area-weighted over the lit sides; it "
              "includes the reference's own error, about 1/%d of classic's.\n",
    c.referenceFactor, c.referenceFactor);

  // Radiance's 5-phase method for the same sensors, by reasoning (Documentation/Performance.md):
  // daylight coefficients for the sky (MF:4 Reinhart, 2,305 patches) at -ab 5 -ad 10000, the
  // same at -ab 1 for the direct sky part it replaces, and a sun coefficient matrix of 5,165
  // suns (MF:6) at -ab 0; rcontrib caches no ambient values, and past the first bounce each
  // ambient ray carries on as one path (-lw 1e-4), so a sensor casts about -ad x -ab rays.
  const double ad = 10000, ab = 5, suns = 5165;
  const double radianceRays = double(sensors.size()) * (ad * ab + ad * 1 + suns);
  std::printf("\nRadiance 5-phase for the same %zu sensors, by reasoning: %.2g rays (%.0f per "
              "sensor: -ad %.0f x -ab %.0f for the sky's coefficients, %.0f for their direct "
              "part, %.0f suns), for the sensors only; the year then costs matrix products, no "
              "rays. This run: %.3g rays for the sensors and %.3g for every element of the scene "
              "in every frame.\n",
    sensors.size(), radianceRays, radianceRays / double(sensors.size()), ad, ab, ad, suns,
    double(ss.shadowRays + ss.gatheringRays),
    double(ys.shootingRays + ys.shadowRays + ys.gatheringRays + ys.reachabilityRays));
  std::printf("Whole benchmark: %.0f s\n", secondsSince(started));

  std::ostringstream json;
  json << "{\n    \"patches\": " << scene.patchCount() << ", \"elements\": " << scene.elementCount()
       << ", \"sensors\": " << sensors.size() << ", \"frames\": " << frames
       << ", \"classic_frames\": " << k << ",\n    \"paths_per_frame\": " << options.pathsPerFrame
       << ", \"threads\": " << ys.threads << ",\n    \"seconds_year_reuse\": " << secondsYear
       << ", \"seconds_reading\": " << secondsReading << ", \"seconds_sky_tables\": " << secondsSky
       << ", \"seconds_solving\": " << secondsSolving << ", \"seconds_sensors\": " << secondsSensors
       << ", \"seconds_metrics\": " << secondsMetrics
       << ",\n    \"seconds_year_classic_extrapolated\": " << classicYear
       << ", \"speedup\": " << speedup << ",\n    \"mse_ratio_mean\": " << meanRatio
       << ", \"mse_ratio_worst\": " << reuseMse[worst] / classicMse[worst]
       << ", \"mse_mean_classic\": " << meanClassic << ", \"mse_mean_reuse\": " << meanReuse
       << ",\n    \"memory_estimate_bytes\": " << estimate << ", \"peak_resident_bytes\": " << peak
       << ",\n    \"sensor_shadow_rays\": " << ss.shadowRays
       << ", \"sensor_gathering_rays\": " << ss.gatheringRays
       << ", \"radiance_5phase_rays_estimate\": " << radianceRays << "\n  }";
  return json.str();
}

} // namespace mlr::bench
