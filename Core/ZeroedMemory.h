// Memory that is zero until written and takes room only once written: fresh anonymous
// mappings, given back whole when freed.
#pragma once

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <new>
#include <type_traits>
#include <utility>

#ifdef __linux__
#include <sys/mman.h>
#endif

namespace mlr
{

/// The transparent huge page: mapZeroed asks for them, and a written byte makes its whole
/// 2 MiB resident where the kernel grants one (MemoryPlan counts written pages at this size).
constexpr std::size_t HugePageBytes = std::size_t(2) << 20;

/**
 * `bytes` of zeroed memory aligned to `alignment` (a power of two), a mapping of its own:
 * its pages are resident only once written, and it goes back to the system when freed.
 * From the heap instead, buffers of tens of MiB that come and go (a long run's chunks) fall
 * under glibc's dynamic mmap threshold, fragment it and stay resident once freed, so that
 * the peak wanders above the memory plan (Performance.md, "Long animations in chunks").
 * Throws std::bad_alloc. Free with unmapZeroed().
 */
inline void* mapZeroed(std::size_t bytes, std::size_t alignment)
{
#ifdef __linux__
  constexpr std::size_t Page = 4096;
  // Any alignment above the page's: map that much more and give back both ends.
  const std::size_t extra = alignment > Page ? alignment : 0;
  if (bytes > SIZE_MAX - extra - Page)
  {
    throw std::bad_alloc();
  }
  const std::size_t length = (std::max<std::size_t>(bytes, 1) + Page - 1) / Page * Page;
  void* mapped =
    mmap(nullptr, length + extra, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mapped == MAP_FAILED)
  {
    throw std::bad_alloc();
  }
  char* const begin = static_cast<char*>(mapped);
  char* p = begin;
  if (extra > 0)
  {
    p = reinterpret_cast<char*>(
      (reinterpret_cast<std::uintptr_t>(begin) + alignment - 1) / alignment * alignment);
    if (p > begin)
    {
      munmap(begin, static_cast<std::size_t>(p - begin));
    }
    char* const end = begin + length + extra;
    if (end > p + length)
    {
      munmap(p + length, static_cast<std::size_t>(end - (p + length)));
    }
  }
#ifdef MADV_HUGEPAGE
  // A page fault costs about as much as writing the page, and on a virtual machine several
  // times more: 2 MiB pages, where the kernel grants them, take 512 times fewer.
  madvise(p, length, MADV_HUGEPAGE);
#endif
  return p;
#else
  const std::size_t a = std::max<std::size_t>(alignment, alignof(std::max_align_t));
  void* p = std::aligned_alloc(a, (std::max<std::size_t>(bytes, 1) + a - 1) / a * a);
  if (!p)
  {
    throw std::bad_alloc();
  }
  std::memset(p, 0, bytes);
  return p;
#endif
}

/// Gives back what mapZeroed(bytes, ...) returned.
inline void unmapZeroed(void* p, std::size_t bytes) noexcept
{
#ifdef __linux__
  munmap(p, std::max<std::size_t>(bytes, 1));
#else
  (void)bytes;
  std::free(p);
#endif
}

/**
 * Allocates results as memory the kernel maps only once it is written (a large array is a
 * fresh anonymous mapping, already zero): a solve's direct light and patches take no memory
 * while the shooting sums they will be made of do (MemoryPlan). A default-constructed
 * element is left as the zero bytes it already is. So an array may only grow by a fresh
 * allocation (constructed at its size, or from empty), never back into capacity it had.
 */
template <typename T>
struct ZeroedAllocator
{
  static_assert(std::is_trivially_copyable<T>::value, "zero bytes must be a default T");
  using value_type = T;
  /// From this size on, an array is a mapping of its own.
  static constexpr std::size_t MappedBytes = std::size_t(1) << 20;
  ZeroedAllocator() = default;
  template <typename U>
  ZeroedAllocator(const ZeroedAllocator<U>&) noexcept
  {
  }
  T* allocate(std::size_t n)
  {
    const std::size_t bytes = std::max<std::size_t>(n, 1) * sizeof(T);
    if (bytes >= MappedBytes)
    {
      // Aligned to huge pages, so that the pages a write makes resident are those MemoryPlan
      // counts (writtenResultBytes).
      return static_cast<T*>(mapZeroed(bytes, bytes >= HugePageBytes ? HugePageBytes : 1));
    }
    void* p = std::calloc(1, bytes);
    if (!p)
    {
      throw std::bad_alloc();
    }
    return static_cast<T*>(p);
  }
  void deallocate(T* p, std::size_t n) noexcept
  {
    const std::size_t bytes = std::max<std::size_t>(n, 1) * sizeof(T);
    if (bytes >= MappedBytes)
    {
      unmapZeroed(p, bytes);
      return;
    }
    std::free(p);
  }
  template <typename U>
  void construct(U*) noexcept
  {
  }
  template <typename U, typename... Args>
  void construct(U* p, Args&&... args)
  {
    ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
  template <typename U>
  bool operator==(const ZeroedAllocator<U>&) const noexcept
  {
    return true;
  }
  template <typename U>
  bool operator!=(const ZeroedAllocator<U>&) const noexcept
  {
    return false;
  }
};

} // namespace mlr
