// The byte layout of one Ray-Strip (Lauterbach et al., §4.1, Figure 5): a header, the
// implicit balanced spatial kd-tree over the strip, the strip's vertex indices and one
// record per triangle. Decoding needs nothing but this comment and the shared vertex array.
//
// A Ray-Strip of n triangles (1 <= n <= 65535) lists n + 2 vertices s[0 .. n+1]; triangle k
// has the corners (s[k], s[k+1], s[k+2]). Turns of the strip repeat a triangle (a swap
// vertex), so n counts those repeats too; a repeated triangle answers exactly as its first
// copy. Little-endian; a strip starts 4-byte aligned; N = ceil(n / 2) - 1 kd-tree nodes when
// n > 14, else N = 0: the AVX-512 walks test up to 14 triangles (16 vertices) in one pass of
// sixteen lanes, the AVX2 ones in up to three runs of eight (strip_traversal.hpp), and over so
// few triangles a tree cost more in descents and bytes than the runs it spared. The
// strip's frame F is the box of the top leaf that holds it (its float box in the binary top,
// its decoded box in the 8-wide one), which the owner knows when it encodes and traverses.
//
//   offset            size        field
//        0               2        n             uint16  triangles (repeats included)
//        2               1        widths        bit 0: vertex indices are uint16
//                                               bit 1: triangle records are uint16 (else uint32)
//                                               bit 2: vertex indices are uint8 (bit 0 clear)
//                                               neither bit 0 nor 2: vertex indices are uint32
//                                               bits 3-7: zero
//        3               1        zero
//        4               4        vertex_base   uint32  added to every stored vertex index
//        8               4        triangle_base uint32  added to every record's triangle delta
//       12             2 N       splits        per node, on its split axis a: uint8 q_max, uint8 q_min;
//                                               with step = (F.upper[a] - F.lower[a]) * (1.0f / 255.0f),
//                                               lower_child_max = fma(-q_max, step, F.upper[a]),
//                                               upper_child_min = fma(q_min, step, F.lower[a])
//                                               (rounded outward by the encoder through this arithmetic)
//   12 + 2N              N        node_bits     per node: bits 0-1 split axis (0 x, 1 y, 2 z),
//                                               bit 2 reverse, bits 3-7 zero
//   I = align(12 + 3N, W)         indices       (n + 2) x W bytes, W = 1, 2 or 4 (widths bits 0, 2):
//                                               s[i] = vertex_base + stored[i]
//   R = align(I + W(n + 2), V)    records       n x V bytes, V = 2 or 4 (widths bit 1):
//                                               record = (triangle - triangle_base) << 3 | corners
//   size = align(R + V n, 4)
//
// The kd-tree (only when n > 14). Leaves are pairs of triangles, leaf j = triangles {2j, 2j + 1} (the last leaf
// of an odd strip holds one); they are implicit. A node spans the leaves [a, a + c), c >= 2,
// and splits them into its first ceil(c / 2) leaves (the strip-first child) and the rest
// (the strip-second child), so the tree is balanced and needs no child pointers. Nodes are
// stored in pre-order: the root is node 0, the strip-first child of node i is node i + 1
// and the strip-second child is node i + ceil(c / 2) (a child with one leaf is not stored).
// On the split axis, the lower child's box ends at lower_child_max and the upper child's
// box starts at upper_child_min; every other face is the parent's (the strip's box is the
// top BVH leaf's box). The lower child is the strip-first one unless reverse is set. The
// axis is the one along which the two children's boxes overlap least (§4.1).
//
// Records. corners = 3 * c1 + c2, where c1 and c2 are the strip corners (0, 1 or 2 in
// (s[k], s[k+1], s[k+2])) of the mesh triangle's second and third vertex: barycentrics are
// reported in the mesh's corner order through them. uint16 records hold deltas below 2^13,
// uint32 records deltas below 2^29.
#pragma once

#include <cstddef>
#include <cstdint>
#include <cmath>
#include <cstring>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace::ray_strip {

inline constexpr std::size_t kHeaderBytes = 12;
inline constexpr std::uint32_t kMaxTriangles = 65535;
inline constexpr std::uint8_t kShortIndices = 1u << 0;
inline constexpr std::uint8_t kShortRecords = 1u << 1;
inline constexpr std::uint8_t kByteIndices = 1u << 2;
inline constexpr std::uint8_t kKnownWidths = kShortIndices | kShortRecords | kByteIndices;
// Strips of at most this many triangles carry no kd-tree (the comment above).
inline constexpr std::uint32_t kUntreedTriangles = 14;
inline constexpr std::uint8_t kAxisMask = 3u;
inline constexpr std::uint8_t kReverse = 1u << 2;
inline constexpr std::uint32_t kCornerBits = 3;
inline constexpr std::uint32_t kShortDeltaLimit = 1u << (16 - kCornerBits);
inline constexpr std::uint32_t kLongDeltaLimit = 1u << (32 - kCornerBits);

// `alignment` a power of two: a mask, not a division, since every strip a ray meets works its
// layout out again.
constexpr std::size_t align_up(std::size_t offset, std::size_t alignment) {
  return (offset + alignment - 1) & ~(alignment - 1);
}

constexpr std::uint32_t leaf_count(std::uint32_t triangles) { return (triangles + 1) / 2; }
constexpr bool has_tree(std::uint32_t triangles) { return triangles > kUntreedTriangles; }
constexpr std::uint32_t node_count(std::uint32_t triangles) { return has_tree(triangles) ? leaf_count(triangles) - 1 : 0; }
constexpr std::size_t index_bytes(std::uint8_t widths) {
  return (widths & kByteIndices) ? 1 : (widths & kShortIndices) ? 2 : 4;
}

// Where each part of a strip of n triangles starts, and its size (the formula above).
struct StripLayout {
  std::size_t splits, node_bits, indices, records, size;
};

constexpr StripLayout strip_layout(std::uint32_t triangles, std::uint8_t widths) {
  const std::size_t nodes = node_count(triangles);
  const std::size_t index_width = index_bytes(widths);
  const std::size_t record_bytes = (widths & kShortRecords) ? 2 : 4;
  StripLayout layout{};
  layout.splits = kHeaderBytes;
  layout.node_bits = kHeaderBytes + 2 * nodes;
  layout.indices = align_up(layout.node_bits + nodes, index_width);
  layout.records = align_up(layout.indices + index_width * (triangles + 2), record_bytes);
  layout.size = align_up(layout.records + record_bytes * triangles, 4);
  return layout;
}

// Read-only access to one encoded strip.
class StripView {
 public:
  explicit StripView(const std::byte* base) : base_(base) {
    std::uint16_t triangles;
    std::memcpy(&triangles, base, 2);
    triangles_ = triangles;
    widths_ = static_cast<std::uint8_t>(base[2]);
    std::memcpy(&vertex_base_, base + 4, 4);
    std::memcpy(&triangle_base_, base + 8, 4);
    layout_ = strip_layout(triangles_, widths_);
  }

  const std::byte* data() const { return base_; }
  std::uint32_t triangles() const { return triangles_; }
  std::size_t size() const { return layout_.size; }
  const StripLayout& layout() const { return layout_; }
  std::uint8_t widths() const { return widths_; }
  std::uint32_t vertex_base() const { return vertex_base_; }

  const std::uint8_t* split_steps(std::uint32_t node) const {
    return reinterpret_cast<const std::uint8_t*>(base_ + layout_.splits) + 2 * node;
  }
  std::uint8_t node_bits(std::uint32_t node) const { return static_cast<std::uint8_t>(base_[layout_.node_bits + node]); }

  std::uint32_t vertex(std::uint32_t i) const {
    const std::byte* indices = base_ + layout_.indices;
    if (widths_ & kByteIndices) return vertex_base_ + reinterpret_cast<const std::uint8_t*>(indices)[i];
    if (widths_ & kShortIndices) return vertex_base_ + reinterpret_cast<const std::uint16_t*>(indices)[i];
    return vertex_base_ + reinterpret_cast<const std::uint32_t*>(indices)[i];
  }
  std::size_t index_width() const { return index_bytes(widths_); }
  const void* vertex_address(std::uint32_t i) const { return base_ + layout_.indices + i * index_width(); }

  std::uint32_t record(std::uint32_t k) const {
    const std::byte* records = base_ + layout_.records;
    if (widths_ & kShortRecords) return reinterpret_cast<const std::uint16_t*>(records)[k];
    return reinterpret_cast<const std::uint32_t*>(records)[k];
  }
  const void* record_address(std::uint32_t k) const {
    return base_ + layout_.records + k * ((widths_ & kShortRecords) ? 2 : 4);
  }
  std::uint32_t triangle(std::uint32_t k) const { return triangle_base_ + (record(k) >> kCornerBits); }
  std::uint32_t corners(std::uint32_t k) const { return record(k) & ((1u << kCornerBits) - 1); }

 private:
  const std::byte* base_;
  std::uint32_t triangles_;
  std::uint8_t widths_;
  std::uint32_t vertex_base_;
  std::uint32_t triangle_base_;
  StripLayout layout_;
};

// A node's planes on its split axis a (see above), from the strip's frame.
struct SplitPlanes {
  float lower_child_max, upper_child_min;
};
inline float split_step(const Bounds3& frame, int axis) { return (frame.upper[axis] - frame.lower[axis]) * (1.0f / 255.0f); }
inline SplitPlanes decode_split(const std::uint8_t* steps, const Bounds3& frame, int axis) {
  const float step = split_step(frame, axis);
  return {std::fma(-float(steps[0]), step, frame.upper[axis]), std::fma(float(steps[1]), step, frame.lower[axis])};
}

}  // namespace wavetrace::ray_strip
