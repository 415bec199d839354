// mlr-benchmark's annual case: a year of hourly sun and Perez sky from a weather file over the
// town block, with a work plane of sensors, full reuse end to end against classic sampled on
// a few frames.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

namespace mlr::bench
{

struct AnnualCaseOptions
{
  std::uint64_t paths = 600000; ///< N, effective paths per frame
  int threads = 0;
  /// The reference of the sampled frames is classic with this many times N paths per frame.
  int referenceFactor = 16;
  std::string cacheDirectory = "output/benchmark-cache";
  std::string weather; ///< an EPW file; empty: Data/paris_synthetic.epw of the source tree
  std::string dates;   ///< "MM-DD,MM-DD", both included; empty: the whole year
  std::size_t classicFrames = 48; ///< K: classic is timed on K evenly spread frames
  double sensorSpacing = 1.55;    ///< metres between the work plane's sensors
};

/**
 * The town block of scenes::townBlock() (3,176 patches) under every daylit hour of the weather
 * file (its sun from libnova at the file's place, its direct normal irradiance and a Perez sky
 * from its diffuse horizontal irradiance), with a work plane of sensors 0.8 m above the free
 * ground. Prints the whole run's time with full reuse, stage by stage (reading, the sky's
 * tables, solving, sensors, metrics); classic (each frame alone) on K evenly spread frames,
 * extrapolated to the year, and the ratio; the per-frame MSE of full reuse and classic at equal
 * N on those frames against a classic reference; the memory estimate against the measured peak
 * resident set; and the rays a Radiance 5-phase run would cast for the same sensors (by
 * reasoning, Documentation/Performance.md). Returns the figures as JSON.
 */
std::string runAnnual(const AnnualCaseOptions& options);

} // namespace mlr::bench
