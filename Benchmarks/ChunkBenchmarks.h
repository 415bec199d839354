// mlr-benchmark --case long, in chunks: flat memory over the frame count, the speed of
// chunked full reuse against classic, and the flicker at the seams against inside a chunk.
#pragma once

#include "ScaleBenchmarks.h"

#include <string>

namespace mlr::bench
{

/**
 * The paper-scale room over 300, 1,000 and 3,000 frames in chunks of 100, streamed (frames
 * dropped as they come): seconds and peak resident memory of each. Classic's seconds per
 * frame, timed over 100 frames (each frame is solved alone, so its cost per frame does not
 * depend on the frame count), against the chunks over 3,000. Flicker, the RMS over elements
 * of the frame-to-frame change's error, from two seeds (the difference of two independent
 * estimates has twice the variance of one): at the seams and inside the chunks of 300 frames
 * in chunks of 30. Targets: flat memory, 15x faster than classic, seams within 1.1x of
 * inside. Returns the results as JSON.
 */
std::string runChunkedAnimation(const ScaleCaseOptions& options);

/**
 * The large scene (the paper room in about 100,000 patches) over 3,000 frames, N = 4,000,000,
 * full reuse, streamed in the chunks that a 7 GiB memory limit chooses (or that of
 * --memory-limit-mib): the chunk length, seconds, peak resident memory against the estimate.
 * Target: the process within 8 GB (10^9 bytes). Returns the results as JSON.
 */
std::string runLargeChunked(const ScaleCaseOptions& options);

} // namespace mlr::bench
