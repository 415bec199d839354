// What the benchmarks read of their own process: CPU time, which other load on the cores
// hardly changes, and resident memory, whose peak can be restarted around one solve.
#pragma once

#include <cstdint>
#include <string>

namespace mlr::bench
{

/// CPU seconds (user + system, all threads) this process has used.
double processCpuSeconds();

/// A field of /proc/self/status in bytes (VmRSS, VmHWM), or 0 where there is none.
std::uint64_t statusBytes(const std::string& field);

/// Starts a new peak of resident memory (VmHWM) at the current resident size: Linux resets it
/// when "5" is written to clear_refs. False where the kernel does not allow it.
bool resetPeakResidentMemory();

/// The process's peak resident set since it started (bytes): unlike VmHWM, never restarted.
std::uint64_t lifetimePeakResidentBytes();

} // namespace mlr::bench
