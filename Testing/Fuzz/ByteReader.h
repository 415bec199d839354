// Turns a fuzzer's bytes into numbers, the same way on every run: inputs replay exactly.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstring>
#include <limits>

namespace mlr::fuzz
{

/// Reads integers and doubles from the front of a byte string; past its end every read gives
/// 0, so any input decodes to something.
class ByteReader
{
public:
  ByteReader(const std::uint8_t* data, std::size_t size)
    : Data(data)
    , Size(size)
  {
  }

  std::uint8_t byte() { return this->Position < this->Size ? this->Data[this->Position++] : 0; }

  std::uint32_t u16()
  {
    const std::uint32_t low = this->byte();
    return low | (static_cast<std::uint32_t>(this->byte()) << 8);
  }

  /// A value in [0, count) (0 when count is 0).
  std::size_t below(std::size_t count)
  {
    if (count == 0)
    {
      return 0;
    }
    return count <= 256 ? this->byte() % count : this->u16() % count;
  }

  /// A value in [0, 1] in steps of 1/255.
  double unit() { return this->byte() / 255.0; }

  /// Usually a small grid coordinate in [-2, 2] (so that points coincide, align and lie on
  /// planes, as in real scenes); sometimes a raw double or a special value (NaN, infinities,
  /// huge, tiny, denormal).
  double coordinate()
  {
    const std::uint8_t kind = this->byte();
    if (kind < 232)
    {
      return (kind % 17) / 4.0 - 2.0;
    }
    switch (kind % 8)
    {
      case 0:
        return std::numeric_limits<double>::quiet_NaN();
      case 1:
        return std::numeric_limits<double>::infinity();
      case 2:
        return -std::numeric_limits<double>::infinity();
      case 3:
        return 1e300;
      case 4:
        return 1e-300;
      case 5:
        return std::numeric_limits<double>::denorm_min();
      case 6:
        return (this->u16() / 65535.0 - 0.5) * 4.0 + this->u16() * 1e-12;
      default:
        return this->rawDouble();
    }
  }

  double rawDouble()
  {
    std::uint64_t bits = 0;
    for (int i = 0; i < 8; ++i)
    {
      bits |= static_cast<std::uint64_t>(this->byte()) << (8 * i);
    }
    double value;
    std::memcpy(&value, &bits, sizeof(value));
    return value;
  }

  bool exhausted() const { return this->Position >= this->Size; }

private:
  const std::uint8_t* Data;
  std::size_t Size;
  std::size_t Position = 0;
};

} // namespace mlr::fuzz
