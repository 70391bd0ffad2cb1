// Power-proportional choice of emissive triangles by inverting a cumulative table.
#include "scene/lights.hpp"

#include <algorithm>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "kernels/sampling.hpp"

namespace wavetrace {

LightSampler::LightSampler(const Scene& scene) {
  // A streamed scene generates just its emissive objects here.
  TriangleMesh generated;
  if (scene.streamed()) {
    std::vector<bool> emissive(scene.materials.size());
    for (std::size_t m = 0; m < emissive.size(); ++m) emissive[m] = scene.materials[m].emissive();
    generated = scene.stream->triangles_with_materials(emissive);
  } else if (scene.mesh.triangles.empty() && scene.triangle_count > 0) {
    throw std::logic_error("LightSampler needs the scene's mesh: build it before the mesh is released");
  }
  const TriangleMesh& mesh = scene.streamed() ? generated : scene.mesh;
  std::vector<double> power;
  double total = 0.0;
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    const Material& material = scene.materials[mesh.material(t)];
    if (!material.emissive()) continue;
    const glm::uvec3& tri = mesh.triangles[t];
    EmissiveTriangle light;
    light.corner = mesh.positions[tri.x];
    light.edge1 = mesh.positions[tri.y] - light.corner;
    light.edge2 = mesh.positions[tri.z] - light.corner;
    const glm::vec3 cross = glm::cross(light.edge1, light.edge2);
    light.normal = glm::normalize(cross);
    light.emission = material.emission;
    light.pdf_area = 0.5f * glm::length(cross);  // the area, until divided below
    triangles_.push_back(light);
    const double weight = double(light.pdf_area) * std::max({material.emission.x, material.emission.y, material.emission.z});
    power.push_back(weight);
    total += weight;
  }
  double running = 0.0;
  for (std::size_t i = 0; i < triangles_.size(); ++i) {
    running += power[i];
    cumulative_.push_back(static_cast<float>(running / total));
    triangles_[i].pdf_area = static_cast<float>(power[i] / total) / triangles_[i].pdf_area;
  }
  if (!cumulative_.empty()) cumulative_.back() = 1.0f;
}

LightSampler::LightSampler(std::vector<EmissiveTriangle> triangles, std::vector<float> cumulative)
    : triangles_(std::move(triangles)), cumulative_(std::move(cumulative)) {
  if (triangles_.size() != cumulative_.size()) throw std::invalid_argument("light sampler: one cumulative weight per light");
}

LightSample LightSampler::sample(float u_choice, float u1, float u2) const {
  const std::size_t index = std::min<std::size_t>(
      std::upper_bound(cumulative_.begin(), cumulative_.end(), u_choice) - cumulative_.begin(),
      triangles_.size() - 1);
  const EmissiveTriangle& light = triangles_[index];
  const Barycentrics bary = uniform_triangle(u1, u2);
  return {light.corner + light.edge1 * bary.b1 + light.edge2 * bary.b2, light.normal, light.emission, light.pdf_area};
}

}  // namespace wavetrace
