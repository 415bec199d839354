// mlr-benchmark's accuracy cases: every frame's error of full reuse against classic at equal
// N for the schemes that could serve the ends of an animation, the error bars against the
// spread over seeds, and a solve to a target relative error, all against classic references.
#pragma once

#include <cstdint>
#include <string>

namespace mlr::bench
{

struct AccuracyCaseOptions
{
  std::uint64_t paths = 100000; ///< N, effective paths per frame (the first round's for a target)
  /// The paper room's and the turning light's frames; 0: 30 (10 for target-error).
  std::size_t frames = 0;
  int threads = 0;
  /// Seeds per scheme (ends) or solves (error-bars); 0: the case's default (2 and 20).
  int seeds = 0;
  /// The reference has this many times N paths; 0: the case's default (classic at 32 N for
  /// ends and error-bars; full reuse at twice the paths the target took for target-error).
  int referenceFactor = 0;
  double target = 0.02; ///< target-error's TargetRelativeError
  std::string cacheDirectory = "output/benchmark-cache";
};

/**
 * The ends of an animation: the paper room (a light translating on a diagonal), the turning
 * light and the sun over the town block, each solved classic and with full reuse in several
 * schemes (balanced shares, equal shares, windows of neighbouring positions, a defensive
 * share of classic paths). Prints every frame's MSE over classic's at equal N, the worst
 * frame and the middle one, CPU seconds and time x MSE, and the first-hit variance factor
 * of share clamps wider than the solver's. Returns JSON.
 */
std::string runEnds(const AccuracyCaseOptions& options);

/**
 * Error bars: the paper room solved with 16 error batches for S seeds; per frame, the RMS
 * error against the reference over the mean reported standard error, and the share of lit
 * values whose 1-sigma interval covers the reference. Returns JSON.
 */
std::string runErrorBars(const AccuracyCaseOptions& options);

/**
 * The paper room solved to a target relative error: the paths it took, the time, what
 * stopped it, and its 95th percentile against a reference of twice the paths with its own
 * standard errors. Returns JSON.
 */
std::string runTargetError(const AccuracyCaseOptions& options);

} // namespace mlr::bench
