// Shared by the reliability tests: resident memory, sanitizer detection, the 200,000-triangle
// input and a canceller that asks to stop at a given time from another thread.
#pragma once

#include "Remeshing.h"

#include <atomic>
#include <chrono>
#include <cstddef>
#include <thread>

namespace mlr::reliability
{

#if defined(__SANITIZE_ADDRESS__)
constexpr bool UnderAddressSanitizer = true;
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
constexpr bool UnderAddressSanitizer = true;
#else
constexpr bool UnderAddressSanitizer = false;
#endif
#else
constexpr bool UnderAddressSanitizer = false;
#endif

/// The bound the cancellation tests assert: ten times the 0.5 s promised
/// (Documentation/Reliability.md) on a quiet machine, so that the gate's verdict does not depend on
/// the machine's load (the test command runs two tests at a time on two cores). The tests print the
/// latency they measured; a stretch without a cancellation check shows there as a regression long
/// before it fails. Sanitizer builds run several times slower and get three times as long.
constexpr double CancelLatencyBound = UnderAddressSanitizer ? 15.0 : 5.0;

/// Resident set size of this process, in bytes (/proc/self/statm).
std::size_t residentBytes();

/// A geodesic sphere of radius 1 with 20 * frequency^2 triangles (200,000 at 100).
PolygonSoup sphereSoup(int frequency);

/**
 * Asks to stop at a given time, as a user pressing Abort does: the flag is set from another
 * thread at `delay` after construction, whatever the solve is doing then. keepGoing() is what
 * a progress callback returns; latency() is the time from the request to the call of
 * finished() (or to now).
 */
class DelayedCancel
{
public:
  using Clock = std::chrono::steady_clock;

  explicit DelayedCancel(double delaySeconds);
  ~DelayedCancel();
  DelayedCancel(const DelayedCancel&) = delete;
  DelayedCancel& operator=(const DelayedCancel&) = delete;

  bool keepGoing() const
  {
    const bool stop = this->Requested.load();
    if (stop)
    {
      this->Refused.store(true);
    }
    return !stop;
  }
  bool requested() const { return this->Requested.load(); }
  /// True once a poll saw the request and said to stop: the work must then stop. A request
  /// that came after the last poll (the work was finishing) is not a missed cancellation.
  bool refused() const { return this->Refused.load(); }
  void finished() { this->End = Clock::now(); }
  /// Seconds from the request to finished(); negative when it was never requested.
  double latency() const;

private:
  std::atomic<bool> Requested{ false };
  std::atomic<bool> Stop{ false };
  mutable std::atomic<bool> Refused{ false };
  Clock::time_point RequestedAt{};
  Clock::time_point End{};
  std::thread Timer;
};

} // namespace mlr::reliability
