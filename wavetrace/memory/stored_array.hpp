// An array an accelerator traverses, either built in this process (owned) or read in place
// from a mapped world file (a view, kept alive by the mapping's owner). Traversal sees one
// pointer and a size either way; nothing is copied when a world is loaded.
#pragma once

#include <cstddef>
#include <memory>
#include <span>
#include <type_traits>
#include <utility>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {

template <typename T>
class StoredArray {
  static_assert(std::is_trivially_copyable_v<T>, "a stored array is saved and mapped as raw bytes");

 public:
  using value_type = T;

  StoredArray() = default;
  // Takes a built array; moving a vector keeps its buffer, so the view stays valid. The
  // array is final: pages past its end that a reserve or a growth touched go back to the OS.
  explicit StoredArray(LargeArray<T> owned) : owned_(std::move(owned)), view_(owned_.data(), owned_.size()) {
    release_spare_capacity(owned_.data(), owned_.size() * sizeof(T), owned_.capacity() * sizeof(T));
  }
  // Bytes of a mapped file, which `keep_alive` keeps mapped for as long as this array lives.
  StoredArray(std::span<const T> view, std::shared_ptr<const void> keep_alive)
      : view_(view), keep_alive_(std::move(keep_alive)) {}

  StoredArray(StoredArray&& other) noexcept { *this = std::move(other); }
  StoredArray& operator=(StoredArray&& other) noexcept {
    owned_ = std::move(other.owned_);
    view_ = other.view_;
    keep_alive_ = std::move(other.keep_alive_);
    other.view_ = {};
    return *this;
  }
  StoredArray(const StoredArray&) = delete;
  StoredArray& operator=(const StoredArray&) = delete;

  const T* data() const { return view_.data(); }
  std::size_t size() const { return view_.size(); }
  bool empty() const { return view_.empty(); }
  const T& operator[](std::size_t i) const { return view_[i]; }
  const T* begin() const { return view_.data(); }
  const T* end() const { return view_.data() + view_.size(); }
  std::span<const T> span() const { return view_; }
  operator std::span<const T>() const { return view_; }
  std::span<const std::byte> bytes() const { return std::as_bytes(view_); }

 private:
  LargeArray<T> owned_;
  std::span<const T> view_;
  std::shared_ptr<const void> keep_alive_;
};

}  // namespace wavetrace
