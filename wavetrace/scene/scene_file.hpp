// Scene files: a TOML list of objects (mesh files or builtins, each with a transform and a
// material), area lights and a camera, flattened into one mesh. Example: scenes/gallery.toml.
//
//   background = [0.02, 0.02, 0.03]        # sky radiance (a number or [r, g, b]); default 0
//   [camera]                               # optional; position and look_at required if present
//   position = [0, 1.5, 4]
//   look_at = [0, 0.8, 0]
//   up = [0, 1, 0]                         # default +y
//   fov = 45                               # vertical, degrees; default 40
//   [[object]]
//   name = "bunny"                         # default "object N"
//   mesh = "../data/bunny00.off"           # relative to this file, or builtin:NAME[:TRIANGLES]
//   fit = 1.2                              # optional: centre, and scale the largest extent to this
//   scale = 1.0                            # a number or [x, y, z]; non-zero
//   rotate = [0, 30, 0]                    # degrees about x, then y, then z
//   translate = [0, 0.6, 0]
//   subdivide = 0                          # Loop subdivision levels of this object, 0-6
//   albedo = [0.8, 0.5, 0.3]               # with emission, replaces the mesh's own materials
//   emission = [0, 0, 0]
//   material = { type = "glass", ior = 1.5 }   # instead of albedo and emission beside the mesh:
//                                          # type diffuse (default), mirror or glass; albedo
//                                          # (default 1 for mirror and glass), emission, ior
//                                          # (glass only, [1, 4], default 1.5)
//   [[light]]                              # a parallelogram emitting along cross(edge_u, edge_v)
//   corner = [-0.5, 3, -0.5]
//   edge_u = [1, 0, 0]
//   edge_v = [0, 0, 1]
//   emission = [10, 10, 10]
#pragma once

#include <string>

#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

bool is_scene_file(std::string_view source);  // by its .toml extension

struct SceneFileLimits {
  // The most triangles all objects may make together, after subdivision; an object past it
  // is refused before it is built. 0: what available memory holds at
  // kSubdividedBytesPerTriangle (subdivide.hpp).
  std::size_t max_triangles = 0;
};

// Throws SceneError naming the file and the object (by name and number) for a syntax error,
// an unknown key, a value of the wrong type or range, a missing mesh, a degenerate
// transform, or objects that make more triangles than `limits` allow.
Scene load_scene_file(const std::string& path, const SceneFileLimits& limits = {});

}  // namespace wavetrace
