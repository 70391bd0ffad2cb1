// A std::allocator replacement for large arrays: blocks start on a cache line, and blocks
// of 2 MiB or more start on a 2 MiB boundary and are advised to use transparent huge
// pages (this machine's THP mode is "madvise"), which cuts the page faults of first touch
// by 512x; in a VM each fault is costly (about 12% of a BVH build here).
#pragma once

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <new>
#include <string_view>
#include <utility>
#include <vector>

#include <sys/mman.h>

#include "wavetrace/memory/aligned_buffer.hpp"

namespace wavetrace {

inline constexpr std::size_t kHugePageBytes = std::size_t{2} << 20;

// WAVETRACE_HUGE_PAGES=0 in the environment leaves large arrays to 4 KiB pages: the A/B of
// what huge pages buy (memory.md, "Huge pages at scale"). Read once.
inline bool huge_pages_advised() {
  static const bool advised = [] {
    const char* setting = std::getenv("WAVETRACE_HUGE_PAGES");
    return setting == nullptr || std::string_view(setting) != "0";
  }();
  return advised;
}

inline void* allocate_large_array(std::size_t bytes) {
  const bool huge = bytes >= kHugePageBytes && huge_pages_advised();
  const std::size_t alignment = huge ? kHugePageBytes : kColumnAlignment;
  void* memory = std::aligned_alloc(alignment, align_up(bytes, alignment));
  if (memory == nullptr) throw std::bad_alloc();
  // Only the whole 2 MiB the array fills are advised: a huge page over its last, partial
  // stretch would hold up to 2 MiB it never uses, per array (room:8M's hmq:width=8 chunks
  // kept 29 MB so). Advice only: failure is harmless.
  if (huge) madvise(memory, bytes / kHugePageBytes * kHugePageBytes, MADV_HUGEPAGE);
  return memory;
}

// Hands back the pages of a large array's allocation past its last element (a vector's
// spare capacity, and the rest of the huge page its end lies in: the kernel splits that
// page's mapping), for an array that is final and will not grow again. Advice only.
inline void release_spare_capacity(const void* data, std::size_t used_bytes, std::size_t capacity_bytes) {
  constexpr std::uintptr_t kPage = 4096;
  const auto begin = reinterpret_cast<std::uintptr_t>(data);
  const std::uintptr_t first = (begin + used_bytes + kPage - 1) & ~(kPage - 1);
  const std::uintptr_t last = (begin + capacity_bytes) & ~(kPage - 1);
  if (capacity_bytes >= kHugePageBytes && first < last) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

// Hands the whole 4 KiB pages within [begin, end) back to the OS: for a large temporary read
// front to back, whose part already read is no longer needed (it reads as zeros afterwards).
// Advice only: where the OS refuses, the pages stay.
inline void release_read_pages(const void* begin, const void* end) {
  constexpr std::uintptr_t kPage = 4096;
  const std::uintptr_t first = (reinterpret_cast<std::uintptr_t>(begin) + kPage - 1) & ~(kPage - 1);
  const std::uintptr_t last = reinterpret_cast<std::uintptr_t>(end) & ~(kPage - 1);
  if (first < last) madvise(reinterpret_cast<void*>(first), last - first, MADV_DONTNEED);
}

template <typename T>
struct CacheAlignedAllocator {
  using value_type = T;
  CacheAlignedAllocator() = default;
  template <typename U>
  CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}

  T* allocate(std::size_t count) { return static_cast<T*>(allocate_large_array(count * sizeof(T))); }
  void deallocate(T* pointer, std::size_t) { std::free(pointer); }
  template <typename U>
  bool operator==(const CacheAlignedAllocator<U>&) const { return true; }
};

template <typename T>
using LargeArray = std::vector<T, CacheAlignedAllocator<T>>;

// CacheAlignedAllocator whose resize() leaves new elements default-initialized (for trivial
// types: unwritten), for a large array that is filled in parallel right after it is sized:
// its pages are then first touched by the threads that fill it, not by one thread zeroing them
// (on this VM a first touch of cold huge pages is ~3 ms each, and two threads halve it).
template <typename T>
struct DefaultInitAllocator : CacheAlignedAllocator<T> {
  using value_type = T;
  template <typename U>
  struct rebind {
    using other = DefaultInitAllocator<U>;
  };
  DefaultInitAllocator() = default;
  template <typename U>
  DefaultInitAllocator(const DefaultInitAllocator<U>&) {}
  template <typename U>
  void construct(U* pointer) {
    ::new (static_cast<void*>(pointer)) U;
  }
  template <typename U, typename... Args>
  void construct(U* pointer, Args&&... args) {
    ::new (static_cast<void*>(pointer)) U(std::forward<Args>(args)...);
  }
};

template <typename T>
using UnfilledLargeArray = std::vector<T, DefaultInitAllocator<T>>;

}  // namespace wavetrace
