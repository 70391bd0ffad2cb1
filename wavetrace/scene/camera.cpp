// Pinhole camera set-up and validation.
#include "wavetrace/scene/camera.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>
#include <glm/geometric.hpp>

#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {

void validate_camera(const Camera& camera) {
  const glm::vec3 forward = camera.look_at - camera.position;
  if (glm::dot(forward, forward) == 0.0f) throw SceneError("look_at equals position");
  if (glm::dot(camera.up, camera.up) == 0.0f) throw SceneError("up is a zero vector");
  if (glm::length(glm::cross(glm::normalize(forward), glm::normalize(camera.up))) < 1e-6f) {
    throw SceneError("up is parallel to the viewing direction");
  }
  if (!(camera.vertical_fov_degrees > 0.0f && camera.vertical_fov_degrees < 180.0f)) {
    throw SceneError(fmt::format("fov {} is outside (0, 180) degrees", camera.vertical_fov_degrees));
  }
}

Camera frame_bounds(const Bounds3& bounds) {
  Camera camera;
  const glm::vec3 center = bounds.center();
  // Fit the largest extent to the image height with a 10% margin: the bounding sphere
  // would leave most of the image empty (and most benchmark rays missing).
  const glm::vec3 extent = bounds.extent();
  const float radius = std::max(0.55f * std::max({extent.x, extent.y, extent.z}), 1e-6f);
  const float distance = radius / std::tan(0.5f * camera.vertical_fov_degrees * kPi / 180.0f) + 0.5f * extent.z;
  camera.look_at = center;
  camera.position = center + glm::normalize(glm::vec3(0.0f, 0.35f, 1.0f)) * distance;
  return camera;
}

CameraFrame::CameraFrame(const Camera& camera, float aspect) : origin(camera.position) {
  const glm::vec3 forward = glm::normalize(camera.look_at - camera.position);
  const glm::vec3 right = glm::normalize(glm::cross(forward, camera.up));
  const glm::vec3 true_up = glm::cross(right, forward);
  const float half_height = std::tan(0.5f * camera.vertical_fov_degrees * kPi / 180.0f);
  const float half_width = half_height * aspect;
  horizontal = right * (2.0f * half_width);
  vertical = true_up * (2.0f * half_height);
  lower_left = forward - right * half_width - true_up * half_height;
}

}  // namespace wavetrace
