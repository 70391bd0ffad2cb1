// What a Scene knows of its mesh once the mesh is gone (counts, bounds, material runs), and
// material types by name.
#include "wavetrace/scene/scene.hpp"

#include <fmt/format.h>

namespace wavetrace {

Surface parse_surface(const std::string& text) {
  if (text == "diffuse") return Surface::diffuse;
  if (text == "mirror") return Surface::mirror;
  if (text == "glass") return Surface::glass;
  throw SceneError(fmt::format("unknown material type '{}' (known: diffuse, mirror, glass)", text));
}

std::string to_string(Surface surface) {
  switch (surface) {
    case Surface::diffuse: return "diffuse";
    case Surface::mirror: return "mirror";
    case Surface::glass: return "glass";
  }
  return "unknown";
}

void Scene::describe_mesh() {
  triangle_count = mesh.triangle_count();
  vertex_count = mesh.vertex_count();
  bounds = mesh.bounds();
  material_runs = MaterialRuns::from_triangles(mesh.material_of_triangle, mesh.triangle_count());
}

void Scene::release_mesh() { mesh = TriangleMesh{}; }

}  // namespace wavetrace
