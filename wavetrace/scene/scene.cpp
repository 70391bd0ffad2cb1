// What a Scene knows of its mesh once the mesh is gone: counts, bounds, material runs.
#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

void Scene::describe_mesh() {
  triangle_count = mesh.triangle_count();
  vertex_count = mesh.vertex_count();
  bounds = mesh.bounds();
  material_runs = MaterialRuns::from_triangles(mesh.material_of_triangle, mesh.triangle_count());
}

void Scene::release_mesh() { mesh = TriangleMesh{}; }

}  // namespace wavetrace
