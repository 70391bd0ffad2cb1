// Appends object meshes, offsetting vertex indices and materials.
#include "wavetrace/scene/scene_assembly.hpp"

#include <limits>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

namespace wavetrace {

std::uint32_t SceneAssembly::add_material(const Material& material) {
  materials_.push_back(material);
  return static_cast<std::uint32_t>(materials_.size() - 1);
}

std::uint32_t SceneAssembly::append_geometry(const TriangleMesh& part) {
  if (mesh_.positions.size() + part.positions.size() > std::numeric_limits<std::uint32_t>::max()) {
    throw SceneError(fmt::format("the scene has more than {} vertices, beyond 32-bit indices",
                                 std::numeric_limits<std::uint32_t>::max()));
  }
  const auto offset = static_cast<std::uint32_t>(mesh_.positions.size());
  object_starts_.push_back(mesh_.triangles.size());
  mesh_.positions.insert(mesh_.positions.end(), part.positions.begin(), part.positions.end());
  const std::size_t first = mesh_.triangles.size();
  mesh_.triangles.resize(first + part.triangles.size());
  tbb::parallel_for(std::size_t{0}, part.triangles.size(),
                    [&](std::size_t t) { mesh_.triangles[first + t] = part.triangles[t] + offset; });
  return static_cast<std::uint32_t>(first);
}

void SceneAssembly::add(const TriangleMesh& part, std::uint32_t material) {
  append_geometry(part);
  mesh_.material_of_triangle.resize(mesh_.triangles.size(), material);
}

void SceneAssembly::add(const TriangleMesh& part, const std::vector<Material>& materials) {
  const auto base = static_cast<std::uint32_t>(materials_.size());
  materials_.insert(materials_.end(), materials.begin(), materials.end());
  const std::size_t first = append_geometry(part);
  mesh_.material_of_triangle.resize(mesh_.triangles.size());
  for (std::size_t t = 0; t < part.triangle_count(); ++t) {
    mesh_.material_of_triangle[first + t] = base + part.material(t);
  }
}

Scene SceneAssembly::finish(std::string name, const glm::vec3& background) && {
  Scene scene;
  scene.name = std::move(name);
  for (std::uint32_t material : mesh_.material_of_triangle) {
    if (material >= materials_.size()) {
      throw SceneError(fmt::format("{}: a triangle uses material {} of {}", scene.name, material, materials_.size()));
    }
  }
  if (object_starts_.empty()) object_starts_.push_back(0);
  scene.cleanup = validate_and_clean(mesh_, scene.name, &object_starts_);
  scene.mesh = std::move(mesh_);
  scene.object_starts = std::move(object_starts_);
  scene.materials = std::move(materials_);
  scene.background = background;
  return scene;
}

}  // namespace wavetrace
