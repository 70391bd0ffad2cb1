// Morton reordering of an indexed face set and per-triangle bounds.
#include "accel/bvh/indexed_face_set.hpp"

#include <limits>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include <glm/common.hpp>

#include "kernels/morton.hpp"

namespace wavetrace {

TriangleOrder parse_triangle_order(const std::string& text) {
  if (text == "input") return TriangleOrder::input;
  if (text == "morton") return TriangleOrder::morton;
  throw std::invalid_argument("unknown triangle order '" + text + "' (input, morton)");
}

std::string to_string(TriangleOrder order) { return order == TriangleOrder::morton ? "morton" : "input"; }

IndexedFaceSet::IndexedFaceSet(const TriangleMesh& mesh, TriangleOrder order)
    : vertex_count_(mesh.vertex_count()), triangle_count_(mesh.triangle_count()) {
  if (order == TriangleOrder::input) {
    positions_ = mesh.positions.data();
    triangles_ = mesh.triangles.data();
    return;
  }
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

  owned_triangles_.resize(triangle_count_);
  input_id_.resize(triangle_count_);
  std::vector<std::uint32_t> new_vertex(mesh.vertex_count(), std::numeric_limits<std::uint32_t>::max());
  owned_positions_.reserve(mesh.vertex_count() + 1);
  for (std::size_t slot = 0; slot < keys.size(); ++slot) {
    const std::uint32_t t = keys[slot].second;
    input_id_[slot] = t;
    glm::uvec3 tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& mapped = new_vertex[tri[k]];
      if (mapped == std::numeric_limits<std::uint32_t>::max()) {
        mapped = static_cast<std::uint32_t>(owned_positions_.size());
        owned_positions_.push_back(mesh.positions[tri[k]]);
      }
      tri[k] = mapped;
    }
    owned_triangles_[slot] = tri;
  }
  positions_ = owned_positions_.data();
  triangles_ = owned_triangles_.data();
  vertex_count_ = owned_positions_.size();
  build_scratch_bytes_ = keys.size() * sizeof(keys[0]) + new_vertex.size() * sizeof(std::uint32_t);
}

std::vector<Bounds3> IndexedFaceSet::triangle_bounds() const {
  std::vector<Bounds3> bounds(triangle_count_);
  tbb::parallel_for(std::size_t{0}, triangle_count_, [&](std::size_t t) {
    const glm::uvec3& tri = triangles_[t];
    Bounds3 b;
    b.extend(positions_[tri.x]);
    b.extend(positions_[tri.y]);
    b.extend(positions_[tri.z]);
    bounds[t] = b;
  });
  return bounds;
}

std::vector<std::span<const std::byte>> IndexedFaceSet::spans() const {
  return {std::as_bytes(std::span(triangles_, triangle_count_)), std::as_bytes(std::span(positions_, vertex_count_))};
}

}  // namespace wavetrace
