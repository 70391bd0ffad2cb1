// A scene's triangles as a source a chunked build reads a range at a time: an in-memory mesh,
// or a procedural scene that generates each range on demand and never holds the whole.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "wavetrace/scene/material_runs.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

class TriangleSource {
 public:
  virtual ~TriangleSource() = default;
  virtual std::size_t triangle_count() const = 0;
  virtual Bounds3 bounds() const = 0;
  // Where each object's triangles begin, ascending from 0: chunks are cut there too, so that
  // no chunk's box spans two objects.
  virtual std::vector<std::size_t> object_starts() const = 0;
  // Triangles [first, first + count) as a mesh of their own: vertices renumbered from 0,
  // triangle i of the result is triangle first + i of the source, material_of_triangle empty.
  virtual TriangleMesh extract(std::size_t first, std::size_t count) const = 0;
  // Whether several ranges may be extracted at once, from several threads (a file read in
  // order may not be).
  virtual bool extracts_concurrently() const { return false; }
  // Each triangle's material (scene indices); a source without materials has only material 0.
  virtual MaterialRuns material_runs() const { return MaterialRuns::from_triangles({}, triangle_count()); }
  // Every triangle whose material is `wanted` (by index), with material_of_triangle: what
  // a light sampler needs without the rest of the scene.
  virtual TriangleMesh triangles_with_materials(const std::vector<bool>& wanted) const;
};

// The ranges of a mesh that is already in memory (read in place; it must outlive the source).
// `object_starts` as Scene::object_starts: a scene's mesh is cut into chunks where the same
// scene streamed would be.
class MeshTriangleSource final : public TriangleSource {
 public:
  explicit MeshTriangleSource(const TriangleMesh& mesh, std::vector<std::size_t> object_starts = {0})
      : mesh_(mesh), object_starts_(std::move(object_starts)) {}
  std::size_t triangle_count() const override { return mesh_.triangle_count(); }
  Bounds3 bounds() const override { return mesh_.bounds(); }
  std::vector<std::size_t> object_starts() const override { return object_starts_; }
  TriangleMesh extract(std::size_t first, std::size_t count) const override;
  bool extracts_concurrently() const override { return true; }

 private:
  const TriangleMesh& mesh_;
  std::vector<std::size_t> object_starts_;
};

}  // namespace wavetrace
