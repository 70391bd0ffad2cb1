// Plan to world: loading, choosing, building.
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/world_setup.hpp"

#include <algorithm>

#include <fmt/format.h>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"

namespace wavetrace {

std::unique_ptr<Accelerator> build_world_accelerator(const Scene& scene, const AcceleratorOptions& options,
                                                    const ChunkStream* stream) {
  if (scene.streamed()) return make_world_accelerator(*scene.stream, nullptr, options, stream);
  const MeshTriangleSource source(scene.mesh, scene.object_starts);
  return make_world_accelerator(source, &scene.mesh, options, stream);
}

void check_scene_fits(const RenderPlan& plan, bool structure_to_file) {
  const std::string& source = plan.scene.source;
  // accel.type = auto chooses by its own budget.
  if (!is_builtin_scene(source) || plan.scene.subdivide > 0 || plan.accel_goal.automatic) return;
  const std::optional<std::size_t> requested = requested_triangle_count(source);
  if (!requested) return;
  const double triangles = double(*requested);
  const std::size_t available = available_memory_bytes();
  if (available == 0) return;
  // Measured on builtin:room (docs/memory.md, "Memory at scale"): the finished structure, the mesh
  // when it is built whole (positions, indices, a material per triangle), and the build's
  // temporaries, bounded by a chunk where the type builds in chunks.
  const double structure = estimated_bytes_per_triangle(plan.accelerator);
  const double mesh = plan.scene.streamed ? 0.0 : kWholeMeshBytesPerTriangle;
  const bool chunked = builds_in_chunks(plan.accelerator.type);
  const double build_triangles = chunked ? std::min(triangles, double(plan.accelerator.chunk_triangles)) : triangles;
  const double held_triangles = chunked && structure_to_file ? build_triangles : triangles;
  const double needed = held_triangles * structure + triangles * mesh +
                        build_triangles * estimated_build_bytes_per_triangle(plan.accelerator.type);
  if (needed > double(available)) {
    throw SceneError(fmt::format(
        "{}: about {:.1f} GB needed to build '{}' ({:.0f} bytes/triangle{} plus build temporaries) but {:.1f} GB "
        "of memory is available; try fewer triangles or a more compact accelerator (hmq)",
        source, needed * 1e-9, plan.accelerator.type, structure, mesh > 0.0 ? " and the whole mesh" : "",
        double(available) * 1e-9));
  }
}

SceneForWorld load_scene_for_world(const RenderPlan& plan, bool keep_mesh, bool structure_to_file) {
  SceneRequest request = plan.scene;
  // Streamed where the structure may not need the whole mesh: auto decides after the scene's
  // pass; a builtin's size, known before it is made, says whether a chunked build's will.
  const std::optional<std::size_t> known_triangles = is_builtin_scene(plan.scene.source) && plan.scene.subdivide == 0
                                                         ? builtin_triangle_count(plan.scene.source)
                                                         : std::nullopt;
  const bool whole_mesh_read = !plan.accel_goal.automatic &&
                               (known_triangles ? reads_whole_mesh(plan.accelerator, *known_triangles)
                                                : !holds_own_geometry(plan.accelerator.type));
  request.streamed = !whole_mesh_read && !keep_mesh;
  RenderPlan checked = plan;
  checked.scene = request;
  check_scene_fits(checked, structure_to_file);
  Scene scene = load_scene(request);
  const Camera camera = resolve_camera(plan.camera, scene);
  const MeshTriangleSource whole(scene.mesh, scene.object_starts);
  const TriangleSource& triangles = scene.streamed() ? *scene.stream : static_cast<const TriangleSource&>(whole);
  ResolvedAccelerator resolved =
      resolve_accelerator(plan.accelerator, plan.accel_goal, triangles, camera, plan.image, scene.streamed());
  if (scene.streamed() && reads_whole_mesh(resolved.options, triangles.triangle_count())) {
    request.streamed = false;
    scene = load_scene(request);
  }
  return {std::move(scene), camera, std::move(resolved)};
}

std::unique_ptr<Proxy> build_proxy(const RenderPlan& plan, const Scene& scene, const Accelerator& accelerator) {
  if (!plan.needs_proxy()) return nullptr;
  return std::make_unique<Proxy>(scene.mesh, plan.proxy, accelerator);
}

Camera resolve_camera(const CameraOverride& override, const Scene& scene) {
  Camera camera = scene.camera.value_or(frame_bounds(scene.bounds));
  if (override.position) camera.position = *override.position;
  if (override.look_at) camera.look_at = *override.look_at;
  if (override.up) camera.up = *override.up;
  if (override.vertical_fov_degrees) camera.vertical_fov_degrees = *override.vertical_fov_degrees;
  try {
    validate_camera(camera);
  } catch (const SceneError& error) {
    throw SceneError(fmt::format("camera: {}", error.what()));
  }
  return camera;
}

}  // namespace wavetrace
