// The one memory policy: sizes that saturate instead of wrapping, the limit (given, or half
// of the physical memory) and the one message for an estimate over it. Remeshing, solving,
// the filter's input conversion and the command line's guarded reading all go through it,
// so they agree on the limit and speak of it alike.
#pragma once

#include <cstdint>
#include <initializer_list>
#include <string>

namespace mlr
{

/// a + b, saturating at UINT64_MAX: an estimate too large to represent is still refused.
std::uint64_t saturatingSum(std::uint64_t a, std::uint64_t b);

/// a * b, saturating at UINT64_MAX.
std::uint64_t saturatingProduct(std::uint64_t a, std::uint64_t b);

/// The product of all factors, saturating at UINT64_MAX.
std::uint64_t saturatingProduct(std::initializer_list<std::uint64_t> factors);

/// `bytes` as "1.23 GiB" (three significant digits), the unit of every memory message.
std::string gibibytes(std::uint64_t bytes);

/// The physical memory of this machine in bytes, 0 when it cannot be read.
std::uint64_t physicalMemoryBytes();

/// Half of the physical memory (4 GiB when it cannot be read): the default memory limit.
std::uint64_t defaultMemoryLimitBytes();

/**
 * A memory limit, and the check of an estimate against it.
 *
 * Every part that allocates in proportion to its input estimates the bytes first and asks
 * its budget, so that a scene too large for the machine is refused with a message naming
 * what to change, before anything is allocated.
 */
class MemoryBudget
{
public:
  /// `limitBytes` 0 means the default limit, half of the physical memory.
  explicit MemoryBudget(std::uint64_t limitBytes = 0);

  std::uint64_t limitBytes() const { return this->Limit; }

  bool fits(std::uint64_t bytes) const { return bytes <= this->Limit; }

  /**
   * The message for `bytes` over the limit:
   * "WHAT needs an estimated X GiB (DETAIL), over the memory limit of Y GiB: ADVICE".
   * An empty `detail` leaves out the parentheses; `advice` says what to change (for
   * example "use fewer frames, or raise the limit").
   */
  std::string overLimitMessage(std::uint64_t bytes, const std::string& what,
    const std::string& detail, const std::string& advice) const;

  /// Throws mlr::Error with overLimitMessage() when `bytes` do not fit.
  void check(std::uint64_t bytes, const std::string& what, const std::string& detail,
    const std::string& advice) const;

private:
  std::uint64_t Limit;
};

}
