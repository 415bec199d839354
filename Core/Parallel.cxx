#include "Parallel.h"

#include "Error.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace mlr
{

int resolveThreadCount(int requested)
{
  if (requested > 0)
  {
    return requested;
  }
  const unsigned cores = std::thread::hardware_concurrency();
  return cores > 0 ? static_cast<int>(cores) : 1;
}

void parallelFor(std::size_t taskCount, int threads,
  const std::function<void(std::size_t task, int worker)>& body,
  const std::function<bool(std::size_t tasksDone)>& tick, double tickSeconds)
{
  std::atomic<std::size_t> next{ 0 };
  std::atomic<std::size_t> done{ 0 };
  std::atomic<bool> stop{ false };
  bool cancelled = false;
  std::exception_ptr failure;
  std::mutex failureMutex;
  // The caller, out of tasks, waits for the others on this; it wakes when the last task ends
  // or the loop stops, not a tick later (a sleep cost up to tickSeconds per loop).
  std::mutex finishedMutex;
  std::condition_variable finished;
  auto notifyFinished = [&]
  {
    std::lock_guard<std::mutex> lock(finishedMutex);
    finished.notify_all();
  };

  auto work = [&](int worker, bool isCaller)
  {
    using clock = std::chrono::steady_clock;
    auto lastTick = clock::now();
    while (!stop.load(std::memory_order_relaxed))
    {
      const std::size_t task = next.fetch_add(1, std::memory_order_relaxed);
      if (task >= taskCount)
      {
        break;
      }
      try
      {
        body(task, worker);
      }
      catch (...)
      {
        {
          std::lock_guard<std::mutex> lock(failureMutex);
          if (!failure)
          {
            failure = std::current_exception();
          }
        }
        stop = true;
        notifyFinished();
        break;
      }
      if (done.fetch_add(1) + 1 == taskCount)
      {
        notifyFinished();
      }
      if (isCaller && tick)
      {
        const auto now = clock::now();
        if (std::chrono::duration<double>(now - lastTick).count() >= tickSeconds)
        {
          lastTick = now;
          if (!tick(done.load(std::memory_order_relaxed)))
          {
            cancelled = true;
            stop = true;
          }
        }
      }
    }
  };

  const int workers = std::max(1, threads);
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  for (int w = 1; w < workers; ++w)
  {
    pool.emplace_back(work, w, false);
  }
  work(0, true);
  // The caller ran out of tasks: keep reporting (and honouring cancel) while others finish.
  if (tick && !stop)
  {
    std::unique_lock<std::mutex> lock(finishedMutex);
    while (done.load() < taskCount && !stop.load())
    {
      finished.wait_for(lock, std::chrono::duration<double>(tickSeconds));
      if (done.load() < taskCount && !stop.load())
      {
        lock.unlock();
        if (!tick(done.load()))
        {
          cancelled = true;
          stop = true;
        }
        lock.lock();
      }
    }
  }
  for (std::thread& t : pool)
  {
    t.join();
  }
  if (failure)
  {
    std::rethrow_exception(failure);
  }
  if (cancelled)
  {
    throw Cancelled();
  }
  if (tick && !tick(taskCount))
  {
    throw Cancelled();
  }
}

} // namespace mlr
