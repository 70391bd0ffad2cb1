// Structure-of-arrays ray and hit batches: rays are entities, columns are components.
// Every column is 64-byte aligned and holds `capacity` elements; `count` are in use.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include <glm/vec3.hpp>

#include "memory/aligned_buffer.hpp"

namespace wavetrace {

inline constexpr std::uint32_t kInvalidPrimitive = std::numeric_limits<std::uint32_t>::max();
inline constexpr std::size_t kDefaultBatchCapacity = 4096;

enum class RayKind : std::uint8_t { camera = 0, bounce = 1, shadow = 2 };

// Bits of RayBatch::flags.
namespace ray_flags {
inline constexpr std::uint8_t alive = 1u << 0;
inline constexpr std::uint8_t missed_scene_box = 1u << 1;
inline constexpr std::uint8_t continues = 1u << 2;  // shade kept the path going: spawn bounces it
}  // namespace ray_flags

// A half-open range of ray indices inside one batch: the unit accelerators answer.
struct RayRange {
  std::uint32_t begin = 0;
  std::uint32_t end = 0;
  std::uint32_t size() const { return end - begin; }
};

class RayBatch {
 public:
  explicit RayBatch(std::size_t capacity = kDefaultBatchCapacity);

  std::size_t capacity() const { return capacity_; }
  std::size_t count = 0;

  // Always present.
  float* origin_x;
  float* origin_y;
  float* origin_z;
  float* direction_x;
  float* direction_y;
  float* direction_z;
  float* tmin;
  float* tmax;
  std::uint32_t* pixel;
  std::uint32_t* sample;
  std::uint16_t* depth;
  RayKind* kind;
  float* throughput_r;
  float* throughput_g;
  float* throughput_b;
  std::uint8_t* flags;

  // Optional columns, allocated on first request and kept when a pooled batch is reused.
  bool has_approx_hit() const { return approx_hit_x != nullptr; }
  void enable_approx_hit();
  bool has_sort_key() const { return sort_key != nullptr; }
  void enable_sort_key();
  float* approx_hit_x = nullptr;
  float* approx_hit_y = nullptr;
  float* approx_hit_z = nullptr;
  std::uint64_t* sort_key = nullptr;

  // Writes a ray's origin, direction and [tmin, tmax]; other columns are untouched.
  void set_geometry(std::size_t i, const glm::vec3& origin, const glm::vec3& direction, float ray_tmin, float ray_tmax) {
    origin_x[i] = origin.x;
    origin_y[i] = origin.y;
    origin_z[i] = origin.z;
    direction_x[i] = direction.x;
    direction_y[i] = direction.y;
    direction_z[i] = direction.z;
    tmin[i] = ray_tmin;
    tmax[i] = ray_tmax;
  }

  // Copies every present column of ray `from` of `source` into slot `to` of this batch.
  void copy_ray(std::size_t to, const RayBatch& source, std::size_t from);

  RayRange all() const { return {0, static_cast<std::uint32_t>(count)}; }

 private:
  std::size_t capacity_;
  AlignedBuffer storage_;
  AlignedBuffer approx_hit_storage_;
  AlignedBuffer sort_key_storage_;
};

// Closest-hit results per ray; any-hit queries set primitive to a valid id when occluded.
class HitBatch {
 public:
  explicit HitBatch(std::size_t capacity = kDefaultBatchCapacity);
  std::size_t capacity() const { return capacity_; }

  float* t;
  std::uint32_t* primitive;  // kInvalidPrimitive on a miss
  float* u;
  float* v;

  bool is_hit(std::size_t ray) const { return primitive[ray] != kInvalidPrimitive; }
  void set_hit(std::size_t ray, float hit_t, std::uint32_t hit_primitive, float hit_u, float hit_v) {
    t[ray] = hit_t;
    primitive[ray] = hit_primitive;
    u[ray] = hit_u;
    v[ray] = hit_v;
  }
  void set_miss(std::size_t ray) { set_hit(ray, std::numeric_limits<float>::infinity(), kInvalidPrimitive, 0.0f, 0.0f); }

 private:
  std::size_t capacity_;
  AlignedBuffer storage_;
};

// What travels between stages: a ray batch and the hits of its rays.
struct Batch {
  explicit Batch(std::size_t capacity = kDefaultBatchCapacity) : rays(capacity), hits(capacity) {}
  RayBatch rays;
  HitBatch hits;
};

}  // namespace wavetrace
