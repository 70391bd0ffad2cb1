// Scene loading: mesh files through mesh_io, scene files through scene_file, builtins through
// builtin_scenes, then subdivision.
#include "wavetrace/scene/load_scene.hpp"

#include <fmt/format.h>

#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/mesh_io.hpp"
#include "wavetrace/scene/ply_file.hpp"
#include "wavetrace/scene/scene_file.hpp"
#include "wavetrace/scene/subdivide.hpp"

namespace wavetrace {

Scene load_scene(const SceneRequest& request) {
  if (request.subdivide < 0 || request.subdivide > 6) {
    throw SceneError(fmt::format("scene.subdivide = {}: must be in [0, 6]", request.subdivide));
  }
  Scene scene;
  if (is_builtin_scene(request.source)) {
    scene = make_builtin_scene(request.source, request.streamed && request.subdivide == 0);
  } else if (is_scene_file(request.source)) {
    scene = load_scene_file(request.source);
  } else if (is_binary_ply(request.source)) {
    auto ply = std::make_shared<const PlyTriangleSource>(request.source);
    scene.name = request.source;
    scene.cleanup.degenerate_dropped = ply->degenerate_dropped();
    scene.materials = {Material{}};
    scene.background = glm::vec3(1.0f);
    if (request.streamed && request.subdivide == 0) {
      scene.triangle_count = ply->triangle_count();
      scene.vertex_count = ply->vertex_count();
      scene.bounds = ply->bounds();
      scene.material_runs = ply->material_runs();
      scene.stream = std::move(ply);
    } else {
      scene.mesh = ply->extract(0, ply->triangle_count());
    }
  } else {
    LoadedMesh loaded = load_mesh_file(request.source);
    scene.name = request.source;
    scene.mesh = std::move(loaded.mesh);
    scene.cleanup = loaded.cleanup;
    scene.materials = {Material{}};
    scene.background = glm::vec3(1.0f);  // a plain white sky lights a lone mesh
  }
  if (request.subdivide > 0) {
    SubdivisionResult subdivided = loop_subdivide(scene.mesh, request.subdivide);
    scene.non_manifold_faces_dropped = subdivided.non_manifold_faces_dropped;
    scene.mesh = std::move(subdivided.mesh);
    const MeshCleanup cleanup = validate_and_clean(scene.mesh, request.source + " (subdivided)");
    scene.cleanup.degenerate_dropped += cleanup.degenerate_dropped;
    scene.subdivision_levels = static_cast<std::size_t>(request.subdivide);
    scene.enclosure.reset();  // Loop subdivision pulls the walls inward
    scene.object_starts = {0};  // its faces no longer follow the objects' order
  }
  if (!scene.streamed()) scene.describe_mesh();
  return scene;
}

}  // namespace wavetrace
