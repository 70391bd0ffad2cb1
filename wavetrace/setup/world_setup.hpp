// From a plan to the world it renders: the scene loaded (streamed where it can be), the
// accelerator auto and pixel bounds resolve to, the camera, the proxy; and the check that
// a builtin scene fits in memory before anything is generated.
#pragma once

#include <memory>

#include "wavetrace/accel/proxy/proxy.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/scene/camera.hpp"
#include "wavetrace/scene/scene.hpp"
#include "wavetrace/setup/accel_choice.hpp"
#include "wavetrace/setup/render_plan.hpp"

namespace wavetrace {

// The proxy the plan's chain needs (approx_hit), built against the scene's accelerator;
// null when the chain has no approx_hit.
std::unique_ptr<Proxy> build_proxy(const RenderPlan& plan, const Scene& scene, const Accelerator& accelerator);

// The scene's accelerator (make_world_accelerator): from its generators when the scene is
// streamed, else from its mesh, which must then outlive the accelerator. A chunked world's
// chunks go to `stream` as they are built (make_world_accelerator).
std::unique_ptr<Accelerator> build_world_accelerator(const Scene& scene, const AcceleratorOptions& options,
                                                    const ChunkStream* stream = nullptr);

// Before anything is allocated: throws SceneError when a builtin scene of the requested
// size would not fit in the memory the machine has available, by the accelerator's bytes
// per triangle (and the whole mesh's, when the scene is not streamed). With
// `structure_to_file`, a type that builds in chunks writes each to a file as it is built
// (ChunkStream) and holds one chunk's structure, not the world's.
void check_scene_fits(const RenderPlan& plan, bool structure_to_file = false);

// A scene loaded for building its world, and the accelerator it is built with: the plan's,
// or what accel.type = auto and pixel error bounds resolve to on this scene and camera. The
// scene is generated streamed when the type (or auto) may build from a stream and no mesh
// is wanted (`keep_mesh`: a proxy is simplified from it), and loaded again whole when the
// chosen type reads the mesh in place.
struct SceneForWorld {
  Scene scene;
  Camera camera;
  ResolvedAccelerator accelerator;
};
SceneForWorld load_scene_for_world(const RenderPlan& plan, bool keep_mesh, bool structure_to_file = false);

// The camera: the config's keys over the scene's own camera over one framing the bounds.
Camera resolve_camera(const CameraOverride& override, const Scene& scene);

}  // namespace wavetrace
