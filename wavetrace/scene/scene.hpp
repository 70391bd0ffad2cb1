// A renderable scene: one flattened triangle mesh, its materials, the light the sky
// gives, and the camera its author suggests.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "wavetrace/scene/camera.hpp"
#include "wavetrace/scene/material_runs.hpp"
#include "wavetrace/scene/procedural_scene.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// How a surface scatters light: Lambertian, a perfect mirror, or a smooth dielectric (glass)
// that reflects or refracts by Fresnel's equations.
enum class Surface : std::uint32_t { diffuse = 0, mirror = 1, glass = 2 };
Surface parse_surface(const std::string& text);  // "diffuse", "mirror", "glass"; else SceneError
std::string to_string(Surface surface);

// A surface plus optional emission (emitting from the front face only). `albedo` is the
// diffuse reflectance, or a mirror's reflectance, or glass's tint of both reflected and
// transmitted light. Glass takes its front face (the triangles' winding, counter-clockwise
// seen from outside) as its outside, where the index of refraction is 1.
struct Material {
  glm::vec3 albedo{0.7f};
  glm::vec3 emission{0.0f};
  Surface surface = Surface::diffuse;
  float ior = 1.5f;  // glass only: index of refraction inside
  bool emissive() const { return emission.x > 0.0f || emission.y > 0.0f || emission.z > 0.0f; }
  bool specular() const { return surface != Surface::diffuse; }
};

struct Scene {
  std::string name;
  // The flattened mesh; empty when the scene is streamed (`stream` makes its triangles a
  // range at a time) or was released once an accelerator that keeps its own geometry was built.
  TriangleMesh mesh;
  std::shared_ptr<const TriangleSource> stream;  // set when streamed
  // Where each object's (or object part's) triangles begin in `mesh`, ascending from 0, as a
  // streamed scene's source would say: a chunked build of the mesh cuts its chunks there, so
  // that a world is chunked the same whether its scene was kept whole (for a proxy) or not.
  // {0} where the objects are not known (a mesh file, a subdivided scene).
  std::vector<std::size_t> object_starts{0};
  // What stays known without the mesh: counts, bounds, each triangle's material.
  std::size_t triangle_count = 0;
  std::size_t vertex_count = 0;
  Bounds3 bounds;
  MaterialRuns material_runs;
  std::vector<Material> materials;
  glm::vec3 background{0.0f};    // radiance of every ray that leaves the scene
  std::optional<Camera> camera;  // the scene author's view, if any
  // A box whose every inside point is enclosed by a closed shell of the scene's triangles
  // (builtin:room's walls): rays from it can never escape, whatever else the scene holds.
  std::optional<Bounds3> enclosure;
  MeshCleanup cleanup;
  std::size_t subdivision_levels = 0;
  std::size_t non_manifold_faces_dropped = 0;

  bool streamed() const { return stream != nullptr; }
  // Frees the mesh (and its per-triangle materials); counts, bounds and runs stay.
  void release_mesh();
  // Sets counts, bounds and material runs from the mesh.
  void describe_mesh();
};

}  // namespace wavetrace
