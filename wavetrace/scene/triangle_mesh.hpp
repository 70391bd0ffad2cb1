// The indexed triangle mesh every accelerator is built from: float positions, 32-bit
// indices, an optional material index per triangle.
#pragma once

#include <cstddef>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include <glm/common.hpp>
#include <glm/vec3.hpp>

namespace wavetrace {

// Every error in scene input: the message names the file or object and the problem.
class SceneError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

struct Bounds3 {
  glm::vec3 lower{std::numeric_limits<float>::infinity()};
  glm::vec3 upper{-std::numeric_limits<float>::infinity()};

  bool empty() const { return lower.x > upper.x; }
  // Inline: builders call these in their innermost loops.
  void extend(const glm::vec3& point) {
    lower = glm::min(lower, point);
    upper = glm::max(upper, point);
  }
  void extend(const Bounds3& other) {
    lower = glm::min(lower, other.lower);
    upper = glm::max(upper, other.upper);
  }
  glm::vec3 extent() const { return upper - lower; }
  glm::vec3 center() const { return (lower + upper) * 0.5f; }
  float diagonal() const;
  bool operator==(const Bounds3&) const = default;
};

struct TriangleMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  std::vector<std::uint32_t> material_of_triangle;  // empty: every triangle uses material 0

  std::size_t triangle_count() const { return triangles.size(); }
  std::size_t vertex_count() const { return positions.size(); }
  std::uint32_t material(std::size_t triangle) const {
    return material_of_triangle.empty() ? 0u : material_of_triangle[triangle];
  }
  Bounds3 bounds() const;  // parallel
  // Vertex and index bytes, as an accelerator that reads this mesh in place pays them.
  std::size_t bytes() const;
};

// Coordinates beyond this magnitude are rejected: products of two of them would overflow
// float in ray-triangle tests, so such a mesh cannot be traced correctly.
inline constexpr float kMaxCoordinateMagnitude = 1e15f;

struct MeshCleanup {
  std::size_t degenerate_dropped = 0;  // repeated vertex or zero area
};

// Checks a mesh for problems that would make tracing wrong and fixes what has a safe fix:
// throws SceneError naming `source` for an empty mesh, NaN/Inf or huge coordinates,
// out-of-range indices or a material list of the wrong length; drops degenerate triangles.
// Leaves one vertex of spare capacity so an accelerator may read 16 bytes at the last vertex.
// `object_starts` (ascending triangle indices, or null) are moved past the dropped triangles.
MeshCleanup validate_and_clean(TriangleMesh& mesh, std::string_view source,
                               std::vector<std::size_t>* object_starts = nullptr);

// The checks of validate_and_clean that a streamed scene can make without its mesh: the box
// of all its vertices is finite and within kMaxCoordinateMagnitude (throws SceneError).
void validate_bounds(const Bounds3& bounds, std::string_view source);

}  // namespace wavetrace
