// A procedural shape as a generator: any range of its triangles can be made on its own, so a
// scene of billions of triangles is produced a chunk at a time and never exists whole.
// Vertices are named by 64-bit keys that are pure functions of the shape, so a vertex two
// chunks share gets the same key and the same float position in both.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec3.hpp>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

class ShapeGenerator {
 public:
  virtual ~ShapeGenerator() = default;
  virtual std::size_t triangle_count() const = 0;
  // Dense shapes key their vertices 0 .. vertex_count() - 1; others (0 from vertex_count)
  // use sparse keys, which extraction sorts.
  virtual std::size_t vertex_count() const = 0;
  // How many distinct vertices the whole shape has (sparse shapes count their keys).
  virtual std::size_t distinct_vertices() const { return vertex_count(); }
  // The three corner keys of each triangle of [first, first + count), in winding order, to
  // out[3 * (t - first) + k]. Called from several threads on disjoint ranges.
  virtual void corners(std::size_t first, std::size_t count, std::uint64_t* out) const = 0;
  virtual glm::vec3 position(std::uint64_t key) const = 0;
  // A box sure to hold position(key), where one is much cheaper than the position (a displaced
  // shape's bound on its displacement); nullopt where none is.
  virtual std::optional<Bounds3> position_bound(std::uint64_t key) const { return std::nullopt; }
  // The shape's own material index of a triangle (see material_count).
  virtual std::uint32_t material(std::size_t triangle) const { return 0; }
  virtual std::uint32_t material_count() const { return 1; }
  // Where the shape's natural parts begin (ascending, from 0), as cut points for chunks: a
  // part of its own has a box of its own (a room's six walls, not the room).
  virtual std::vector<std::size_t> part_starts() const { return {0}; }
};

// The shape's triangles [first, first + count) as a mesh of their own, moved by `offset`:
// vertices renumbered from 0 in key order; material_of_triangle filled when the shape has
// more than one material. The whole of a dense shape keeps its vertex numbering.
TriangleMesh generate_range(const ShapeGenerator& shape, std::size_t first, std::size_t count,
                            const glm::vec3& offset = glm::vec3(0.0f));
TriangleMesh generate_mesh(const ShapeGenerator& shape, const glm::vec3& offset = glm::vec3(0.0f));

// The box of every vertex the shape generates, moved by `offset` (parallel). With `known`,
// the box of those vertices only that position_bound does not put strictly inside `known`:
// extended by it, it is `known` extended by every vertex, to the bit (a vertex left out lies
// strictly inside), and displaced shapes inside a room skip most of their positions.
Bounds3 generated_bounds(const ShapeGenerator& shape, const glm::vec3& offset = glm::vec3(0.0f),
                         const Bounds3* known = nullptr);

}  // namespace wavetrace
