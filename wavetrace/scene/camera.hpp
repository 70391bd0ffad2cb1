// A pinhole camera and the frame that turns film coordinates into rays.
#pragma once

#include <glm/vec3.hpp>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct Camera {
  glm::vec3 position{0.0f, 0.0f, 5.0f};
  glm::vec3 look_at{0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  float vertical_fov_degrees = 40.0f;
};

// Throws SceneError if the camera looks at its own position, has a zero or parallel up
// vector, or a field of view outside (0, 180).
void validate_camera(const Camera& camera);

// A camera that frames the bounds from the front (+z), slightly above.
Camera frame_bounds(const Bounds3& bounds);

// Film point (x, y in [0,1], y up) to the unnormalized ray direction.
struct CameraFrame {
  CameraFrame(const Camera& camera, float aspect);
  glm::vec3 origin;
  glm::vec3 lower_left;  // direction to the film's lower-left corner
  glm::vec3 horizontal;
  glm::vec3 vertical;
  glm::vec3 direction(float x, float y) const { return lower_left + horizontal * x + vertical * y; }
};

}  // namespace wavetrace
