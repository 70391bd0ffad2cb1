// Area lights: the emissive triangles of a scene, sampled in proportion to their power.
#pragma once

#include <algorithm>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <glm/vec3.hpp>

#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/scene/scene.hpp"

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
  // The emitters with every corner moved by `represent` (a lossy accelerator's surface:
  // Accelerator::represented_point); a light that becomes degenerate there is dropped.
  LightSampler(const Scene& scene, const std::function<glm::vec3(const glm::vec3&)>& represent);

  // What sampling needs, precomputed per emissive triangle so a sample is arithmetic only.
  // A saved world stores these as they are, 64 bytes each: corner, edge1, edge2, normal,
  // emission (float x, y, z each, offsets 0, 12, 24, 36, 48), pdf_area (float, offset 60).
  struct EmissiveTriangle {
    glm::vec3 corner, edge1, edge2;
    glm::vec3 normal;
    glm::vec3 emission;
    float pdf_area;  // choice probability / area
  };
  // The sampler a saved world held; throws std::invalid_argument on mismatched lengths.
  LightSampler(std::vector<EmissiveTriangle> triangles, std::vector<float> cumulative);
  std::span<const EmissiveTriangle> triangles() const { return triangles_; }
  std::span<const float> cumulative() const { return cumulative_; }

  bool empty() const { return triangles_.empty(); }
  std::size_t count() const { return triangles_.size(); }

  // u_choice picks a triangle, (u1, u2) a point on it; all in [0, 1).
  LightSample sample(float u_choice, float u1, float u2) const;  // inline below: called per shadow ray

 private:
  // Walker's alias table over the lights' choice probabilities (Vose's construction), so a
  // sample picks its light in constant time: slot floor(u n) keeps its own light when the
  // rest of u n is under `keep`, else takes `other`. Derived from cumulative_, not saved.
  struct AliasSlot {
    float keep;
    std::uint32_t other;
  };
  void build_alias_table();

  std::vector<EmissiveTriangle> triangles_;
  std::vector<float> cumulative_;  // normalized running sum of power
  std::vector<AliasSlot> alias_;
};

inline LightSample LightSampler::sample(float u_choice, float u1, float u2) const {
  const float scaled = u_choice * float(alias_.size());
  const std::size_t slot = std::min(static_cast<std::size_t>(scaled), alias_.size() - 1);
  const AliasSlot& entry = alias_[slot];
  const EmissiveTriangle& light = triangles_[scaled - float(slot) < entry.keep ? slot : entry.other];
  const Barycentrics bary = uniform_triangle(u1, u2);
  return {light.corner + light.edge1 * bary.b1 + light.edge2 * bary.b2, light.normal, light.emission, light.pdf_area};
}

}  // namespace wavetrace
