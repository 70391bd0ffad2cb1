// The one entry from a scene's name to a Scene: a mesh file, a scene file or a builtin,
// subdivided and checked. Apart from scene.hpp, which the loaders themselves return.
#pragma once

#include <string>

#include "wavetrace/scene/scene.hpp"

namespace wavetrace {

struct SceneRequest {
  std::string source = "builtin:default";  // a mesh file, a scene file (.toml) or builtin:NAME[:TRIANGLES]
  int subdivide = 0;                       // Loop subdivision levels applied after loading
  // A builtin is left as its generators, a binary PLY file as its vertices and a reader of
  // its faces (Scene::stream), rather than assembled into one mesh, for a chunked build that
  // reads it a range at a time. Ignored for other files and when subdividing.
  bool streamed = false;
  bool operator==(const SceneRequest&) const = default;
};

// Loads a mesh or scene file or generates a builtin, subdivides, validates; throws
// SceneError. Subdivision moves the walls of an enclosure, so it drops the enclosure.
Scene load_scene(const SceneRequest& request);

}  // namespace wavetrace
