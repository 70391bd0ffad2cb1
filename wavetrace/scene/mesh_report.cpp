// Edge census by sorting undirected edge keys, components by union-find over vertices.
#include "wavetrace/scene/mesh_report.hpp"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <numeric>
#include <vector>

#include <glm/geometric.hpp>
#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

namespace wavetrace {
namespace {

class DisjointSets {
 public:
  explicit DisjointSets(std::size_t size) : parent_(size) { std::iota(parent_.begin(), parent_.end(), 0u); }
  std::uint32_t find(std::uint32_t x) {
    while (parent_[x] != x) {
      parent_[x] = parent_[parent_[x]];
      x = parent_[x];
    }
    return x;
  }
  void unite(std::uint32_t a, std::uint32_t b) {
    a = find(a);
    b = find(b);
    if (a != b) parent_[std::max(a, b)] = std::min(a, b);
  }

 private:
  std::vector<std::uint32_t> parent_;
};

}  // namespace

MeshReport analyze_mesh(const TriangleMesh& mesh) {
  MeshReport report;
  report.triangles = mesh.triangle_count();
  report.vertices = mesh.vertex_count();
  report.bounds = mesh.bounds();

  std::vector<std::uint64_t> edge_keys(mesh.triangle_count() * 3);
  std::atomic<std::size_t> degenerate{0};
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
    const glm::uvec3& triangle = mesh.triangles[t];
    for (int corner = 0; corner < 3; ++corner) {
      const std::uint32_t a = triangle[corner];
      const std::uint32_t b = triangle[(corner + 1) % 3];
      edge_keys[t * 3 + corner] = (std::uint64_t{std::min(a, b)} << 32) | std::max(a, b);
    }
    const glm::vec3 normal = glm::cross(mesh.positions[triangle.y] - mesh.positions[triangle.x],
                                        mesh.positions[triangle.z] - mesh.positions[triangle.x]);
    if (triangle.x == triangle.y || triangle.y == triangle.z || triangle.x == triangle.z ||
        glm::dot(normal, normal) == 0.0f) {
      degenerate.fetch_add(1, std::memory_order_relaxed);
    }
  });
  report.degenerate_triangles = degenerate.load();

  tbb::parallel_sort(edge_keys.begin(), edge_keys.end());
  for (std::size_t i = 0; i < edge_keys.size();) {
    std::size_t j = i + 1;
    while (j < edge_keys.size() && edge_keys[j] == edge_keys[i]) ++j;
    ++report.edges;
    const std::size_t uses = j - i;
    if (uses == 1) ++report.boundary_edges;
    if (uses > 2) ++report.non_manifold_edges;
    i = j;
  }

  DisjointSets sets(mesh.vertex_count());
  std::vector<bool> used(mesh.vertex_count(), false);
  for (const glm::uvec3& triangle : mesh.triangles) {
    sets.unite(triangle.x, triangle.y);
    sets.unite(triangle.x, triangle.z);
    used[triangle.x] = used[triangle.y] = used[triangle.z] = true;
  }
  for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    if (used[v] && sets.find(v) == v) ++report.connected_components;
  }
  return report;
}

}  // namespace wavetrace
