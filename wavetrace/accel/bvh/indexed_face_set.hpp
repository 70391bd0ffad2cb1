// The geometry a BVH traverses: an indexed face set, either the mesh's own arrays read in
// place, or a copy whose triangles follow a Morton curve of their centroids or the order
// the BVH's leaves list them (vertices renumbered by first use in both copies).
#pragma once

#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/memory/stored_array.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

class SectionSaver;
class SectionLoader;

// input: the mesh's arrays, leaves reach triangles through a 4-byte index per triangle.
// morton: a copy sorted along a Morton curve, leaves still index it.
// leaf: a copy in leaf order, so a leaf's triangles are contiguous and need no index.
enum class TriangleOrder { input, morton, leaf };
TriangleOrder parse_triangle_order(const std::string& text);  // "input" | "morton" | "leaf"
std::string to_string(TriangleOrder order);

class IndexedFaceSet {
 public:
  // `mesh` must outlive this object when order is input or leaf (leaf starts as input
  // until adopt_leaf_order is called).
  IndexedFaceSet(const TriangleMesh& mesh, TriangleOrder order);
  // Saved as "faces.positions" (float x, y, z per vertex), "faces.triangles" (uint32 x3 per
  // triangle) and "faces.input_id" (uint32 per triangle, empty in input order), and read
  // back in place; whatever order it was built in, a loaded face set owns its arrays.
  void save(SectionSaver& out) const;
  explicit IndexedFaceSet(SectionLoader& in);

  // Re-stores the triangles so that slot i holds what slot order[i] held before (a copy,
  // vertices renumbered by first use); input ids follow.
  void adopt_order(std::span<const std::uint32_t> order);

  const glm::vec3* positions() const { return positions_; }
  const glm::uvec3* triangles() const { return triangles_; }
  std::size_t vertex_count() const { return vertex_count_; }
  std::size_t triangle_count() const { return triangle_count_; }

  // The mesh's index of the triangle stored at `slot`.
  std::uint32_t input_id(std::uint32_t slot) const { return input_id_.empty() ? slot : input_id_[slot]; }
  // Where input_id reads, for probes; null when the face set is in input order.
  const std::uint32_t* input_id_address(std::uint32_t slot) const {
    return input_id_.empty() ? nullptr : input_id_.data() + slot;
  }

  // The SAH builder's references: slot t's box and id t (parallel).
  LargeArray<SahReference> triangle_references() const;
  std::size_t geometry_bytes() const { return vertex_count_ * sizeof(glm::vec3) + triangle_count_ * sizeof(glm::uvec3); }
  std::size_t id_map_bytes() const { return input_id_.size() * sizeof(std::uint32_t); }
  std::size_t build_scratch_bytes() const { return build_scratch_bytes_; }
  std::vector<std::span<const std::byte>> spans() const;

 private:
  StoredArray<glm::vec3> owned_positions_;
  StoredArray<glm::uvec3> owned_triangles_;
  StoredArray<std::uint32_t> input_id_;  // empty for input order
  const glm::vec3* positions_ = nullptr;
  const glm::uvec3* triangles_ = nullptr;
  std::size_t vertex_count_ = 0;
  std::size_t triangle_count_ = 0;
  std::size_t build_scratch_bytes_ = 0;
};

}  // namespace wavetrace
