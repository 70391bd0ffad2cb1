// What both HMQ layouts do at a leaf: decode its record against its grid box, test its
// triangles, keep the nearest hit in leaf terms, and write it out in the mesh's terms.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <limits>

#include "wavetrace/accel/bvh/leaf_query.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/accel/hmq/leaf_codec.hpp"
#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/kernels/watertight_lanes.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace::hmq {

// The nearest hit of one ray, kept in leaf terms until written.
struct LeafHit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;  // weights of the strip triangle's second and third corner
  LeafIdentity leaf{};
  std::uint32_t triangle = 0;
  glm::vec3 corner[3];  // the strip triangle's decoded corners, for the hit's point and normal
  bool found = false;

  std::uint32_t triangle_id() const { return leaf.triangle_id(triangle); }
  std::uint32_t corner_code() const { return leaf.corner_code(triangle); }
};

// A leaf decoded once, with its triangles' corners gathered into lanes (triangle k in lane k),
// ready to be tested by one ray or by each ray of a packet: eight triangles a pass in AVX2, all
// fourteen in one pass of the AVX-512 walks (of a GCC build: watertight_lanes.hpp). With lanes
// it keeps only them and where its ids are (640 bytes): the decoded columns it was gathered
// from (1,152 bytes more) stay in a scratch the next decode overwrites, so that a cache of
// decoded leaves (DecodedLeafCache) holds four times the leaves in the same bytes.
struct LeafTriangles {
  LeafIdentity identity;
  const StripLayoutEntry* layout = nullptr;
#if WAVETRACE_AVX2
  TriangleLanes<16> lanes;
  glm::vec3 corner(std::uint32_t k, std::uint32_t c) const {
    return {lanes.corner[c][0][k], lanes.corner[c][1][k], lanes.corner[c][2][k]};
  }
#else
  DecodedLeaf decoded;
  glm::vec3 corner(std::uint32_t k, std::uint32_t c) const { return decoded.slot_position(layout->first_slot[k] + c); }
#endif
};

#if WAVETRACE_AVX2
// column[index] in each lane, for indices below 8 * parts (1, 2 or 4; 0: any index below 64):
// a permute within each 8-lane part and blends on the index's bits 3 and 4, or a gather from
// memory past 32 entries. Most leaves hold at most 16 vertices and slots, where two permutes
// and a blend take a few cycles and a gather of eight dozens (room:1M: 1.17 -> 1.38 Mrays/s).
[[gnu::always_inline]] inline __m256 pick_lanes(const float* column, __m256i index, int parts) {
  if (parts == 0) return _mm256_i32gather_ps(column, index, 4);
  const __m256 first = _mm256_permutevar8x32_ps(_mm256_load_ps(column), index);
  if (parts == 1) return first;
  const __m256 bit3 = _mm256_castsi256_ps(_mm256_slli_epi32(index, 28));  // bit 3 in the sign
  const __m256 low = _mm256_blendv_ps(first, _mm256_permutevar8x32_ps(_mm256_load_ps(column + 8), index), bit3);
  if (parts == 2) return low;
  const __m256 high = _mm256_blendv_ps(_mm256_permutevar8x32_ps(_mm256_load_ps(column + 16), index),
                                       _mm256_permutevar8x32_ps(_mm256_load_ps(column + 24), index), bit3);
  return _mm256_blendv_ps(low, high, _mm256_castsi256_ps(_mm256_slli_epi32(index, 27)));
}

inline int lane_parts(std::uint32_t entries) { return entries <= 8 ? 1 : entries <= 16 ? 2 : entries <= 32 ? 4 : 0; }
#endif

#if WAVETRACE_AVX512_DISPATCH
// pick_lanes in sixteen lanes: one permute over up to 16 entries, one of two registers over
// up to 32, a gather past that. (The masked forms here and in the widening below start from
// zero, where the plain ones start from _mm512_undefined, which GCC 12 reports as maybe
// uninitialized once inlined.)
[[WAVETRACE_AVX512_TARGET]] inline __m512 pick_sixteen_lanes(const float* column, __m512i index, std::uint32_t entries) {
  if (entries <= 16) return _mm512_maskz_permutexvar_ps(0xffff, index, _mm512_load_ps(column));
  if (entries <= 32) return _mm512_permutex2var_ps(_mm512_load_ps(column), index, _mm512_load_ps(column + 16));
  return _mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff, index, column, 4);
}

// The AVX-512 walks' gather of every triangle's corners into lanes, sixteen at once.
[[WAVETRACE_AVX512_TARGET]] inline void gather_corners_sixteen(const DecodedLeaf& decoded, TriangleLanes<16>& lanes) {
  const StripLayoutEntry& layout = *decoded.layout;
  const __m512i index_mask = _mm512_set1_epi32(63);  // lanes past the last triangle pick in bounds
  const __m512i first_slot =
      _mm512_maskz_cvtepu8_epi32(0xffff, _mm_loadu_si128(reinterpret_cast<const __m128i*>(layout.first_slot.data())));
  const float* slot_vertex = reinterpret_cast<const float*>(decoded.slot_vertex);  // permuted as bits
  for (int c = 0; c < 3; ++c) {
    __m512i vertex = _mm512_and_si512(_mm512_add_epi32(first_slot, _mm512_set1_epi32(c)), index_mask);
    if (decoded.header.indexed) {
      vertex = _mm512_and_si512(_mm512_castps_si512(pick_sixteen_lanes(slot_vertex, vertex, layout.slots)), index_mask);
    }
    for (int axis = 0; axis < 3; ++axis) {
      _mm512_store_ps(lanes.corner[c][axis], pick_sixteen_lanes(decoded.position[axis], vertex, decoded.header.vertex_count));
    }
  }
}
#endif

// Decodes the record at `record` (its decoded box `box`) into `scratch` and gathers its
// triangles' corners into `leaf`.
template <KernelIsa kIsa = KernelIsa::baseline, typename Probe>
[[gnu::always_inline]] inline void prepare_leaf(const std::byte* record, const GlobalGrid& grid, const Box& box,
                                                LeafTriangles& leaf, DecodedLeaf& scratch, Probe& probe) {
#if WAVETRACE_AVX2
  DecodedLeaf& decoded = scratch;
#else
  (void)scratch;
  DecodedLeaf& decoded = leaf.decoded;
#endif
  // Its first page announced before the decode reads it (paged in frames, where the probe
  // says), its size reported after, by the decode that finds it (a record ending on the next
  // page faults that page in, but in a frame, whose tail holds it).
  const std::byte* bytes = record;
  if constexpr (Probe::kRecords) bytes = probe.template resident_record<kMaxLeafRecordBytes>(record);
  decode_leaf<kIsa>(bytes, grid, snap_outward(grid, box), decoded);
  if constexpr (Probe::kRecords) probe.record_read(record, std::size_t(decoded.end() - bytes));
  leaf.identity = decoded.identity();
  leaf.layout = decoded.layout;
#if WAVETRACE_AVX512_DISPATCH
  if constexpr (kSixteenLanes<kIsa>) return gather_corners_sixteen(decoded, leaf.lanes);
#endif
#if WAVETRACE_AVX2
  const StripLayoutEntry& layout = *decoded.layout;
  const __m256i index_mask = _mm256_set1_epi32(63);  // lanes past the last triangle pick in bounds
  const int vertex_parts = lane_parts(decoded.header.vertex_count), slot_parts = lane_parts(layout.slots);
  const float* slot_vertex = reinterpret_cast<const float*>(decoded.slot_vertex);  // permuted as bits
  for (std::uint32_t base = 0; base < layout.triangles; base += 8) {
    __m128i first_bytes = _mm_setzero_si128();
    std::memcpy(&first_bytes, layout.first_slot.data() + base, 8);
    const __m256i first_slot = _mm256_cvtepu8_epi32(first_bytes);
    for (int c = 0; c < 3; ++c) {
      __m256i vertex = _mm256_and_si256(_mm256_add_epi32(first_slot, _mm256_set1_epi32(c)), index_mask);
      if (decoded.header.indexed) {
        vertex = _mm256_and_si256(_mm256_castps_si256(pick_lanes(slot_vertex, vertex, slot_parts)), index_mask);
      }
      for (int axis = 0; axis < 3; ++axis) {
        _mm256_store_ps(leaf.lanes.corner[c][axis] + base, pick_lanes(decoded.position[axis], vertex, vertex_parts));
      }
    }
  }
#endif
}

// Tests a prepared leaf's triangles against one ray; a hit that replaces `best` by the
// nearest-hit rule (nearest_hit.hpp) shrinks `tmax` to it (with kAnyHit, the first hit ends
// the test).
template <bool kAnyHit, KernelIsa kIsa = KernelIsa::baseline>
[[gnu::always_inline]] inline void test_leaf_triangles(const LeafTriangles& leaf, const WatertightRay& sheared,
                                                       float tmin, float& tmax, LeafHit& best) {
  const std::uint32_t triangles = leaf.layout->triangles;
  // False when the hit loses to `best`; else it becomes `best`.
  auto accept = [&](std::uint32_t k, const TriangleHit& hit) {
    if (!replaces_nearest(
            hit.t, tmax, best.found, [&] { return leaf.identity.triangle_id(k); }, [&] { return best.triangle_id(); })) {
      return false;
    }
    tmax = hit.t;
    best = {hit.t, hit.u, hit.v, leaf.identity, k, {leaf.corner(k, 0), leaf.corner(k, 1), leaf.corner(k, 2)}, true};
    return true;
  };
#if WAVETRACE_AVX2
  // Candidates of each pass are taken in triangle order against the shrinking tmax, exactly
  // as the scalar loop takes them (same hits, same t).
  constexpr std::uint32_t kPass = kSixteenLanes<kIsa> && WAVETRACE_SIXTEEN_LANES ? 16 : 8;
  for (std::uint32_t base = 0; base < triangles; base += kPass) {
    const std::uint32_t count = std::min<std::uint32_t>(kPass, triangles - base);
    WatertightLanes<kPass> result;
    intersect_watertight_lanes(sheared, leaf.lanes, (1u << count) - 1, tmin, tmax, result, int(base));
    for (unsigned pending = result.candidates | result.on_edge; pending != 0; pending &= pending - 1) {
      const int lane = std::countr_zero(pending);
      const std::uint32_t k = base + lane;
      TriangleHit hit;
      if (result.on_edge >> lane & 1u) {
        if (!intersect_watertight(sheared, leaf.corner(k, 0), leaf.corner(k, 1), leaf.corner(k, 2), tmin, tmax, hit)) {
          continue;
        }
      } else {
        if (result.t[lane] > tmax) continue;
        hit = {result.t[lane], result.u[lane], result.v[lane]};
      }
      if (!accept(k, hit)) continue;
      if constexpr (kAnyHit) return;
    }
  }
#else
  for (std::uint32_t k = 0; k < triangles; ++k) {
    TriangleHit hit;
    if (intersect_watertight(sheared, leaf.corner(k, 0), leaf.corner(k, 1), leaf.corner(k, 2), tmin, tmax, hit) &&
        accept(k, hit)) {
      if constexpr (kAnyHit) return;
    }
  }
#endif
}

// The leaves one walker decoded last, by record address, direct-mapped: coherent rays (a
// camera's neighbouring pixels, rays sorted by hit point) meet the same leaves one after
// another, and the decode is most of a leaf's cost. In-core walks only (NullProbe): a probed
// walk must read, and report, every record it tests, and a paged record's frame may be
// reused while its decoded copy is held. 128 entries of lanes alone (80 KB, one per batch
// call): against 32 entries that also held their decoded columns (55 KB), hmq:width=8 5-10%
// faster on the rooms' camera and diffuse rays and the same on the scans' (docs/
// measurements.md, "HMQ's decoded leaves as lanes alone"); with the columns, 128 (220 KB) had
// gained camera rays and lost diffuse ones ("Entry planes once a ray, and a larger cache of
// decoded leaves").
class DecodedLeafCache {
 public:
  static constexpr std::size_t kEntries = 128;

  template <KernelIsa kIsa, typename Probe>
  [[gnu::always_inline]] const LeafTriangles& leaf(const std::byte* record, const GlobalGrid& grid, const Box& box,
                                                   Probe& probe) {
    const std::size_t slot = (reinterpret_cast<std::uintptr_t>(record) >> 4) % kEntries;
    if (record_[slot] != record || Probe::kRecords) {
      prepare_leaf<kIsa>(record, grid, box, leaves_[slot], scratch_, probe);
      record_[slot] = Probe::kRecords ? nullptr : record;
    }
    return leaves_[slot];
  }

 private:
  const std::byte* record_[kEntries] = {};
  LeafTriangles leaves_[kEntries];
  DecodedLeaf scratch_;  // the columns a leaf is gathered from
};

// The leaf record at `record`, whose decoded box is `box`, against one ray (decoded through
// `cache`).
template <bool kAnyHit, KernelIsa kIsa = KernelIsa::baseline, typename Probe>
[[gnu::always_inline]] inline void test_leaf_record(const std::byte* record, const GlobalGrid& grid, const Box& box,
                                                    const WatertightRay& sheared, float tmin, float& tmax,
                                                    LeafHit& best, Probe& probe, DecodedLeafCache& cache) {
  test_leaf_triangles<kAnyHit, kIsa>(cache.template leaf<kIsa>(record, grid, box, probe), sheared, tmin, tmax, best);
}

// With kSurface (closest hits, whose corners test_leaf_record kept) also the point and normal.
template <bool kSurface>
inline void write_leaf_hit(const LeafHit& best, HitBatch& hits, std::uint32_t i) {
  if (!best.found) return hits.set_miss(i);
  const std::uint32_t code = best.corner_code();
  const float weight[3] = {1.0f - best.u - best.v, best.u, best.v};
  hits.set_hit(i, best.t, best.triangle_id(), weight[code / 3], weight[code % 3]);
  if constexpr (kSurface) set_surface_from_strip(hits, i, best.corner, code);
}

}  // namespace wavetrace::hmq
