// HMQ leaf records (hmq_format.hpp): encoding a leaf's triangles as the smaller of strips
// or indexed strips over quantized vertices, and decoding one on the fly during traversal.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2

#include <cstdint>
#include <span>
#include <vector>

#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/accel/hmq/packed_stream.hpp"
#include "wavetrace/accel/hmq/strip_table.hpp"
#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

namespace wavetrace::hmq {

// What the encoder reads: the mesh's triangles and every vertex's global grid point.
struct QuantizedMesh {
  const TriangleMesh* mesh;
  std::vector<glm::ivec3> lines;  // per mesh vertex
};

// The leaf's grid box: its decoded box re-snapped outward.
struct GridBox {
  glm::ivec3 lower, upper;
};
// Every leaf a ray visits is re-snapped: with AVX2 the six lines in two SSE passes, with
// GlobalGrid::floor_line's and ceil_line's float operations and clamp (NaN included: maxps
// returns its second operand, -2^30, as to_line does), so the lines are the encoder's.
inline GridBox snap_outward(const GlobalGrid& grid, const Box& box) {
  GridBox snapped;
#if WAVETRACE_AVX2
  const __m128 origin = _mm_setr_ps(grid.origin.x, grid.origin.y, grid.origin.z, 0.0f);
  const __m128 inverse_cell = _mm_setr_ps(grid.inverse_cell.x, grid.inverse_cell.y, grid.inverse_cell.z, 0.0f);
  const __m128 limit = _mm_set1_ps(1073741824.0f);  // 2^30
  auto lines = [&](const glm::vec3& corner, auto round, glm::ivec3& out) {
    const __m128 scaled = _mm_mul_ps(_mm_sub_ps(_mm_setr_ps(corner.x, corner.y, corner.z, 0.0f), origin), inverse_cell);
    const __m128 clamped = _mm_min_ps(_mm_max_ps(round(scaled), _mm_sub_ps(_mm_setzero_ps(), limit)), limit);
    alignas(16) std::int32_t line[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(line), _mm_cvttps_epi32(clamped));
    out = {line[0], line[1], line[2]};
  };
  lines(box.lower, [](__m128 x) { return _mm_floor_ps(x); }, snapped.lower);
  lines(box.upper, [](__m128 x) { return _mm_ceil_ps(x); }, snapped.upper);
#else
  for (int axis = 0; axis < 3; ++axis) {
    snapped.lower[axis] = grid.floor_line(box.lower[axis], axis);
    snapped.upper[axis] = grid.ceil_line(box.upper[axis], axis);
  }
#endif
  return snapped;
}

// A leaf's triangles and their vertices lie scattered over the mesh (the SAH reordered them),
// and encoding waited on them, a cache miss a corner: an encoder of a run of leaves fetches
// the corners of a leaf a few ahead, then the grid points of a nearer one (the corners are
// in cache by then).
inline void prefetch_leaf_corners(const QuantizedMesh& quantized, std::span<const std::uint32_t> triangles) {
  for (const std::uint32_t t : triangles) __builtin_prefetch(&quantized.mesh->triangles[t]);
}
inline void prefetch_leaf_grid_points(const QuantizedMesh& quantized, std::span<const std::uint32_t> triangles) {
  for (const std::uint32_t t : triangles) {
    const glm::uvec3& corners = quantized.mesh->triangles[t];
    for (int c = 0; c < 3; ++c) __builtin_prefetch(&quantized.lines[corners[c]]);
  }
}

// Appends the record of `triangles` (1 .. 14 mesh triangle ids) to `out`. Returns the bits of
// it that name the mesh's triangles and corners (the id base, ids and corner codes), for the
// statistics' split of a record's bytes.
std::size_t encode_leaf(const QuantizedMesh& quantized, std::span<const std::uint32_t> triangles, const GridBox& box,
                        LargeArray<std::byte>& out);

// Where a record names its mesh triangles and their corners: all a hit keeps of its leaf.
struct LeafIdentity {
  const std::byte* record = nullptr;
  std::uint32_t id_base = 0, id_bits = 0;
  std::uint32_t ids_bit = 0, corners_bit = 0;  // where the id and corner streams start

  std::uint32_t triangle_id(std::uint32_t k) const { return id_base + read_value(record, ids_bit + k * id_bits, id_bits); }
  std::uint32_t corner_code(std::uint32_t k) const { return read_value(record, corners_bit + 3 * k, 3); }
};

// A decoded leaf: vertex positions in columns (SoA, ready to gather into triangle lanes)
// and which vertex each strip slot holds.
struct DecodedLeaf {
  LeafHeader header;
  const StripLayoutEntry* layout;
  alignas(64) float position[3][64];  // per axis, per vertex; rows aligned for 16-lane loads
  alignas(64) std::uint32_t slot_vertex[64];  // indexed strips: the vertex of each slot; else unused
  const std::byte* record;
  std::uint32_t ids_bit;      // where the id stream starts in the record
  std::uint32_t corners_bit;  // where the corner stream starts

  // One past the record's last byte: its corner stream ends it.
  const std::byte* end() const { return record + (corners_bit + stream_bits(3, layout->triangles) + 7) / 8; }
  std::uint32_t vertex_of_slot(std::uint32_t slot) const { return header.indexed ? slot_vertex[slot] : slot; }
  glm::vec3 slot_position(std::uint32_t slot) const {
    const std::uint32_t v = vertex_of_slot(slot);
    return {position[0][v], position[1][v], position[2][v]};
  }
  LeafIdentity identity() const { return {record, header.id_base, header.id_bits, ids_bit, corners_bit}; }
  std::uint32_t triangle_id(std::uint32_t k) const { return identity().triangle_id(k); }
  std::uint32_t corner_code(std::uint32_t k) const { return identity().corner_code(k); }
};

#if WAVETRACE_AVX512_DISPATCH
// Whether a walk of this kernel set decodes and tests a leaf sixteen lanes at a time.
template <KernelIsa kIsa>
inline constexpr bool kSixteenLanes = kIsa == KernelIsa::avx512;

// One axis of decode_leaf's positions, sixteen vertices at a time (the same operations).
[[WAVETRACE_AVX512_TARGET]] inline void decode_axis_sixteen(const std::byte* data, std::uint32_t first_bit,
                                                            std::uint32_t bits, std::uint32_t vertices, int lower,
                                                            int upper, float origin, float cell, float* position) {
  using SixteenI32 = std::int32_t __attribute__((vector_size(64)));
  using SixteenF32 = float __attribute__((vector_size(64)));
  for (std::uint32_t first = 0; first < vertices; first += 16) {
    const SixteenU32 value = read_stream_sixteen(data, first_bit, bits, first, vertices);
    const SixteenU32 offset = value >> 1u;
    // In unsigned arithmetic, as the scalar decode: the adds and subtracts wrap modulo 2^32.
    const SixteenU32 line = (value & 1u) != 0u ? std::uint32_t(upper) - offset : std::uint32_t(lower) + offset;
    const SixteenF32 position_lanes = origin + __builtin_convertvector(SixteenI32(line), SixteenF32) * cell;
    std::memcpy(position + first, &position_lanes, sizeof(position_lanes));
  }
}

// The slots' vertex indices of an indexed record, sixteen at a time.
[[WAVETRACE_AVX512_TARGET]] inline void decode_indices_sixteen(const std::byte* data, std::uint32_t first_bit,
                                                               std::uint32_t bits, std::uint32_t slots,
                                                               std::uint32_t* slot_vertex) {
  for (std::uint32_t first = 0; first < slots; first += 16) {
    const SixteenU32 vertex = read_stream_sixteen(data, first_bit, bits, first, slots);
    std::memcpy(slot_vertex + first, &vertex, sizeof(vertex));
  }
}
#else
template <KernelIsa>
inline constexpr bool kSixteenLanes = false;
#endif

// Vertex v's grid line on an axis is the leaf box's plane its offset counts from (the
// min-max trick), and its position the grid point of that line: origin + line * cell, the
// float operations of GlobalGrid::point. With AVX2, eight vertices at a time straight from
// the record (read_stream_lanes), sixteen in the AVX-512 walks, the columns' lanes past the
// last vertex left unspecified.
template <KernelIsa kIsa = KernelIsa::baseline>
inline void decode_leaf(const std::byte* record, const GlobalGrid& grid, const GridBox& box, DecodedLeaf& leaf) {
  leaf.header = read_leaf_header(record);
  leaf.layout = &StripTable::instance().entry(leaf.header.entry);
  leaf.record = record;
  const std::uint32_t vertices = leaf.header.vertex_count;
  std::uint32_t bit = leaf.header.stream_bit;
  for (int axis = 0; axis < 3; ++axis) {
    const std::uint32_t bits = leaf.header.axis_bits[axis] + 1;
    const int lower = box.lower[axis], upper = box.upper[axis];
    const float origin = grid.origin[axis], cell = grid.cell[axis];
    float* position = leaf.position[axis];
    const std::uint32_t first_bit = bit;
    bit += bits * vertices;
#if WAVETRACE_AVX512_DISPATCH
    if constexpr (kSixteenLanes<kIsa>) {
      if (bits <= kLaneStreamBits) {
        decode_axis_sixteen(record, first_bit, bits, vertices, lower, upper, origin, cell, position);
        continue;
      }
    }
#endif
#if WAVETRACE_AVX2
    if (bits <= kLaneStreamBits) {
      for (std::uint32_t first = 0; first < vertices; first += 8) {
        const __m256i value = read_stream_lanes(record, first_bit, bits, first, vertices);
        // In unsigned arithmetic, as below: the lanes' adds and subtracts wrap modulo 2^32.
        const __m256i offset = _mm256_srli_epi32(value, 1);
        const __m256i from_upper = _mm256_cmpeq_epi32(_mm256_and_si256(value, _mm256_set1_epi32(1)), _mm256_set1_epi32(1));
        const __m256i line = _mm256_blendv_epi8(_mm256_add_epi32(_mm256_set1_epi32(lower), offset),
                                                _mm256_sub_epi32(_mm256_set1_epi32(upper), offset), from_upper);
        _mm256_store_ps(position + first, _mm256_add_ps(_mm256_set1_ps(origin),
                                                        _mm256_mul_ps(_mm256_cvtepi32_ps(line), _mm256_set1_ps(cell))));
      }
      continue;
    }
#endif
    alignas(32) std::uint32_t values[64];
    read_stream(record, first_bit, bits, vertices, values);
    for (std::uint32_t i = 0; i < vertices; ++i) {
      // In unsigned arithmetic (C++20 converts back modulo 2^32): the same lines for every
      // record the encoder writes, and no signed overflow for one a crafted file holds.
      const std::uint32_t offset = values[i] >> 1;
      const int line = static_cast<int>((values[i] & 1u) ? std::uint32_t(upper) - offset : std::uint32_t(lower) + offset);
      position[i] = origin + float(line) * cell;
    }
  }
  const std::uint32_t slots = leaf.layout->slots;
  if (leaf.header.indexed) {
    const std::uint32_t bits = leaf.header.index_bits;
#if WAVETRACE_AVX512_DISPATCH
    if (kSixteenLanes<kIsa> && bits != 0 && bits <= kLaneStreamBits) {
      decode_indices_sixteen(record, bit, bits, slots, leaf.slot_vertex);
    } else
#endif
    {
#if WAVETRACE_AVX2
      if (bits != 0 && bits <= kLaneStreamBits) {
        for (std::uint32_t first = 0; first < slots; first += 8) {
          _mm256_store_si256(reinterpret_cast<__m256i*>(leaf.slot_vertex + first),
                             read_stream_lanes(record, bit, bits, first, slots));
        }
      } else {
        read_stream(record, bit, bits, slots, leaf.slot_vertex);
      }
#else
      read_stream(record, bit, bits, slots, leaf.slot_vertex);
#endif
    }
    bit += bits * slots;
  }
  leaf.ids_bit = bit;
  leaf.corners_bit = bit + leaf.header.id_bits * leaf.layout->triangles;
}

// Bits a record of this header and strip layout occupies: its header, id base and streams.
inline std::size_t leaf_record_bits(const LeafHeader& header, const StripLayoutEntry& layout) {
  std::size_t bits = header.stream_bit;
  for (int axis = 0; axis < 3; ++axis) bits += stream_bits(header.axis_bits[axis] + 1, header.vertex_count);
  if (header.indexed) bits += stream_bits(header.index_bits, layout.slots);
  return bits + stream_bits(header.id_bits, layout.triangles) + stream_bits(3, layout.triangles);
}
inline std::size_t leaf_record_bytes(const LeafHeader& header, const StripLayoutEntry& layout) {
  return (leaf_record_bits(header, layout) + 7) / 8;
}

// Bytes the record at `record` occupies (for tests and statistics); reads its header's
// kLeafHeaderReadBytes.
std::size_t leaf_record_bytes(const std::byte* record);

}  // namespace wavetrace::hmq
