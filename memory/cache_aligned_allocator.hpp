// A std::allocator replacement whose blocks start on a cache line, for arrays of nodes
// whose documented layout assumes 64-byte alignment.
#pragma once

#include <cstddef>
#include <cstdlib>
#include <new>

#include "memory/aligned_buffer.hpp"

namespace wavetrace {

template <typename T>
struct CacheAlignedAllocator {
  using value_type = T;
  CacheAlignedAllocator() = default;
  template <typename U>
  CacheAlignedAllocator(const CacheAlignedAllocator<U>&) {}

  T* allocate(std::size_t count) {
    void* memory = std::aligned_alloc(kColumnAlignment, align_up(count * sizeof(T)));
    if (memory == nullptr) throw std::bad_alloc();
    return static_cast<T*>(memory);
  }
  void deallocate(T* pointer, std::size_t) { std::free(pointer); }
  template <typename U>
  bool operator==(const CacheAlignedAllocator<U>&) const { return true; }
};

}  // namespace wavetrace
