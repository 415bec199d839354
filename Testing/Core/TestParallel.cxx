// parallelFor: every task exactly once on any number of workers, progress on the calling
// thread, the first exception rethrown, cancellation, and results keyed by task that do not
// depend on the worker count.
#include "Error.h"
#include "FixedPointAccumulator.h"
#include "Parallel.h"
#include "Random.h"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <string>
#include <thread>
#include <vector>

using namespace mlr;

namespace
{
struct TaskFailed : std::runtime_error
{
  explicit TaskFailed(std::size_t task)
    : std::runtime_error("task " + std::to_string(task))
    , Task(task)
  {
  }
  std::size_t Task;
};
}

TEST(ParallelFor, VisitsEveryTaskExactlyOnce)
{
  for (int threads : { 1, 2, 3, 4, 7, 16 })
  {
    for (std::size_t tasks : { 0, 1, 5, 1000, 20000 })
    {
      std::vector<std::atomic<int>> visits(tasks);
      std::atomic<int> badWorker{ 0 };
      parallelFor(tasks, threads,
        [&](std::size_t task, int worker)
        {
          visits[task].fetch_add(1);
          badWorker += worker < 0 || worker >= threads ? 1 : 0;
        },
        {});
      for (std::size_t t = 0; t < tasks; ++t)
      {
        ASSERT_EQ(visits[t].load(), 1)
          << "task " << t << " of " << tasks << ", " << threads << " threads";
      }
      EXPECT_EQ(badWorker.load(), 0);
    }
  }
}

TEST(ParallelFor, WorkerZeroIsTheCallerAndTicksStayOnIt)
{
  const std::thread::id caller = std::this_thread::get_id();
  std::atomic<int> wrongThread{ 0 };
  std::vector<std::size_t> ticks;
  const std::size_t tasks = 2000;
  parallelFor(
    tasks, 4,
    [&](std::size_t, int worker)
    {
      if ((worker == 0) != (std::this_thread::get_id() == caller))
      {
        ++wrongThread;
      }
      std::this_thread::sleep_for(std::chrono::microseconds(20));
    },
    [&](std::size_t done)
    {
      wrongThread += std::this_thread::get_id() == caller ? 0 : 1;
      ticks.push_back(done);
      return true;
    },
    0.0);
  EXPECT_EQ(wrongThread.load(), 0);
  // Ticks count tasks done, never backwards, and the last one reports all of them.
  ASSERT_FALSE(ticks.empty());
  for (std::size_t i = 1; i < ticks.size(); ++i)
  {
    EXPECT_LE(ticks[i - 1], ticks[i]);
  }
  EXPECT_EQ(ticks.back(), tasks);
  EXPECT_LE(ticks.back(), tasks);
}

TEST(ParallelFor, RethrowsTheExceptionATaskThrows)
{
  for (int threads : { 1, 2, 4 })
  {
    std::atomic<int> ran{ 0 };
    try
    {
      parallelFor(
        1000, threads,
        [&](std::size_t task, int)
        {
          ++ran;
          if (task == 37)
          {
            throw TaskFailed(task);
          }
        },
        [](std::size_t) { return true; });
      ADD_FAILURE() << "no exception, " << threads << " threads";
    }
    catch (const TaskFailed& e)
    {
      // The type and content of the task's exception, not a Cancelled or a copy as
      // std::exception.
      EXPECT_EQ(e.Task, 37u);
    }
    EXPECT_GE(ran.load(), 1) << threads;
  }
  // One worker: tasks run in order and none starts after the failure.
  std::atomic<int> ran{ 0 };
  EXPECT_THROW(parallelFor(1000, 1,
                 [&](std::size_t task, int)
                 {
                   ++ran;
                   if (task == 37)
                   {
                     throw TaskFailed(task);
                   }
                 },
                 {}),
    TaskFailed);
  EXPECT_EQ(ran.load(), 38);
  // When every task throws, one exception comes out (the first one, on one worker).
  try
  {
    parallelFor(100, 1, [](std::size_t task, int) { throw TaskFailed(task); }, {});
    ADD_FAILURE() << "no exception";
  }
  catch (const TaskFailed& e)
  {
    EXPECT_EQ(e.Task, 0u);
  }
  // A failure wins over a cancel that the progress asks for at the same time.
  EXPECT_THROW(parallelFor(
                 10, 1,
                 [](std::size_t task, int)
                 {
                   if (task == 3)
                     throw TaskFailed(task);
                 },
                 [](std::size_t) { return false; }, 1e9),
    TaskFailed);
}

TEST(ParallelFor, CancelStopsStartingTasks)
{
  // One worker, a tick after every task: the first tick that says stop is the last task.
  std::atomic<int> ran{ 0 };
  int tickCalls = 0;
  EXPECT_THROW(parallelFor(
                 1000, 1, [&](std::size_t, int) { ++ran; },
                 [&](std::size_t done)
                 {
                   ++tickCalls;
                   return done < 10;
                 },
                 0.0),
    Cancelled);
  EXPECT_EQ(ran.load(), 10);
  EXPECT_EQ(tickCalls, 10);

  // Several workers: the others finish the task they are in and start no more. Tasks take
  // a millisecond, so running all 100,000 would take minutes; stopping takes one task each.
  for (int threads : { 2, 4 })
  {
    std::atomic<int> started{ 0 };
    EXPECT_THROW(parallelFor(
                   100000, threads,
                   [&](std::size_t, int)
                   {
                     ++started;
                     std::this_thread::sleep_for(std::chrono::milliseconds(1));
                   },
                   [](std::size_t done) { return done < 20; }, 0.0),
      Cancelled);
    EXPECT_GE(started.load(), 20) << threads;
    EXPECT_LT(started.load(), 5000) << threads;
  }
}

TEST(ParallelFor, TheFinalTickCanCancelToo)
{
  // All tasks ran, but a "no" from the tick that reports the end still cancels: a caller's
  // last chance to say stop is not lost.
  std::atomic<int> ran{ 0 };
  EXPECT_THROW(
    parallelFor(
      50, 3, [&](std::size_t, int) { ++ran; }, [](std::size_t done) { return done < 50; }, 1e9),
    Cancelled);
  EXPECT_EQ(ran.load(), 50);
  // Without a tick nothing can cancel.
  EXPECT_NO_THROW(parallelFor(50, 3, [](std::size_t, int) {}, {}));
}

TEST(ParallelFor, ResultsKeyedByTaskDoNotDependOnTheWorkers)
{
  // What the solver does: each task draws from its own stream and adds to the fixed-point
  // sums of the worker that runs it. Every worker count gives the same bits.
  const std::size_t tasks = 5000, records = 13;
  auto run = [&](int threads, bool copyPerWorker)
  {
    FixedPointAccumulator<1> sums(
      threads, copyPerWorker, records, 1, 1e-9, FrameLayout::FramesInner);
    std::vector<double> perTask(tasks);
    parallelFor(
      tasks, threads,
      [&](std::size_t task, int worker)
      {
        RandomStream random(77, StreamPurpose::Shooting, task);
        double drawn = 0;
        for (int k = 0; k < 10; ++k)
        {
          const double value = random.uniform();
          const auto record = static_cast<std::size_t>(random.uniform() * records);
          sums.add(sums.slots(worker, record, 0), 0, &value);
          drawn += value;
        }
        perTask[task] = drawn;
      },
      [](std::size_t) { return true; });
    std::vector<double> out = perTask;
    for (std::size_t r = 0; r < records; ++r)
    {
      double t = 0;
      sums.total(r, 0, 0, &t);
      out.push_back(t);
    }
    return out;
  };
  const std::vector<double> reference = run(1, true);
  for (int threads : { 2, 3, 8 })
  {
    EXPECT_EQ(run(threads, true), reference) << threads;
    EXPECT_EQ(run(threads, false), reference) << threads << " shared";
  }
}

TEST(ParallelFor, ResolveThreadCount)
{
  EXPECT_EQ(resolveThreadCount(1), 1);
  EXPECT_EQ(resolveThreadCount(5), 5);
  const unsigned cores = std::thread::hardware_concurrency();
  EXPECT_EQ(resolveThreadCount(0), cores > 0 ? static_cast<int>(cores) : 1);
}
