// Fresh mappings (ZeroedMemory.h): zero, aligned as asked, resident only once written, and
// given back whole.
#include "ZeroedMemory.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <string>
#include <vector>

using namespace mlr;

namespace
{
std::uint64_t residentBytes()
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.rfind("VmRSS:", 0) == 0)
    {
      return std::stoull(line.substr(6)) * 1024;
    }
  }
  return 0;
}
}

TEST(ZeroedMemory, MappingsAreZeroAlignedAndGivenBack)
{
  constexpr std::size_t Alignment = std::size_t(2) << 20;
  for (const std::size_t bytes : { std::size_t(1), std::size_t(4097), std::size_t(3) << 20 })
  {
    char* p = static_cast<char*>(mapZeroed(bytes, Alignment));
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(p) % Alignment, 0u) << bytes;
    EXPECT_EQ(p[0], 0);
    EXPECT_EQ(p[bytes - 1], 0);
    p[0] = 1;
    p[bytes - 1] = 1;
    unmapZeroed(p, bytes);
  }
#ifdef __linux__
  // 64 MiB written then freed: the resident set comes back down.
  constexpr std::size_t Bytes = std::size_t(64) << 20;
  const std::uint64_t before = residentBytes();
  char* p = static_cast<char*>(mapZeroed(Bytes, Alignment));
  for (std::size_t i = 0; i < Bytes; i += 4096)
  {
    p[i] = 1;
  }
  EXPECT_GE(residentBytes(), before + Bytes / 2);
  unmapZeroed(p, Bytes);
  EXPECT_LT(residentBytes(), before + Bytes / 4);
#endif
}

TEST(ZeroedMemory, TheAllocatorGivesZeroedArraysOfEverySize)
{
  for (const std::size_t n : { std::size_t(10), std::size_t(1) << 20 })
  {
    std::vector<std::uint16_t, ZeroedAllocator<std::uint16_t>> a(n);
    EXPECT_EQ(a.front(), 0);
    EXPECT_EQ(a.back(), 0);
    a.back() = 7;
    std::vector<std::uint16_t, ZeroedAllocator<std::uint16_t>> b(a);
    EXPECT_EQ(b.back(), 7) << n;
  }
}
