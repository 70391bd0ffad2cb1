// Area lights: the emissive triangles of a scene, sampled in proportion to their power.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec3.hpp>

#include "scene/scene.hpp"

namespace wavetrace {

struct LightSample {
  glm::vec3 point;
  glm::vec3 normal;    // the emitting (front) side
  glm::vec3 emission;
  float pdf_area;      // probability density per unit area of choosing this point
};

class LightSampler {
 public:
  explicit LightSampler(const Scene& scene);

  bool empty() const { return triangles_.empty(); }
  std::size_t count() const { return triangles_.size(); }

  // u_choice picks a triangle, (u1, u2) a point on it; all in [0, 1).
  LightSample sample(float u_choice, float u1, float u2) const;

 private:
  // Everything sampling needs, precomputed per emissive triangle so a sample is arithmetic only.
  struct EmissiveTriangle {
    glm::vec3 corner, edge1, edge2;
    glm::vec3 normal;
    glm::vec3 emission;
    float pdf_area;  // choice probability / area
  };
  std::vector<EmissiveTriangle> triangles_;
  std::vector<float> cumulative_;  // normalized running sum of power
};

}  // namespace wavetrace
