// A minimal parallel loop over tasks, with progress and cancellation on the calling thread.
#pragma once

#include <cstddef>
#include <functional>

namespace mlr
{

/**
 * Runs body(task, worker) for every task in [0, taskCount) on `threads` workers; worker 0 is
 * the calling thread. Tasks are handed out dynamically, so any result that must not depend
 * on scheduling has to be keyed by task, not by worker.
 *
 * `tick(tasksDone)` is called on the calling thread between its tasks, at most every
 * `tickSeconds`, and once at the end; returning false cancels: no new task starts and
 * parallelFor throws mlr::Cancelled once the running ones end. The first exception a task
 * throws stops the loop the same way and is rethrown.
 */
void parallelFor(std::size_t taskCount, int threads,
  const std::function<void(std::size_t task, int worker)>& body,
  const std::function<bool(std::size_t tasksDone)>& tick, double tickSeconds = 0.02);

/// The number of workers for a requested count: 0 means every core.
int resolveThreadCount(int requested);

} // namespace mlr
