// HMQ leaf records (hmq_format.hpp): encoding a leaf's triangles as the smaller of strips
// or indexed strips over quantized vertices, and decoding one on the fly during traversal.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "accel/hmq/global_grid.hpp"
#include "accel/hmq/hmq_format.hpp"
#include "accel/hmq/packed_stream.hpp"
#include "accel/hmq/strip_table.hpp"
#include "scene/triangle_mesh.hpp"

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
inline GridBox snap_outward(const GlobalGrid& grid, const Box& box) {
  GridBox snapped;
  for (int axis = 0; axis < 3; ++axis) {
    snapped.lower[axis] = grid.floor_line(box.lower[axis], axis);
    snapped.upper[axis] = grid.ceil_line(box.upper[axis], axis);
  }
  return snapped;
}

// Appends the record of `triangles` (1 .. 14 mesh triangle ids) to `out`.
void encode_leaf(const QuantizedMesh& quantized, std::span<const std::uint32_t> triangles, const GridBox& box,
                 std::vector<std::byte>& out);

// A decoded leaf: vertex positions per slot, ready for triangle tests.
struct DecodedLeaf {
  LeafHeader header;
  const StripLayoutEntry* layout;
  glm::vec3 slot_position[64];
  const std::byte* ids;      // the id stream
  const std::byte* corners;  // the corner stream

  std::uint32_t triangle_id(std::uint32_t k) const {
    std::uint32_t delta[kMaxLeafTriangles];
    read_stream(ids, header.id_bits, k + 1, delta);
    return header.id_base + delta[k];
  }
  std::uint32_t corner_code(std::uint32_t k) const {
    std::uint32_t codes[kMaxLeafTriangles];
    read_stream(corners, 3, k + 1, codes);
    return codes[k];
  }
};

inline void decode_leaf(const std::byte* record, const GlobalGrid& grid, const GridBox& box, DecodedLeaf& leaf) {
  leaf.header = read_leaf_header(record);
  leaf.layout = &StripTable::instance().entry(leaf.header.entry);
  const std::uint32_t vertices = leaf.header.vertex_count;
  const std::byte* data = record + kLeafHeaderBytes;
  std::uint32_t values[3][64];
  for (int axis = 0; axis < 3; ++axis) {
    const std::uint32_t bits = leaf.header.axis_bits[axis] + 1;
    read_stream(data, bits, vertices, values[axis]);
    data += stream_bytes(bits, vertices);
  }
  glm::vec3 vertex[64];
  for (std::uint32_t i = 0; i < vertices; ++i) {
    glm::ivec3 line;
    for (int axis = 0; axis < 3; ++axis) {
      const std::uint32_t value = values[axis][i];
      const int offset = static_cast<int>(value >> 1);
      line[axis] = (value & 1u) ? box.upper[axis] - offset : box.lower[axis] + offset;
    }
    vertex[i] = grid.point(line);
  }
  const std::uint32_t slots = leaf.layout->slots;
  if (leaf.header.indexed) {
    std::uint32_t index[64];
    read_stream(data, leaf.header.index_bits, slots, index);
    data += stream_bytes(leaf.header.index_bits, slots);
    for (std::uint32_t s = 0; s < slots; ++s) leaf.slot_position[s] = vertex[index[s]];
  } else {
    for (std::uint32_t s = 0; s < slots; ++s) leaf.slot_position[s] = vertex[s];
  }
  const std::uint32_t triangles = leaf.layout->triangles;
  leaf.ids = data;
  leaf.corners = data + stream_bytes(leaf.header.id_bits, triangles);
}

// Bytes the record at `record` occupies (for tests and statistics).
std::size_t leaf_record_bytes(const std::byte* record);

}  // namespace wavetrace::hmq
