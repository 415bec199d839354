// Private to Core: polling a progress callback for cancellation from inside long loops and
// library calls, cheaply enough to do at every step.
#pragma once

#include "Error.h"

#include <chrono>
#include <cstdint>
#include <functional>
#include <utility>

namespace mlr::detail
{

/**
 * Asks `keepGoing` (a caller's progress callback, usually) whether to go on, at most every
 * 20 ms, and throws mlr::Cancelled when it says no. tick() is cheap enough for every
 * iteration of an inner loop, or every comparison of a sort: it looks at the clock every
 * 1024 calls only.
 */
class CancellationPoll
{
public:
  using Clock = std::chrono::steady_clock;

  explicit CancellationPoll(std::function<bool()> keepGoing)
    : KeepGoing(std::move(keepGoing))
    , Last(Clock::now())
  {
  }

  void tick()
  {
    if ((++this->Count & 1023) == 0)
    {
      this->check();
    }
  }

  /// Asks the callback, unless it was asked less than 20 ms ago.
  void check()
  {
    const Clock::time_point now = Clock::now();
    if (now - this->Last < std::chrono::milliseconds(20))
    {
      return;
    }
    this->Last = now;
    if (this->KeepGoing && !this->KeepGoing())
    {
      throw Cancelled();
    }
  }

private:
  std::function<bool()> KeepGoing;
  Clock::time_point Last;
  std::uint64_t Count = 0;
};

} // namespace mlr::detail
