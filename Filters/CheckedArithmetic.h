// Size, offset and index arithmetic on numbers read from files. A hostile file chooses every
// operand, so a bounds check written as `offset + length <= size` can wrap past 2^63 and pass;
// these compute nothing that can overflow, and the readers' bounds checks go through them.
// Header-only and free of VTK, so the tests can check them at the limits. Private to the
// Filters module.
#pragma once

#include <cstdint>

namespace mlr::scenefile
{

/// a + b into `result`; false (and `result` untouched) when the sum does not fit in 64 bits.
inline bool checkedAdd(std::int64_t a, std::int64_t b, std::int64_t& result)
{
  std::int64_t sum = 0;
  if (__builtin_add_overflow(a, b, &sum))
  {
    return false;
  }
  result = sum;
  return true;
}

/// a * b into `result`; false (and `result` untouched) when the product does not fit.
inline bool checkedMultiply(std::int64_t a, std::int64_t b, std::int64_t& result)
{
  std::int64_t product = 0;
  if (__builtin_mul_overflow(a, b, &product))
  {
    return false;
  }
  result = product;
  return true;
}

/// Whether `count` items `stride` bytes apart, the last `size` bytes long, starting at
/// `offset`, lie within `length` bytes: offset + (count - 1) * stride + size <= length, with
/// every operand non-negative and nothing wrapping. A count of 0 fits when offset <= length.
inline bool spanFits(std::int64_t offset, std::int64_t count, std::int64_t stride,
  std::int64_t size, std::int64_t length)
{
  if (offset < 0 || count < 0 || stride < 0 || size < 0 || length < 0 || offset > length)
  {
    return false;
  }
  if (count == 0)
  {
    return true;
  }
  std::int64_t span = 0;
  return checkedMultiply(count - 1, stride, span) && checkedAdd(span, size, span) &&
    span <= length - offset;
}

} // namespace mlr::scenefile
