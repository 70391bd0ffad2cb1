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

template <typename... Ts>
constexpr std::size_t columns_bytes(std::size_t capacity) {
  return (align_up(sizeof(Ts) * capacity) + ...);
}

}  // namespace

RayBatch::RayBatch(std::size_t capacity)
    : capacity_(capacity),
      storage_(columns_bytes<float, float, float, float, float, float, float, float, std::uint32_t,
                             std::uint32_t, std::uint16_t, RayKind, float, float, float,
                             std::uint8_t>(capacity)) {
  ColumnCarver carve(storage_.data(), capacity);
  origin_x = carve.next<float>();
  origin_y = carve.next<float>();
  origin_z = carve.next<float>();
  direction_x = carve.next<float>();
  direction_y = carve.next<float>();
  direction_z = carve.next<float>();
  tmin = carve.next<float>();
  tmax = carve.next<float>();
  pixel = carve.next<std::uint32_t>();
  sample = carve.next<std::uint32_t>();
  depth = carve.next<std::uint16_t>();
  kind = carve.next<RayKind>();
  throughput_r = carve.next<float>();
  throughput_g = carve.next<float>();
  throughput_b = carve.next<float>();
  flags = carve.next<std::uint8_t>();
}

void RayBatch::enable_approx_hit() {
  if (has_approx_hit()) return;
  approx_hit_storage_ = AlignedBuffer(columns_bytes<float, float, float>(capacity_));
  ColumnCarver carve(approx_hit_storage_.data(), capacity_);
  approx_hit_x = carve.next<float>();
  approx_hit_y = carve.next<float>();
  approx_hit_z = carve.next<float>();
}

void RayBatch::enable_sort_key() {
  if (has_sort_key()) return;
  sort_key_storage_ = AlignedBuffer(columns_bytes<std::uint64_t>(capacity_));
  sort_key = reinterpret_cast<std::uint64_t*>(sort_key_storage_.data());
}

void RayBatch::copy_ray(std::size_t to, const RayBatch& source, std::size_t from) {
  origin_x[to] = source.origin_x[from];
  origin_y[to] = source.origin_y[from];
  origin_z[to] = source.origin_z[from];
  direction_x[to] = source.direction_x[from];
  direction_y[to] = source.direction_y[from];
  direction_z[to] = source.direction_z[from];
  tmin[to] = source.tmin[from];
  tmax[to] = source.tmax[from];
  pixel[to] = source.pixel[from];
  sample[to] = source.sample[from];
  depth[to] = source.depth[from];
  kind[to] = source.kind[from];
  throughput_r[to] = source.throughput_r[from];
  throughput_g[to] = source.throughput_g[from];
  throughput_b[to] = source.throughput_b[from];
  flags[to] = source.flags[from];
  if (source.has_approx_hit()) {
    enable_approx_hit();
    approx_hit_x[to] = source.approx_hit_x[from];
    approx_hit_y[to] = source.approx_hit_y[from];
    approx_hit_z[to] = source.approx_hit_z[from];
  }
  if (source.has_sort_key()) {
    enable_sort_key();
    sort_key[to] = source.sort_key[from];
  }
}

HitBatch::HitBatch(std::size_t capacity)
    : capacity_(capacity),
      storage_(columns_bytes<float, std::uint32_t, float, float, float, float, float, float, float, float, std::uint32_t>(
          capacity)) {
  ColumnCarver carve(storage_.data(), capacity);
  t = carve.next<float>();
  primitive = carve.next<std::uint32_t>();
  u = carve.next<float>();
  v = carve.next<float>();
  point_x = carve.next<float>();
  point_y = carve.next<float>();
  point_z = carve.next<float>();
  normal_x = carve.next<float>();
  normal_y = carve.next<float>();
  normal_z = carve.next<float>();
  material = carve.next<std::uint32_t>();
}

void HitBatch::copy_hit(std::size_t to, const HitBatch& source, std::size_t from) {
  set_hit(to, source.t[from], source.primitive[from], source.u[from], source.v[from]);
  point_x[to] = source.point_x[from];
  point_y[to] = source.point_y[from];
  point_z[to] = source.point_z[from];
  normal_x[to] = source.normal_x[from];
  normal_y[to] = source.normal_y[from];
  normal_z[to] = source.normal_z[from];
  material[to] = source.material[from];
}

}  // namespace wavetrace
