// Power-proportional choice of emissive triangles by inverting a cumulative table.
#include "wavetrace/scene/lights.hpp"

#include <algorithm>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/sampling.hpp"

namespace wavetrace {

LightSampler::LightSampler(const Scene& scene) : LightSampler(scene, {}) {}

LightSampler::LightSampler(const Scene& scene, const std::function<glm::vec3(const glm::vec3&)>& represent) {
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
    const auto corner = [&](std::uint32_t v) { return represent ? represent(mesh.positions[v]) : mesh.positions[v]; };
    EmissiveTriangle light;
    light.corner = corner(tri.x);
    light.edge1 = corner(tri.y) - light.corner;
    light.edge2 = corner(tri.z) - light.corner;
    const glm::vec3 cross = glm::cross(light.edge1, light.edge2);
    if (!(glm::length(cross) > 0.0f)) continue;  // collapsed by the representation: it emits nothing there
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
  build_alias_table();
}

LightSampler::LightSampler(std::vector<EmissiveTriangle> triangles, std::vector<float> cumulative)
    : triangles_(std::move(triangles)), cumulative_(std::move(cumulative)) {
  if (triangles_.size() != cumulative_.size()) throw std::invalid_argument("light sampler: one cumulative weight per light");
  for (std::size_t i = 0; i < cumulative_.size(); ++i) {
    const float previous = i == 0 ? 0.0f : cumulative_[i - 1];
    if (!(cumulative_[i] >= previous) || !(cumulative_[i] <= 1.0f)) {
      throw std::invalid_argument("light sampler: cumulative weights must rise from 0 to 1");
    }
  }
  build_alias_table();
}

void LightSampler::build_alias_table() {
  const std::size_t n = cumulative_.size();
  alias_.assign(n, {1.0f, 0});
  if (n == 0) return;
  // Each light's probability times n: slots under 1 are topped up from slots over 1.
  std::vector<double> scaled(n);
  std::vector<std::uint32_t> small, large;
  for (std::size_t i = 0; i < n; ++i) {
    scaled[i] = (double(cumulative_[i]) - (i == 0 ? 0.0 : double(cumulative_[i - 1]))) * double(n);
    alias_[i].other = std::uint32_t(i);
    (scaled[i] < 1.0 ? small : large).push_back(std::uint32_t(i));
  }
  while (!small.empty() && !large.empty()) {
    const std::uint32_t under = small.back(), over = large.back();
    small.pop_back();
    alias_[under] = {static_cast<float>(scaled[under]), over};
    scaled[over] -= 1.0 - scaled[under];
    if (scaled[over] < 1.0) {
      large.pop_back();
      small.push_back(over);
    }
  }
  // What rounding leaves on either list is a full slot.
  for (std::uint32_t i : small) alias_[i] = {1.0f, i};
  for (std::uint32_t i : large) alias_[i] = {1.0f, i};
}


}  // namespace wavetrace
