#include "ReliabilitySupport.h"

#include "GeneratedScenes.h"

#include <fstream>
#include <unistd.h>

namespace mlr::reliability
{

std::size_t residentBytes()
{
  std::ifstream statm("/proc/self/statm");
  std::size_t size = 0, resident = 0;
  statm >> size >> resident;
  return resident * static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
}

PolygonSoup sphereSoup(int frequency)
{
  return scenes::icosphere(frequency);
}

DelayedCancel::DelayedCancel(double delaySeconds)
{
  const auto at = Clock::now() +
    std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(delaySeconds));
  this->Timer = std::thread(
    [this, at]
    {
      while (!this->Stop.load() && Clock::now() < at)
      {
        std::this_thread::sleep_for(std::chrono::microseconds(200));
      }
      if (!this->Stop.load())
      {
        this->RequestedAt = Clock::now();
        this->Requested.store(true);
      }
    });
}

DelayedCancel::~DelayedCancel()
{
  this->Stop.store(true);
  this->Timer.join();
}

double DelayedCancel::latency() const
{
  if (!this->Requested.load())
  {
    return -1;
  }
  const Clock::time_point end = this->End == Clock::time_point{} ? Clock::now() : this->End;
  return std::chrono::duration<double>(end - this->RequestedAt).count();
}

} // namespace mlr::reliability
