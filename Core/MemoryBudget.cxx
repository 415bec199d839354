#include "MemoryBudget.h"

#include "Error.h"

#include <sstream>
#include <unistd.h>

namespace mlr
{

std::uint64_t saturatingSum(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t sum = 0;
  return __builtin_add_overflow(a, b, &sum) ? UINT64_MAX : sum;
}

std::uint64_t saturatingProduct(std::uint64_t a, std::uint64_t b)
{
  std::uint64_t product = 0;
  return __builtin_mul_overflow(a, b, &product) ? UINT64_MAX : product;
}

std::uint64_t saturatingProduct(std::initializer_list<std::uint64_t> factors)
{
  std::uint64_t product = 1;
  for (std::uint64_t f : factors)
  {
    product = saturatingProduct(product, f);
  }
  return product;
}

std::string gibibytes(std::uint64_t bytes)
{
  std::ostringstream s;
  s.precision(3);
  s << static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0) << " GiB";
  return s.str();
}

std::uint64_t physicalMemoryBytes()
{
  const long pages = sysconf(_SC_PHYS_PAGES);
  const long pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages <= 0 || pageSize <= 0)
  {
    return 0;
  }
  return saturatingProduct(static_cast<std::uint64_t>(pages), static_cast<std::uint64_t>(pageSize));
}

std::uint64_t defaultMemoryLimitBytes()
{
  const std::uint64_t physical = physicalMemoryBytes();
  return physical > 0 ? physical / 2 : 4ULL << 30;
}

MemoryBudget::MemoryBudget(std::uint64_t limitBytes)
  : Limit(limitBytes > 0 ? limitBytes : defaultMemoryLimitBytes())
{
}

std::string MemoryBudget::overLimitMessage(std::uint64_t bytes, const std::string& what,
  const std::string& detail, const std::string& advice) const
{
  std::string message = what + " needs an estimated " + gibibytes(bytes);
  if (!detail.empty())
  {
    message += " (" + detail + ")";
  }
  return message + ", over the memory limit of " + gibibytes(this->Limit) + ": " + advice;
}

void MemoryBudget::check(std::uint64_t bytes, const std::string& what, const std::string& detail,
  const std::string& advice) const
{
  if (!this->fits(bytes))
  {
    throw Error(this->overLimitMessage(bytes, what, detail, advice));
  }
}

}
