// mlr-benchmark's remeshing case: a 1,000,000-triangle input remeshed
// to realistic patch counts, and how fast a cancellation stops it.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

namespace mlr::bench
{

struct RemeshCaseOptions
{
  /// Remeshed to each of these patch counts in turn.
  std::vector<std::size_t> patchCounts = { 10000, 100000 };
  /// Cancellations requested per patch count, evenly spaced over an uncancelled run.
  int cancelPoints = 20;
  /// The scene of scenes::sphereAndBoxOnTiledFloor(): 1,004,800 triangles and 6 quads by
  /// default.
  int floorCells = 320;
  int sphereFrequency = 200;
};

/**
 * Remeshes scenes::sphereAndBoxOnTiledFloor() (a tessellated floor crossed by a fine sphere,
 * a box standing on it: contact lines, a covered face, three surfaces) to each
 * patch count. Prints the time and its phases, the longest gaps between two calls of the
 * progress callback (an upper bound, give or take the 20 ms the poll waits between calls,
 * on how late a cancellation can be seen), and then cancels runs at `cancelPoints` evenly
 * spaced times: the time from the request to mlr::Cancelled reaching the caller, max and
 * median, against the 0.5 s target. Returns the results as a JSON object.
 */
std::string runRemeshing(const RemeshCaseOptions& options);

} // namespace mlr::bench
