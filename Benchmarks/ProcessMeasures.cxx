#include "ProcessMeasures.h"

#include <fstream>
#include <sstream>
#include <sys/resource.h>

namespace mlr::bench
{

double processCpuSeconds()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return double(usage.ru_utime.tv_sec + usage.ru_stime.tv_sec) +
    1e-6 * double(usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

std::uint64_t statusBytes(const std::string& field)
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.compare(0, field.size() + 1, field + ":") == 0)
    {
      std::istringstream value(line.substr(field.size() + 1));
      std::uint64_t kib = 0;
      value >> kib;
      return kib * 1024;
    }
  }
  return 0;
}

bool resetPeakResidentMemory()
{
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5" << std::flush;
  return static_cast<bool>(clear);
}

std::uint64_t lifetimePeakResidentBytes()
{
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<std::uint64_t>(usage.ru_maxrss) * 1024;
}

} // namespace mlr::bench
