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
  MeshCleanup cleanup;
  std::size_t subdivision_levels = 0;
  std::size_t non_manifold_faces_dropped = 0;
};

struct SceneRequest {
  std::string source = "builtin:default";  // a mesh file or builtin:NAME[:TRIANGLES]
  int subdivide = 0;                       // Loop subdivision levels applied after loading
};

// Loads a file or generates a builtin, subdivides, validates; throws SceneError.
Scene load_scene(const SceneRequest& request);

}  // namespace wavetrace
