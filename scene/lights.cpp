// Power-proportional choice of emissive triangles by inverting a cumulative table.
#include "scene/lights.hpp"

#include <algorithm>

#include <glm/geometric.hpp>

#include "kernels/sampling.hpp"

namespace wavetrace {

LightSampler::LightSampler(const Scene& scene) : scene_(&scene) {
  const TriangleMesh& mesh = scene.mesh;
  double total = 0.0;
  std::vector<double> power;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Material& material = scene.materials[mesh.material(t)];
    if (!material.emissive()) continue;
    const glm::uvec3& tri = mesh.triangles[t];
    const float area = 0.5f * glm::length(glm::cross(mesh.positions[tri.y] - mesh.positions[tri.x],
                                                     mesh.positions[tri.z] - mesh.positions[tri.x]));
    const double weight = double(area) * std::max({material.emission.x, material.emission.y, material.emission.z});
    triangles_.push_back(static_cast<std::uint32_t>(t));
    power.push_back(weight);
    total += weight;
  }
  double running = 0.0;
  for (double weight : power) {
    running += weight;
    cumulative_.push_back(static_cast<float>(running / total));
    probability_.push_back(static_cast<float>(weight / total));
  }
  if (!cumulative_.empty()) cumulative_.back() = 1.0f;
}

LightSample LightSampler::sample(float u_choice, float u1, float u2) const {
  const std::size_t index = std::min<std::size_t>(
      std::upper_bound(cumulative_.begin(), cumulative_.end(), u_choice) - cumulative_.begin(),
      triangles_.size() - 1);
  const TriangleMesh& mesh = scene_->mesh;
  const std::uint32_t triangle = triangles_[index];
  const glm::uvec3& tri = mesh.triangles[triangle];
  const glm::vec3 a = mesh.positions[tri.x], b = mesh.positions[tri.y], c = mesh.positions[tri.z];
  const glm::vec3 cross = glm::cross(b - a, c - a);
  const float area = 0.5f * glm::length(cross);
  const Barycentrics bary = uniform_triangle(u1, u2);
  LightSample sample;
  sample.point = a + (b - a) * bary.b1 + (c - a) * bary.b2;
  sample.normal = glm::normalize(cross);
  sample.emission = scene_->materials[mesh.material(triangle)].emission;
  sample.pdf_area = probability_[index] / area;
  return sample;
}

}  // namespace wavetrace
