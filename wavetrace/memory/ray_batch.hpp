// Structure-of-arrays ray and hit batches: rays are entities, columns are components.
// Every column is 64-byte aligned and holds `capacity` elements; `count` are in use.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "wavetrace/memory/aligned_buffer.hpp"

namespace wavetrace {

inline constexpr std::uint32_t kInvalidPrimitive = std::numeric_limits<std::uint32_t>::max();
inline constexpr std::size_t kDefaultBatchCapacity = 4096;

// A specular ray leaves a mirror or glass: no light was sampled where it starts, so like a
// camera ray it sees the emission it hits.
enum class RayKind : std::uint8_t { camera = 0, bounce = 1, shadow = 2, specular = 3 };
inline bool sees_emission(RayKind kind) { return kind == RayKind::camera || kind == RayKind::specular; }

// Bits of RayBatch::flags.
namespace ray_flags {
inline constexpr std::uint8_t alive = 1u << 0;
inline constexpr std::uint8_t missed_scene_box = 1u << 1;
inline constexpr std::uint8_t continues = 1u << 2;  // shade kept the path going: spawn bounces it
}  // namespace ray_flags

// The columns, declared once (pbrt-v4's workitems.soa habit): each X(type, name) is a column
// of `capacity` elements. Layout (one 64-byte-aligned slice per column, in this order),
// copying a ray, the bytes a ray costs and the column visitors (for_each_column) all follow
// from these lists; adding a column is one line here.
#define WAVETRACE_RAY_COLUMNS(X)                                                                     \
  X(float, origin_x) X(float, origin_y) X(float, origin_z)                                             \
  X(float, direction_x) X(float, direction_y) X(float, direction_z)                                    \
  X(float, tmin) X(float, tmax) X(std::uint32_t, pixel) X(std::uint32_t, sample) X(std::uint16_t, depth) \
  X(RayKind, kind) X(float, throughput_r) X(float, throughput_g) X(float, throughput_b) X(std::uint8_t, flags)
// Optional ray columns, allocated on first request (approx_hit's points, zsort's keys).
#define WAVETRACE_APPROX_HIT_COLUMNS(X) X(float, approx_hit_x) X(float, approx_hit_y) X(float, approx_hit_z)
#define WAVETRACE_SORT_KEY_COLUMNS(X) X(std::uint64_t, sort_key)
#define WAVETRACE_HIT_COLUMNS(X)                                                                     \
  X(float, t) X(std::uint32_t, primitive) X(float, u) X(float, v)                                      \
  X(float, point_x) X(float, point_y) X(float, point_z) X(float, normal_x) X(float, normal_y)           \
  X(float, normal_z) X(std::uint32_t, material)

#define WAVETRACE_COLUMN_POINTER(type, name) type* name = nullptr;
#define WAVETRACE_COPY_COLUMN(type, name) name[to] = source.name[from];
#define WAVETRACE_COLUMN_BYTES(type, name) +sizeof(type)

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

  // Always present (WAVETRACE_RAY_COLUMNS): origin, direction, [tmin, tmax], pixel, sample,
  // depth, kind, throughput, flags.
  WAVETRACE_RAY_COLUMNS(WAVETRACE_COLUMN_POINTER)

  // Optional columns, allocated on first request and kept when a pooled batch is reused.
  bool has_approx_hit() const { return approx_hit_x != nullptr; }
  void enable_approx_hit();
  bool has_sort_key() const { return sort_key != nullptr; }
  void enable_sort_key();
  WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_COLUMN_POINTER)
  WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_COLUMN_POINTER)

  // Bytes one ray holds in the always-present columns, and in each optional set.
  static constexpr std::size_t kBytesPerRay = 0 WAVETRACE_RAY_COLUMNS(WAVETRACE_COLUMN_BYTES);
  static constexpr std::size_t kApproxHitBytesPerRay = 0 WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_COLUMN_BYTES);
  static constexpr std::size_t kSortKeyBytesPerRay = 0 WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_COLUMN_BYTES);

  // Calls visit(name, column, element_bytes) for every present column, in layout order: what
  // copies, writes or reads whole columns needs, without a list of its own.
  template <typename Visit>
  void for_each_column(Visit&& visit) {
    for_each_column(visit, has_approx_hit(), has_sort_key());
  }
  // The same over the optional sets asked for, which must be enabled (a spill block's).
  template <typename Visit>
  void for_each_column(Visit&& visit, bool with_approx_hit, bool with_sort_key) {
#define WAVETRACE_VISIT(type, name) visit(#name, static_cast<void*>(name), sizeof(type));
    WAVETRACE_RAY_COLUMNS(WAVETRACE_VISIT)
    if (with_approx_hit) { WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_VISIT) }
    if (with_sort_key) { WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_VISIT) }
#undef WAVETRACE_VISIT
  }

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
  // Inline: approx_hit's compaction and repack call it once a ray.
  void copy_ray(std::size_t to, const RayBatch& source, std::size_t from) {
    copy_keyed_ray(to, source, from);
    if (source.has_approx_hit()) {
      if (!has_approx_hit()) enable_approx_hit();
      WAVETRACE_APPROX_HIT_COLUMNS(WAVETRACE_COPY_COLUMN)
    }
  }

  // copy_ray without the approximate hit, which nothing reads once a ray has its key: zsort's
  // gather moves three columns fewer (a fifth of its time).
  void copy_keyed_ray(std::size_t to, const RayBatch& source, std::size_t from) {
    WAVETRACE_RAY_COLUMNS(WAVETRACE_COPY_COLUMN)
    if (source.has_sort_key()) {
      if (!has_sort_key()) enable_sort_key();
      WAVETRACE_SORT_KEY_COLUMNS(WAVETRACE_COPY_COLUMN)
    }
  }

  RayRange all() const { return {0, static_cast<std::uint32_t>(count)}; }

 private:
  std::size_t capacity_;
  AlignedBuffer storage_;
  AlignedBuffer approx_hit_storage_;
  AlignedBuffer sort_key_storage_;
};

// Closest-hit results per ray; any-hit queries set primitive to a valid id when occluded.
// Closest-hit queries also write what shading needs, so that shade and spawn never read the
// mesh: the hit point (from the barycentrics on the triangle as the accelerator stores it),
// its geometric normal, and (written by the trace stage) its material.
class HitBatch {
 public:
  explicit HitBatch(std::size_t capacity = kDefaultBatchCapacity);
  std::size_t capacity() const { return capacity_; }

  // WAVETRACE_HIT_COLUMNS: t, primitive (kInvalidPrimitive on a miss), u, v; closest hits
  // only: a + (b - a) u + (c - a) v and cross(b - a, c - a) of the hit triangle's corners a,
  // b, c in the mesh's winding (unnormalized: its direction gives the front face), and the
  // material index of the triangle.
  WAVETRACE_HIT_COLUMNS(WAVETRACE_COLUMN_POINTER)
  static constexpr std::size_t kBytesPerHit = 0 WAVETRACE_HIT_COLUMNS(WAVETRACE_COLUMN_BYTES);

  bool is_hit(std::size_t ray) const { return primitive[ray] != kInvalidPrimitive; }
  void set_hit(std::size_t ray, float hit_t, std::uint32_t hit_primitive, float hit_u, float hit_v) {
    t[ray] = hit_t;
    primitive[ray] = hit_primitive;
    u[ray] = hit_u;
    v[ray] = hit_v;
  }
  void set_miss(std::size_t ray) { set_hit(ray, std::numeric_limits<float>::infinity(), kInvalidPrimitive, 0.0f, 0.0f); }
  // The point and normal of a closest hit whose u, v are set, from the triangle's corners.
  // Spawn once computed exactly this from the mesh; the same arithmetic keeps images equal.
  void set_surface(std::size_t ray, const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    const glm::vec3 ab = b - a, ac = c - a;
    const glm::vec3 point = a + ab * u[ray] + ac * v[ray];
    point_x[ray] = point.x;
    point_y[ray] = point.y;
    point_z[ray] = point.z;
    const glm::vec3 normal = glm::cross(ab, ac);
    normal_x[ray] = normal.x;
    normal_y[ray] = normal.y;
    normal_z[ray] = normal.z;
  }
  glm::vec3 point(std::size_t ray) const { return {point_x[ray], point_y[ray], point_z[ray]}; }
  glm::vec3 normal(std::size_t ray) const { return {normal_x[ray], normal_y[ray], normal_z[ray]}; }
  // Copies every column of hit `from` of `source` into slot `to` (inline, as copy_ray).
  void copy_hit(std::size_t to, const HitBatch& source, std::size_t from) { WAVETRACE_HIT_COLUMNS(WAVETRACE_COPY_COLUMN) }

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
