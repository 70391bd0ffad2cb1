// Grid sizing from the surface area, then refinement from the measured count; quadrics
// accumulated per thread and merged; each cell's vertex solved from its quadric.
#include "wavetrace/accel/proxy/cluster_simplify.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/mat3x3.hpp>
#include <tbb/combinable.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/parallel_sort.h>

namespace wavetrace {
namespace {

constexpr std::uint64_t kCellBits = 21;
constexpr std::uint64_t kMaxCells = (std::uint64_t{1} << kCellBits) - 1;

struct Grid {
  glm::dvec3 lower;
  double cell = 1.0;
  std::uint64_t cell_of(const glm::vec3& p) const {
    std::uint64_t key = 0;
    for (int axis = 0; axis < 3; ++axis) {
      const double index = std::floor((double(p[axis]) - lower[axis]) / cell);
      key = (key << kCellBits) | static_cast<std::uint64_t>(std::clamp(index, 0.0, double(kMaxCells)));
    }
    return key;
  }
};

// A triangle of three distinct cells, rotated so the smallest cell comes first (keeping
// its winding), so equal triangles compare equal.
struct CellTriangle {
  std::array<std::uint64_t, 3> cells;
  bool operator<(const CellTriangle& other) const { return cells < other.cells; }
  bool operator==(const CellTriangle& other) const { return cells == other.cells; }
};

std::vector<CellTriangle> surviving_triangles(const TriangleMesh& mesh, const std::vector<std::uint64_t>& vertex_cell) {
  tbb::combinable<std::vector<CellTriangle>> found;
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.triangle_count(), 1 << 14), [&](const auto& range) {
    std::vector<CellTriangle>& local = found.local();
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const glm::uvec3& tri = mesh.triangles[t];
      std::array<std::uint64_t, 3> cells = {vertex_cell[tri.x], vertex_cell[tri.y], vertex_cell[tri.z]};
      if (cells[0] == cells[1] || cells[1] == cells[2] || cells[0] == cells[2]) continue;
      const int first = int(std::min_element(cells.begin(), cells.end()) - cells.begin());
      std::rotate(cells.begin(), cells.begin() + first, cells.end());
      local.push_back({cells});
    }
  });
  std::vector<CellTriangle> all;
  found.combine_each([&](const std::vector<CellTriangle>& part) { all.insert(all.end(), part.begin(), part.end()); });
  tbb::parallel_sort(all.begin(), all.end());
  all.erase(std::unique(all.begin(), all.end()), all.end());
  return all;
}

// Per cell: the area-weighted plane quadric (A = sum n n^T, b = sum n d) and the mean of
// the cell's vertices.
struct CellQuadric {
  std::array<double, 6> a{};  // xx, xy, xz, yy, yz, zz
  glm::dvec3 b{0.0};
  glm::dvec3 position_sum{0.0};
  double vertices = 0.0;
  void add_plane(const glm::dvec3& n, double d, double weight) {
    a[0] += weight * n.x * n.x;
    a[1] += weight * n.x * n.y;
    a[2] += weight * n.x * n.z;
    a[3] += weight * n.y * n.y;
    a[4] += weight * n.y * n.z;
    a[5] += weight * n.z * n.z;
    b += weight * d * n;
  }
  void merge(const CellQuadric& other) {
    for (int k = 0; k < 6; ++k) a[k] += other.a[k];
    b += other.b;
    position_sum += other.position_sum;
    vertices += other.vertices;
  }
  // The quadric's minimum when it is well conditioned and near the cell; else the mean.
  glm::vec3 representative(const glm::dvec3& cell_lower, double cell) const {
    const glm::dvec3 mean = position_sum / std::max(vertices, 1.0);
    const glm::dmat3 matrix(a[0], a[1], a[2], a[1], a[3], a[4], a[2], a[4], a[5]);
    const double trace = a[0] + a[3] + a[5];
    const double determinant = glm::determinant(matrix);
    if (trace <= 0.0 || determinant < 1e-6 * trace * trace * trace) return glm::vec3(mean);
    // Solved relative to the mean for precision: A (mean + x) = -b.
    const glm::dvec3 solution = mean + glm::inverse(matrix) * (-b - matrix * mean);
    const glm::dvec3 slack(cell * 0.5);
    if (glm::any(glm::lessThan(solution, cell_lower - slack)) ||
        glm::any(glm::greaterThan(solution, cell_lower + glm::dvec3(cell) + slack))) {
      return glm::vec3(mean);
    }
    return glm::vec3(solution);
  }
};

}  // namespace

ClusterSimplification simplify_by_clustering(const TriangleMesh& mesh, std::size_t target_triangles) {
  if (mesh.triangles.empty()) throw SceneError("cannot simplify a mesh with no triangles");
  target_triangles = std::max<std::size_t>(target_triangles, 4);
  const Bounds3 bounds = mesh.bounds();
  const double area = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, mesh.triangle_count(), 1 << 14), 0.0,
      [&](const auto& range, double sum) {
        for (std::size_t t = range.begin(); t != range.end(); ++t) {
          const glm::uvec3& tri = mesh.triangles[t];
          const glm::dvec3 a(mesh.positions[tri.x]);
          sum += 0.5 * glm::length(glm::cross(glm::dvec3(mesh.positions[tri.y]) - a, glm::dvec3(mesh.positions[tri.z]) - a));
        }
        return sum;
      },
      std::plus<>());

  ClusterSimplification result;
  Grid grid;
  grid.lower = glm::dvec3(bounds.lower);
  const glm::dvec3 extent(bounds.extent());
  const double largest = std::max({extent.x, extent.y, extent.z, 1e-30});
  // A surface crossing a grid of cell h occupies about area / h^2 cells and keeps about two
  // triangles per occupied cell.
  grid.cell = std::max(std::sqrt(2.0 * area / double(target_triangles)), largest / double(kMaxCells));
  std::vector<std::uint64_t> vertex_cell(mesh.vertex_count());
  std::vector<CellTriangle> kept;
  for (result.rounds = 1; result.rounds <= 4; ++result.rounds) {
    tbb::parallel_for(std::size_t{0}, mesh.vertex_count(), [&](std::size_t v) { vertex_cell[v] = grid.cell_of(mesh.positions[v]); });
    kept = surviving_triangles(mesh, vertex_cell);
    const double ratio = double(std::max<std::size_t>(kept.size(), 1)) / double(target_triangles);
    if ((ratio > 0.87 && ratio < 1.15) || result.rounds == 4) break;
    // Kept triangles scale as 1 / h^2.
    grid.cell = std::max(grid.cell * std::sqrt(std::clamp(ratio, 0.05, 20.0)), largest / double(kMaxCells));
  }
  result.cell_size = grid.cell;

  // The cells the kept triangles use, numbered in key order.
  std::vector<std::uint64_t> cells;
  cells.reserve(kept.size() * 3);
  for (const CellTriangle& triangle : kept) cells.insert(cells.end(), triangle.cells.begin(), triangle.cells.end());
  tbb::parallel_sort(cells.begin(), cells.end());
  cells.erase(std::unique(cells.begin(), cells.end()), cells.end());
  const auto index_of = [&](std::uint64_t cell) -> std::int64_t {
    const auto found = std::lower_bound(cells.begin(), cells.end(), cell);
    return found != cells.end() && *found == cell ? found - cells.begin() : -1;
  };
  std::vector<std::int64_t> vertex_slot(mesh.vertex_count());
  tbb::parallel_for(std::size_t{0}, mesh.vertex_count(), [&](std::size_t v) { vertex_slot[v] = index_of(vertex_cell[v]); });

  tbb::combinable<std::vector<CellQuadric>> partial([&] { return std::vector<CellQuadric>(cells.size()); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.triangle_count(), 1 << 14), [&](const auto& range) {
    std::vector<CellQuadric>& quadrics = partial.local();
    for (std::size_t t = range.begin(); t != range.end(); ++t) {
      const glm::uvec3& tri = mesh.triangles[t];
      const glm::dvec3 a(mesh.positions[tri.x]), b(mesh.positions[tri.y]), c(mesh.positions[tri.z]);
      const glm::dvec3 cross = glm::cross(b - a, c - a);
      const double twice_area = glm::length(cross);
      if (!(twice_area > 0.0)) continue;
      const glm::dvec3 normal = cross / twice_area;
      const double d = -glm::dot(normal, a);
      for (int corner = 0; corner < 3; ++corner) {
        const std::int64_t slot = vertex_slot[tri[corner]];
        if (slot >= 0) quadrics[std::size_t(slot)].add_plane(normal, d, 0.5 * twice_area);
      }
    }
  });
  tbb::combinable<std::vector<CellQuadric>> means([&] { return std::vector<CellQuadric>(cells.size()); });
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, mesh.vertex_count(), 1 << 14), [&](const auto& range) {
    std::vector<CellQuadric>& quadrics = means.local();
    for (std::size_t v = range.begin(); v != range.end(); ++v) {
      if (vertex_slot[v] < 0) continue;
      quadrics[std::size_t(vertex_slot[v])].position_sum += glm::dvec3(mesh.positions[v]);
      quadrics[std::size_t(vertex_slot[v])].vertices += 1.0;
    }
  });
  std::vector<CellQuadric> quadrics(cells.size());
  const auto merge_into = [&](const std::vector<CellQuadric>& part) {
    tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t k) { quadrics[k].merge(part[k]); });
  };
  partial.combine_each(merge_into);
  means.combine_each(merge_into);

  result.mesh.positions.resize(cells.size());
  tbb::parallel_for(std::size_t{0}, cells.size(), [&](std::size_t k) {
    const glm::dvec3 cell_lower = grid.lower + glm::dvec3(double((cells[k] >> (2 * kCellBits)) & kMaxCells),
                                                          double((cells[k] >> kCellBits) & kMaxCells),
                                                          double(cells[k] & kMaxCells)) * grid.cell;
    result.mesh.positions[k] = quadrics[k].representative(cell_lower, grid.cell);
  });
  result.mesh.triangles.resize(kept.size());
  tbb::parallel_for(std::size_t{0}, kept.size(), [&](std::size_t t) {
    result.mesh.triangles[t] = glm::uvec3(std::uint32_t(index_of(kept[t].cells[0])), std::uint32_t(index_of(kept[t].cells[1])),
                                          std::uint32_t(index_of(kept[t].cells[2])));
  });
  return result;
}

}  // namespace wavetrace
