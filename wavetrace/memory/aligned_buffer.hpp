// An owning, 64-byte-aligned byte buffer: the storage under every SoA column.
#pragma once

#include <cstddef>
#include <cstdint>

namespace wavetrace {

inline constexpr std::size_t kColumnAlignment = 64;  // one cache line; also AVX-512-safe

class AlignedBuffer {
 public:
  AlignedBuffer() = default;
  explicit AlignedBuffer(std::size_t bytes);
  ~AlignedBuffer();
  AlignedBuffer(AlignedBuffer&& other) noexcept;
  AlignedBuffer& operator=(AlignedBuffer&& other) noexcept;
  AlignedBuffer(const AlignedBuffer&) = delete;
  AlignedBuffer& operator=(const AlignedBuffer&) = delete;

  std::byte* data() { return data_; }
  const std::byte* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  std::byte* data_ = nullptr;
  std::size_t size_ = 0;
};

// Rounds bytes up to a whole number of cache lines, so consecutive columns stay aligned.
constexpr std::size_t align_up(std::size_t bytes, std::size_t alignment = kColumnAlignment) {
  return (bytes + alignment - 1) / alignment * alignment;
}

}  // namespace wavetrace
