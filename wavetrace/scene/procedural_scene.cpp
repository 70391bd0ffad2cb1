// Ranges across object boundaries, materials as runs, bounds from every generated vertex.
#include "wavetrace/scene/procedural_scene.hpp"

#include <algorithm>
#include <limits>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

namespace wavetrace {

ProceduralScene::ProceduralScene(std::vector<ProceduralObject> objects) : objects_(std::move(objects)) {
  starts_.push_back(0);
  for (const ProceduralObject& object : objects_) {
    starts_.push_back(starts_.back() + object.shape->triangle_count());
    // The objects before (in order, as before) bound this one's positions: a displaced
    // shape inside the room computes only those that might reach past them.
    bounds_.extend(generated_bounds(*object.shape, object.offset, &bounds_));
  }
}

std::vector<std::size_t> ProceduralScene::object_starts() const {
  std::vector<std::size_t> starts;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    for (const std::size_t part : objects_[o].shape->part_starts()) starts.push_back(starts_[o] + part);
  }
  return starts;
}

TriangleMesh ProceduralScene::extract(std::size_t first, std::size_t count) const {
  return extract_objects(first, count, false, nullptr);
}

TriangleMesh ProceduralScene::assemble() const { return extract_objects(0, triangle_count(), true, nullptr); }

TriangleMesh ProceduralScene::triangles_with_materials(const std::vector<bool>& wanted_material) const {
  return extract_objects(0, triangle_count(), true, &wanted_material);
}

TriangleMesh ProceduralScene::extract_objects(std::size_t first, std::size_t count, bool with_materials,
                                              const std::vector<bool>* wanted_material) const {
  if (first > triangle_count() || count > triangle_count() - first) {
    throw std::out_of_range(fmt::format("scene range [{}, {}) beyond its {} triangles", first, first + count,
                                        triangle_count()));
  }
  TriangleMesh mesh;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    const std::size_t begin = std::max(first, starts_[o]), end = std::min(first + count, starts_[o + 1]);
    if (begin >= end) continue;
    const ProceduralObject& object = objects_[o];
    if (wanted_material != nullptr &&
        std::none_of(object.materials.begin(), object.materials.end(), [&](std::uint32_t m) { return (*wanted_material)[m]; })) {
      continue;
    }
    TriangleMesh part = generate_range(*object.shape, begin - starts_[o], end - begin, object.offset);
    if (mesh.positions.size() + part.positions.size() > std::numeric_limits<std::uint32_t>::max()) {
      throw SceneError(fmt::format("more than {} vertices in one piece of the scene, beyond 32-bit indices",
                                   std::numeric_limits<std::uint32_t>::max()));
    }
    const auto vertex_offset = static_cast<std::uint32_t>(mesh.positions.size());
    const std::size_t triangle_offset = mesh.triangles.size();
    if (triangle_offset == 0 && vertex_offset == 0) {
      // The first object's part is the mesh so far: moved, not copied (a chunk is most often
      // one object's, and copying it, zeroing first, ran on one thread).
      mesh.positions = std::move(part.positions);
      mesh.triangles = std::move(part.triangles);
    } else {
      mesh.positions.insert(mesh.positions.end(), part.positions.begin(), part.positions.end());
      mesh.triangles.resize(triangle_offset + part.triangles.size());
      tbb::parallel_for(std::size_t{0}, part.triangles.size(),
                        [&](std::size_t t) { mesh.triangles[triangle_offset + t] = part.triangles[t] + vertex_offset; });
    }
    if (with_materials) {
      mesh.material_of_triangle.resize(mesh.triangles.size());
      for (std::size_t t = triangle_offset; t < mesh.triangles.size(); ++t) {
        mesh.material_of_triangle[t] = object.materials[part.material(t - triangle_offset)];
      }
    }
  }
  mesh.positions.reserve(mesh.positions.size() + 1);  // read slack, as validate_and_clean leaves
  return mesh;
}

MaterialRuns ProceduralScene::material_runs() const {
  MaterialRuns runs;
  for (std::size_t o = 0; o < objects_.size(); ++o) {
    const ProceduralObject& object = objects_[o];
    if (object.materials.size() == 1) {
      runs.append(starts_[o], object.materials[0]);
      continue;
    }
    for (std::size_t t = 0; t < object.shape->triangle_count(); ++t) {
      runs.append(starts_[o] + t, object.materials[object.shape->material(t)]);
    }
  }
  return runs;
}

}  // namespace wavetrace
