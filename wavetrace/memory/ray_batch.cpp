// Column carving for ray and hit batches: one allocation per batch, one cache-aligned slice per column.
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {
namespace {

// Hands out aligned column slices of one buffer in order.
class ColumnCarver {
 public:
  ColumnCarver(std::byte* base, std::size_t capacity) : cursor_(base), capacity_(capacity) {}
  template <typename T>
  T* next() {
    T* column = reinterpret_cast<T*>(cursor_);
    cursor_ += align_up(sizeof(T) * capacity_);
    return column;
  }

 private:
  std::byte* cursor_;
  std::size_t capacity_;
};

// The bytes of a list of columns of `capacity` elements, each slice 64-byte aligned.
#define WAVETRACE_SLICE_BYTES(type, name) +align_up(sizeof(type) * capacity)
#define WAVETRACE_CARVE(type, name) name = carve.next<type>();

}  // namespace

RayBatch::RayBatch(std::size_t capacity)
    : capacity_(capacity), storage_(0 WAVETRACE_RAY_COLUMNS(WAVETRACE_SLICE_BYTES)) {
  ColumnCarver carve(storage_.data(), capacity);
  WAVETRACE_RAY_COLUMNS(WAVETRACE_CARVE)
}

void RayBatch::enable_approx_hit() {
  if (has_approx_hit()) return;
  const std::size_t capacity = capacity_;
  approx_hit_storage_ = AlignedBuffer(0 WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_SLICE_BYTES));
  ColumnCarver carve(approx_hit_storage_.data(), capacity);
  WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_CARVE)
}

void RayBatch::enable_sort_key() {
  if (has_sort_key()) return;
  const std::size_t capacity = capacity_;
  sort_key_storage_ = AlignedBuffer(0 WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_SLICE_BYTES));
  ColumnCarver carve(sort_key_storage_.data(), capacity);
  WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_CARVE)
}


HitBatch::HitBatch(std::size_t capacity)
    : capacity_(capacity), storage_(0 WAVETRACE_HIT_COLUMNS(WAVETRACE_SLICE_BYTES)) {
  ColumnCarver carve(storage_.data(), capacity);
  WAVETRACE_HIT_COLUMNS(WAVETRACE_CARVE)
}

}  // namespace wavetrace
