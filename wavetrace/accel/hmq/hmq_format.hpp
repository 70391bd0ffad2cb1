// The byte layout of HMQ's compressed part (Segovia and Ernst 2010, §4–6, Figure 4): blocks
// of 4-byte quantized nodes, forward slots to other blocks, and leaf records interleaved
// after each block. All little-endian; a block starts 4-byte aligned.
//
// Block (at a word offset from the start of the block array):
//   offset     size   field
//        0        1   node_slots n      (1 .. 64)
//        1        1   forward_slots f   (n + f <= 64)
//        2        1   leaves l
//        3        1   zero
//        4       4n   node slots 0 .. n-1 (below)
//   4 + 4n       4f   forward slots: uint32 word offset of another block from the block
//                     array's start; forward slot j is addressed as slot n + j
//   4 + 4(n+f)   2l   leaf offsets: uint16 byte offset of leaf record i from the block start
//   ...               leaf records, byte-aligned, one after another; the block ends 4-aligned
//
// Node slot, a uint32:
//   bits  0-11   lower[x], lower[y], lower[z]: 4 bits each, child.lower = parent.lower + q * step
//   bits 12-23   upper[x], upper[y], upper[z]: 4 bits each, child.upper = parent.upper - q * step
//                (step = (parent.upper - parent.lower) / 16 per axis, float arithmetic exactly
//                as decode_child_box below; the encoder rounds outward)
//   bits 24-29   index: inner node: its children are slots index and index + 1 of this block,
//                or, when index >= n, the first two node slots of the block forward slot
//                index - n points to; leaf: the leaf's number in this block's leaf offsets
//   bit  30      1: inner node, 0: leaf
//   bit  31      zero
// A block's first one or two slots are the roots of its treelet: the two children of the
// node that forwarded to it, or, for the block under a top-BVH leaf, that leaf's one or two
// roots (the top leaf's `count` says which) with the top leaf's float box as their parent.
//
// Leaf record (its box is its node's decoded box, re-snapped outward to the global grid:
// lines g_lower = floor, g_upper = ceil; never stored): one bit string (packed_stream.hpp),
// starting at a byte, ceil(bits / 8) bytes long, the last byte's spare bits zero:
//   bits  0-8    strip table entry (strip_table.hpp): the triangles and their slots
//   bit   9      1: indexed strips (vertices stored once, slots index them);
//                0: strips (slot i is vertex i)
//   bits 10-15   vertex count v (strips: the entry's slot count)
//   bits 16-30   bits per axis of the vertex offsets, 5 bits each: bx, by, bz
//   bits 31-35   triangle id delta bits bt (0 .. 31)
//   bits 36-40   the id base's bits less one, bb - 1 (bb 1 .. 32)
//   bits 41 ..   the triangle id base, bb bits
//   then the streams, each from the bit after the one before:
//     x offsets   v values of 1 + bx bits: offset << 1 | from_upper; grid line = from_upper ?
//                 g_upper.x - offset : g_lower.x + offset (the min-max trick, §4.1)
//     y, z        the same with by, bz
//     indices     (indexed strips) slot count values of bi bits, bi the bit width of v - 1:
//                 the vertex of each slot
//     ids         t values of bt bits: triangle k is mesh triangle base + id[k]
//     corners     t values of 3 bits: 3 c1 + c2, the corners (0, 1, 2 of the strip triangle)
//                 of the mesh triangle's second and third vertex, for barycentrics
//   A vertex is the global grid point of its three lines, in floats: origin + line * cell.
// (The paper's records start each stream at a byte, in groups of values to a quad-word; see
// packed_stream.hpp for why these do not.)
#pragma once

#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <glm/vec3.hpp>

namespace wavetrace::hmq {

inline constexpr std::uint32_t kMaxBlockSlots = 64;
inline constexpr std::uint32_t kInnerBit = 1u << 30;
inline constexpr std::uint32_t kBlockHeaderBytes = 4;
inline constexpr std::uint32_t kLeafHeaderBits = 41;
// The bytes read_leaf_header loads: the header and the widest id base, as two 8-byte loads.
inline constexpr std::size_t kLeafHeaderReadBytes = 13;
// No leaf record, with the slack its decode reads past it, is longer: the header's fields
// bound it. 41 header bits and a 32-bit id base; three offset streams of at most 63 vertices
// of 32 bits (6,048 bits); indices of at most 42 slots (14 one-triangle strips) of 6 bits
// (252); ids of 14 triangles of 31 bits (434); corners of 14 of 3 bits (42): 857 bytes, and 7
// read past the last: 864.
// A paged walk reads a record from a frame whose tail holds this much of the next page.
inline constexpr std::size_t kMaxLeafRecordBytes = 1024;

struct Box {
  glm::vec3 lower, upper;
};

inline bool is_inner(std::uint32_t node) { return (node & kInnerBit) != 0; }
inline std::uint32_t node_index(std::uint32_t node) { return (node >> 24) & 63u; }

// The child's box from its parent's and its 24 bits; the encoder uses this very function.
inline Box decode_child_box(const Box& parent, std::uint32_t node) {
  Box child;
  for (int axis = 0; axis < 3; ++axis) {
    const float step = (parent.upper[axis] - parent.lower[axis]) * 0.0625f;
    child.lower[axis] = parent.lower[axis] + float((node >> (4 * axis)) & 15u) * step;
    child.upper[axis] = parent.upper[axis] - float((node >> (12 + 4 * axis)) & 15u) * step;
  }
  return child;
}

struct LeafHeader {
  std::uint32_t entry, vertex_count, id_bits, id_base;
  std::uint32_t index_bits;   // indexed strips: the bit width of vertex_count - 1; else 0
  std::uint32_t stream_bit;   // where the x offsets start: after the header and the id base
  bool indexed;
  std::uint32_t axis_bits[3];
};

// Reads kLeafHeaderReadBytes from `record`: past a short record's end, within an array's slack.
inline LeafHeader read_leaf_header(const std::byte* record) {
  std::uint64_t bits, base_bits;
  std::memcpy(&bits, record, 8);
  std::memcpy(&base_bits, record + 5, 8);  // bit 40 of the record is this word's bit 0
  LeafHeader header;
  header.entry = bits & 511u;
  header.indexed = (bits >> 9) & 1u;
  header.vertex_count = (bits >> 10) & 63u;
  for (int axis = 0; axis < 3; ++axis) header.axis_bits[axis] = (bits >> (16 + 5 * axis)) & 31u;
  header.id_bits = (bits >> 31) & 31u;
  const std::uint32_t base_width = ((bits >> 36) & 31u) + 1;
  header.id_base = static_cast<std::uint32_t>((base_bits >> 1) & ((std::uint64_t{1} << base_width) - 1));
  header.index_bits = header.indexed ? std::uint32_t(std::bit_width(header.vertex_count - 1)) : 0u;
  header.stream_bit = kLeafHeaderBits + base_width;
  return header;
}

}  // namespace wavetrace::hmq
