// mlr-benchmark's scale cases: a long animation at the paper's scale, and a large
// scene whose memory is measured against the solver's estimate.
#pragma once

#include <cstdint>
#include <string>

namespace mlr::bench
{

struct ScaleCaseOptions
{
  int threads = 0;
  /// The solver's memory limit (SolverOptions::memoryLimitBytes); 0: half the physical
  /// memory. A limit under twice the per-worker peak makes the workers share one copy of
  /// the accumulators (MemoryPlan).
  std::uint64_t memoryLimitBytes = 0;
};

/**
 * The paper-scale room (2,832 patches) with its light moving along the diagonal over 300
 * frames, N = 600,000, k = 1, lambda = 0.25: classic against full reuse, seconds and seconds
 * per frame, and where the shadow rays go (positions skipped by a zero kernel, rays blocked)
 * with their rate beside bare Embree's. Target: full reuse at least 6x faster than classic.
 * Returns the results as a JSON object.
 */
std::string runLongAnimation(const ScaleCaseOptions& options);

/**
 * The same room cut into about 100,000 patches (400,000 elements), 120 frames, N = 4,000,000,
 * full reuse: seconds, seconds per frame, the memory estimate and the peak resident memory of
 * the solve, in bytes and bytes per element-frame. Targets: the process stays under 16 GiB,
 * and the solve's peak is within 15% of the estimate. Returns the results as JSON.
 */
std::string runLargeScene(const ScaleCaseOptions& options);

} // namespace mlr::bench
