// Placing an object in a scene: an optional fit to a size, then scale, rotation and translation.
#pragma once

#include <optional>

#include <glm/vec3.hpp>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct ObjectTransform {
  // Centre the mesh's bounds at the origin and scale it uniformly so that its largest
  // extent is this size, before the rest: lets a scene place meshes of unknown units.
  std::optional<float> fit;
  glm::vec3 scale{1.0f};
  glm::vec3 rotate_degrees{0.0f};  // about x, then y, then z
  glm::vec3 translate{0.0f};
};

// Throws SceneError (message starting with `what`) for a zero or non-finite scale, a
// non-finite rotation or translation, a fit that is not positive, or a fit of a flat point.
void validate_transform(const ObjectTransform& transform, std::string_view what);

// Moves every vertex (in double precision, in parallel). A mirroring transform (negative
// determinant) also reverses each triangle's winding, so front faces stay front faces.
void apply_transform(TriangleMesh& mesh, const ObjectTransform& transform, std::string_view what);

}  // namespace wavetrace
