// A builtin scene as the objects that generate it: each a shape generator, an offset and the
// scene materials of the shape's own materials. It is a TriangleSource, so a chunked build
// makes it a range at a time, and it assembles the whole mesh when one is wanted.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec3.hpp>

#include "wavetrace/scene/material_runs.hpp"
#include "wavetrace/scene/shape_generator.hpp"
#include "wavetrace/scene/triangle_source.hpp"

namespace wavetrace {

struct ProceduralObject {
  std::shared_ptr<const ShapeGenerator> shape;
  glm::vec3 offset{0.0f};
  std::vector<std::uint32_t> materials;  // scene material of each of the shape's materials
};

class ProceduralScene final : public TriangleSource {
 public:
  explicit ProceduralScene(std::vector<ProceduralObject> objects);

  std::size_t triangle_count() const override { return starts_.back(); }
  Bounds3 bounds() const override { return bounds_; }
  // Every object's parts (ShapeGenerator::part_starts).
  std::vector<std::size_t> object_starts() const override;
  // Vertices shared inside one object stay shared; material_of_triangle stays empty.
  TriangleMesh extract(std::size_t first, std::size_t count) const override;
  bool extracts_concurrently() const override { return true; }  // shapes generate any range from any thread

  MaterialRuns material_runs() const override;
  // Every object that has a wanted material, whole, without generating the rest.
  TriangleMesh triangles_with_materials(const std::vector<bool>& wanted_material) const override;

  const std::vector<ProceduralObject>& objects() const { return objects_; }
  // The whole scene as one mesh with material_of_triangle (scene indices).
  TriangleMesh assemble() const;

 private:
  TriangleMesh extract_objects(std::size_t first, std::size_t count, bool with_materials,
                               const std::vector<bool>* wanted_material) const;
  std::vector<ProceduralObject> objects_;
  std::vector<std::size_t> starts_;  // objects' first triangles, then the total
  Bounds3 bounds_;
};

}  // namespace wavetrace
