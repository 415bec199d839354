// The rays one worker traced, by kind: kept per worker (no sharing in the hot loops) and
// added up when a phase ends.
#pragma once

#include <cstdint>

namespace mlr
{

struct alignas(64) WorkerCounters
{
  std::uint64_t shootingRays = 0;
  std::uint64_t shadowRays = 0;
  std::uint64_t shadowRaysBlocked = 0;
  std::uint64_t gatheringRays = 0;
  std::uint64_t missedRays = 0;
  std::uint64_t firstHits = 0;
  std::uint64_t firstHitsOnBack = 0; ///< one-sided mode: first hits absorbed by a back face

  WorkerCounters& operator+=(const WorkerCounters& o)
  {
    this->shootingRays += o.shootingRays;
    this->shadowRays += o.shadowRays;
    this->shadowRaysBlocked += o.shadowRaysBlocked;
    this->gatheringRays += o.gatheringRays;
    this->missedRays += o.missedRays;
    this->firstHits += o.firstHits;
    this->firstHitsOnBack += o.firstHitsOnBack;
    return *this;
  }
};

} // namespace mlr
