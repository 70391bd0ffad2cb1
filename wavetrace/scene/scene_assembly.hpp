// Flattens objects into one triangle mesh with a material index per triangle, as the
// papers do (no instancing): every accelerator sees a single mesh.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

class SceneAssembly {
 public:
  std::uint32_t add_material(const Material& material);
  // Appends `part` with every triangle using `material` (an index from add_material).
  void add(const TriangleMesh& part, std::uint32_t material);
  // Appends `part` keeping its own per-triangle materials, which index `materials`.
  void add(const TriangleMesh& part, const std::vector<Material>& materials);

  std::size_t triangle_count() const { return mesh_.triangle_count(); }
  const TriangleMesh& mesh() const { return mesh_; }

  // Validates the flattened mesh (throws SceneError naming `name`) and hands it over.
  Scene finish(std::string name, const glm::vec3& background) &&;

 private:
  std::uint32_t append_geometry(const TriangleMesh& part);
  TriangleMesh mesh_;
  std::vector<std::size_t> object_starts_;  // each added part's first triangle
  std::vector<Material> materials_;
};

}  // namespace wavetrace
