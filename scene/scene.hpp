// A renderable scene: one flattened triangle mesh, its materials, the light the sky
// gives, and the camera its author suggests.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/camera.hpp"
#include "scene/triangle_mesh.hpp"

namespace wavetrace {

// Lambertian reflection plus optional emission (emitting from the front face only).
struct Material {
  glm::vec3 albedo{0.7f};
  glm::vec3 emission{0.0f};
  bool emissive() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
};

struct Scene {
  std::string name;
  TriangleMesh mesh;
  std::vector<Material> materials;
  glm::vec3 background{0.0f};    // radiance of every ray that leaves the scene
  std::optional<Camera> camera;  // the scene author's view, if any
  // A box whose every inside point is enclosed by a closed shell of the scene's triangles
  // (builtin:room's walls): rays from it can never escape, whatever else the scene holds.
  std::optional<Bounds3> enclosure;
  MeshCleanup cleanup;
  std::size_t subdivision_levels = 0;
  std::size_t non_manifold_faces_dropped = 0;
};

struct SceneRequest {
  std::string source = "builtin:default";  // a mesh file, a scene file (.toml) or builtin:NAME[:TRIANGLES]
  int subdivide = 0;                       // Loop subdivision levels applied after loading
};

// Loads a mesh or scene file or generates a builtin, subdivides, validates; throws
// SceneError. Subdivision moves the walls of an enclosure, so it drops the enclosure.
Scene load_scene(const SceneRequest& request);

}  // namespace wavetrace
