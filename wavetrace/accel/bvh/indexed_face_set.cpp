// Morton reordering of an indexed face set and per-triangle bounds.
#include "wavetrace/accel/bvh/indexed_face_set.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <glm/common.hpp>

#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/morton.hpp"

namespace wavetrace {

TriangleOrder parse_triangle_order(const std::string& text) {
  if (text == "input") return TriangleOrder::input;
  if (text == "morton") return TriangleOrder::morton;
  if (text == "leaf") return TriangleOrder::leaf;
  throw std::invalid_argument("unknown triangle order '" + text + "' (input, morton, leaf)");
}

std::string to_string(TriangleOrder order) {
  switch (order) {
    case TriangleOrder::morton: return "morton";
    case TriangleOrder::leaf: return "leaf";
    default: return "input";
  }
}

IndexedFaceSet::IndexedFaceSet(const TriangleMesh& mesh, TriangleOrder order)
    : positions_(mesh.positions.data()),
      triangles_(mesh.triangles.data()),
      vertex_count_(mesh.vertex_count()),
      triangle_count_(mesh.triangle_count()) {
  if (order != TriangleOrder::morton) return;
  const Bounds3 bounds = mesh.bounds();
  const glm::vec3 extent = glm::max(bounds.extent(), glm::vec3(1e-30f));
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(triangle_count_);
  tbb::parallel_for(std::size_t{0}, triangle_count_, [&](std::size_t t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::vec3 centroid = (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0f;
    const glm::vec3 unit = glm::clamp((centroid - bounds.lower) / extent, 0.0f, 1.0f);
    const auto quantize = [](float x) { return static_cast<std::uint64_t>(x * 1048575.0f); };  // 20 bits per axis
    keys[t] = {morton3d_encode(quantize(unit.x), quantize(unit.y), quantize(unit.z)), static_cast<std::uint32_t>(t)};
  });
  tbb::parallel_sort(keys.begin(), keys.end());
  std::vector<std::uint32_t> sorted(triangle_count_);
  for (std::size_t slot = 0; slot < keys.size(); ++slot) sorted[slot] = keys[slot].second;
  build_scratch_bytes_ = keys.size() * sizeof(keys[0]);
  adopt_order(sorted);
}

void IndexedFaceSet::adopt_order(std::span<const std::uint32_t> order) {
  LargeArray<glm::vec3> positions;
  LargeArray<glm::uvec3> triangles(triangle_count_);
  LargeArray<std::uint32_t> input_id(triangle_count_);
  std::vector<std::uint32_t> new_vertex(vertex_count_, std::numeric_limits<std::uint32_t>::max());
  positions.reserve(vertex_count_ + 1);
  for (std::size_t slot = 0; slot < triangle_count_; ++slot) {
    const std::uint32_t from = order[slot];
    input_id[slot] = this->input_id(from);
    glm::uvec3 tri = triangles_[from];
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& mapped = new_vertex[tri[k]];
      if (mapped == std::numeric_limits<std::uint32_t>::max()) {
        mapped = static_cast<std::uint32_t>(positions.size());
        positions.push_back(positions_[tri[k]]);
      }
      tri[k] = mapped;
    }
    triangles[slot] = tri;
  }
  build_scratch_bytes_ = std::max(build_scratch_bytes_, new_vertex.size() * sizeof(std::uint32_t) + geometry_bytes() +
                                                            input_id_.size() * sizeof(std::uint32_t));
  owned_positions_ = StoredArray<glm::vec3>(std::move(positions));
  owned_triangles_ = StoredArray<glm::uvec3>(std::move(triangles));
  input_id_ = StoredArray<std::uint32_t>(std::move(input_id));
  positions_ = owned_positions_.data();
  triangles_ = owned_triangles_.data();
  vertex_count_ = owned_positions_.size();
}

void IndexedFaceSet::save(SectionSaver& out) const {
  SectionWriter& writer = out.writer();
  // Positions keep the mesh's spare vertex of read slack: the section's padding provides it.
  writer.add_array(out.prefix() + "faces.positions", std::span(positions_, vertex_count_));
  writer.add_array(out.prefix() + "faces.triangles", std::span(triangles_, triangle_count_));
  out.array("faces.input_id", input_id_);
}

IndexedFaceSet::IndexedFaceSet(SectionLoader& in) {
  in.array("faces.positions", owned_positions_);
  in.array("faces.triangles", owned_triangles_);
  in.array("faces.input_id", input_id_);
  positions_ = owned_positions_.data();
  triangles_ = owned_triangles_.data();
  vertex_count_ = owned_positions_.size();
  triangle_count_ = owned_triangles_.size();
  if (!input_id_.empty() && input_id_.size() != triangle_count_) {
    in.fail("faces.input_id", "does not have one id per triangle");
  }
  const glm::uvec3* const end = triangles_ + triangle_count_;
  const glm::uvec3* const bad = std::find_if(triangles_, end, [&](const glm::uvec3& corners) {
    return corners.x >= vertex_count_ || corners.y >= vertex_count_ || corners.z >= vertex_count_;
  });
  if (bad != end) in.fail("faces.triangles", "names a vertex that does not exist");
}

LargeArray<SahReference> IndexedFaceSet::triangle_references() const {
  LargeArray<SahReference> references(triangle_count_);
  tbb::parallel_for(std::size_t{0}, triangle_count_, [&](std::size_t t) {
    const glm::uvec3& tri = triangles_[t];
    Bounds3 b;
    b.extend(positions_[tri.x]);
    b.extend(positions_[tri.y]);
    b.extend(positions_[tri.z]);
    references[t] = {b, static_cast<std::uint32_t>(t), 0};
  });
  return references;
}

std::vector<std::span<const std::byte>> IndexedFaceSet::spans() const {
  std::vector<std::span<const std::byte>> spans = {std::as_bytes(std::span(triangles_, triangle_count_)),
                                                   std::as_bytes(std::span(positions_, vertex_count_))};
  // A reordered copy maps hits back to the mesh's numbering: traversal reads that too.
  if (!input_id_.empty()) spans.push_back(std::as_bytes(std::span(input_id_.data(), input_id_.size())));
  return spans;
}

}  // namespace wavetrace
