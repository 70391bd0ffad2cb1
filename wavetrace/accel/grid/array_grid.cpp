// Recursive build (items bucketed into a node's cells by counting, then each crowded cell
// refined) and recursive 3D-DDA traversal, each grid stopping once its nearest hit lies
// before its next cell.
#include "wavetrace/accel/grid/array_grid.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/grid/grid_walk.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {
namespace {

struct ArrayGridNode {
  glm::vec3 lower;
  glm::vec3 cell_size;
  glm::uvec3 cells;
  std::uint32_t first_cell;
  std::uint32_t padding[2];
};
static_assert(sizeof(ArrayGridNode) == 48);

struct ArrayGridCell {
  std::uint32_t reference = 0;
  std::uint32_t count = 0;
};
static_assert(sizeof(ArrayGridCell) == 8);

class ArrayGridAccelerator final : public ProbedAccelerator<ArrayGridAccelerator> {
  friend class ProbedAccelerator<ArrayGridAccelerator>;

 public:
  ArrayGridAccelerator(const TriangleMesh& mesh, const ArrayGridOptions& options) : mesh_(mesh), options_(options) {
    const auto start = std::chrono::steady_clock::now();
    boxes_.resize(mesh.triangle_count());
    tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
      const glm::uvec3& tri = mesh.triangles[t];
      Bounds3 box;
      box.extend(mesh.positions[tri.x]);
      box.extend(mesh.positions[tri.y]);
      box.extend(mesh.positions[tri.z]);
      boxes_[t] = box;
    });
    std::vector<std::uint32_t> all(mesh.triangle_count());
    for (std::uint32_t t = 0; t < all.size(); ++t) all[t] = t;
    Bounds3 root = mesh.bounds();
    const glm::vec3 pad = glm::max(root.extent() * 1e-5f, glm::vec3(1e-30f));
    root.lower -= pad;
    root.upper += pad;
    build_grid(root, all, 0);
    boxes_.clear();
    boxes_.shrink_to_fit();
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = memory().total() + mesh.triangle_count() * (sizeof(Bounds3) + 2 * sizeof(std::uint32_t));
  }

  std::string name() const override { return "arraygrid"; }
  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = nodes_.size() * sizeof(ArrayGridNode) + cells_.size() * sizeof(ArrayGridCell) +
                       items_.size() * sizeof(std::uint32_t);
    report.geometry = mesh_.positions.size() * sizeof(glm::vec3) + mesh_.triangles.size() * sizeof(glm::uvec3);
    return report;
  }
  BuildReport build() const override { return build_; }
  std::string build_notes() const override {
    std::string notes = fmt::format("{} grids, {} cells, {:.2f} entries per triangle", nodes_.size(), cells_.size(),
                                    double(items_.size()) / double(mesh_.triangle_count()));
    if (guarded_) {
      notes += fmt::format("; resolution guard: refinement stopped at {} cells or {} list entries",
                           options_.max_cells, options_.max_entries);
    }
    return notes;
  }
  std::vector<std::span<const std::byte>> memory_spans() const override {
    return {std::as_bytes(std::span(nodes_)), std::as_bytes(std::span(cells_)), std::as_bytes(std::span(items_)),
            std::as_bytes(std::span(mesh_.positions)), std::as_bytes(std::span(mesh_.triangles))};
  }

 private:
  // Makes the grid over `box` for `items` and returns its node index.
  std::uint32_t build_grid(const Bounds3& box, const std::vector<std::uint32_t>& items, std::uint32_t depth) {
    const glm::dvec3 size(glm::max(box.extent(), glm::vec3(1e-30f)));
    const double scale = std::cbrt(options_.density * double(items.size()) / (size.x * size.y * size.z));
    ArrayGridNode node{};
    for (int axis = 0; axis < 3; ++axis) {
      node.cells[axis] = static_cast<std::uint32_t>(std::clamp(std::ceil(size[axis] * scale), 1.0, 1024.0));
    }
    node.lower = box.lower;
    node.cell_size = glm::vec3(size / glm::dvec3(node.cells));
    const std::size_t count = std::size_t(node.cells.x) * node.cells.y * node.cells.z;
    node.first_cell = static_cast<std::uint32_t>(cells_.size());
    cells_.resize(cells_.size() + count);
    const auto index = static_cast<std::uint32_t>(nodes_.size());
    nodes_.push_back(node);

    // Bucket the items by the cells their (slightly grown) boxes overlap: count, then fill.
    const glm::vec3 slack = node.cell_size * 1e-3f;
    const auto cell_range = [&](std::uint32_t t, glm::uvec3& low, glm::uvec3& high) {
      low = cell_of(node, boxes_[t].lower - slack);
      high = cell_of(node, boxes_[t].upper + slack);
    };
    std::vector<std::uint32_t> start(count + 1, 0);
    for (std::uint32_t t : items) {
      glm::uvec3 low, high;
      cell_range(t, low, high);
      for (std::uint32_t z = low.z; z <= high.z; ++z)
        for (std::uint32_t y = low.y; y <= high.y; ++y)
          for (std::uint32_t x = low.x; x <= high.x; ++x) ++start[cell_index(node, x, y, z) + 1];
    }
    for (std::size_t c = 0; c < count; ++c) start[c + 1] += start[c];
    std::vector<std::uint32_t> bucketed(start.back());
    std::vector<std::uint32_t> cursor(start.begin(), start.end() - 1);
    for (std::uint32_t t : items) {
      glm::uvec3 low, high;
      cell_range(t, low, high);
      for (std::uint32_t z = low.z; z <= high.z; ++z)
        for (std::uint32_t y = low.y; y <= high.y; ++y)
          for (std::uint32_t x = low.x; x <= high.x; ++x) bucketed[cursor[cell_index(node, x, y, z)]++] = t;
    }

    bucketed_entries_ += bucketed.size();
    for (std::size_t c = 0; c < count; ++c) {
      const std::uint32_t in_cell = start[c + 1] - start[c];
      if (in_cell == 0) continue;  // null
      const bool refine = in_cell >= options_.refine_items && depth < options_.max_depth &&
                          cells_.size() < options_.max_cells && bucketed_entries_ < options_.max_entries;
      guarded_ |= in_cell >= options_.refine_items && depth < options_.max_depth && !refine;
      if (refine) {
        const glm::uvec3 at(std::uint32_t(c % node.cells.x), std::uint32_t(c / node.cells.x % node.cells.y),
                            std::uint32_t(c / (std::size_t(node.cells.x) * node.cells.y)));
        Bounds3 child;
        child.lower = node.lower + glm::vec3(at) * node.cell_size;
        child.upper = child.lower + node.cell_size;
        const std::vector<std::uint32_t> child_items(bucketed.begin() + start[c], bucketed.begin() + start[c + 1]);
        const std::uint32_t child_node = build_grid(child, child_items, depth + 1);
        cells_[node.first_cell + c] = {(child_node << 1) | 1u, in_cell};
      } else {
        // The list start shares its word with the refined-cell flag: 31 bits.
        cells_[node.first_cell + c] = {checked_uint32(std::uint64_t(items_.size()) << 1,
                                                      "arraygrid list start (31 bits); lower accel.arraygrid.max_entries"),
                                       in_cell};
        items_.insert(items_.end(), bucketed.begin() + start[c], bucketed.begin() + start[c + 1]);
      }
    }
    return index;
  }

  static glm::uvec3 cell_of(const ArrayGridNode& node, const glm::vec3& point) {
    const glm::vec3 index = glm::floor((point - node.lower) / node.cell_size);
    return glm::uvec3(glm::clamp(index, glm::vec3(0.0f), glm::vec3(node.cells) - 1.0f));
  }
  static std::size_t cell_index(const ArrayGridNode& node, std::uint32_t x, std::uint32_t y, std::uint32_t z) {
    return (std::size_t(z) * node.cells.y + y) * node.cells.x + x;
  }

  struct RayState {
    glm::vec3 origin, direction;
    WatertightRay ray;
    float tmin;
    float best;
    TriangleHit found;
    std::uint32_t found_triangle;
  };

  // 3D-DDA over one grid within [near, far]; true when an any-hit query may stop.
  template <bool kAnyHit, typename Probe>
  bool traverse_grid(const ArrayGridNode& node, RayState& state, float near, float far, Probe& probe) const {
    probe.read(&node, sizeof node);
    const glm::vec3 upper = node.lower + node.cell_size * glm::vec3(node.cells);
    float enter = 0.0f, leave = 0.0f;
    if (!clip_to_box(make_box_ray(state.origin, state.direction), node.lower, upper, near, far, enter, leave)) return false;
    GridWalk walk(node.lower, node.cell_size, state.origin, state.direction,
                  glm::ivec3(cell_of(node, state.origin + state.direction * enter)));
    float cell_enter = enter;
    const glm::vec3* positions = mesh_.positions.data();
    const glm::uvec3* triangles = mesh_.triangles.data();
    while (true) {
      const int axis = walk.exit_axis();
      const float cell_leave = std::min(walk.next_crossing[axis], leave);
      const glm::uvec3 cell(walk.cell);
      const ArrayGridCell& c = cells_[node.first_cell + cell_index(node, cell.x, cell.y, cell.z)];
      probe.read(&c, sizeof c);
      if (c.count > 0) {
        if (c.reference & 1u) {
          if (traverse_grid<kAnyHit>(nodes_[c.reference >> 1], state, cell_enter,
                                     std::min(cell_leave, pruning_distance(state.best)),
                                     probe)) {
            return true;
          }
        } else {
          for (std::uint32_t k = c.reference >> 1, end = k + c.count; k < end; ++k) {
            const glm::uvec3& tri = triangles[items_[k]];
            if constexpr (Probe::kRecords) {
              probe.read(&items_[k], sizeof(std::uint32_t));
              probe.read(&tri, sizeof tri);
              for (int corner = 0; corner < 3; ++corner) probe.read(positions + tri[corner], sizeof(glm::vec3));
            }
            TriangleHit hit;
            if (intersect_watertight(state.ray, positions[tri.x], positions[tri.y], positions[tri.z], state.tmin,
                                     state.best, hit) &&
                replaces_nearest(
                    hit.t, state.best, state.found_triangle != kInvalidPrimitive, [&] { return items_[k]; },
                    [&] { return state.found_triangle; })) {
              state.best = hit.t;
              state.found = hit;
              state.found_triangle = items_[k];
              if constexpr (kAnyHit) return true;
            }
          }
        }
      }
      if (walk.next_crossing[axis] > pruning_distance(state.best) || walk.next_crossing[axis] > leave) return false;
      cell_enter = walk.next_crossing[axis];
      if (!walk.advance(axis, node.cells)) return false;
    }
  }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      RayState state;
      state.origin = ray.origin;
      state.direction = ray.direction;
      state.ray = ray.sheared;
      state.tmin = ray.tmin;
      state.best = ray.tmax;
      state.found_triangle = kInvalidPrimitive;
      traverse_grid<kAnyHit>(nodes_[0], state, state.tmin, state.best, probe);
      if (state.found_triangle != kInvalidPrimitive) {
        hits.set_hit(i, state.found.t, state.found_triangle, state.found.u, state.found.v);
        set_surface_from_mesh(hits, i, mesh_, state.found_triangle);
      } else {
        hits.set_miss(i);
      }
    });
  }

  const TriangleMesh& mesh_;
  ArrayGridOptions options_;
  std::vector<Bounds3> boxes_;  // build only
  bool guarded_ = false;
  std::size_t bucketed_entries_ = 0;  // list entries made so far, at every level (build only)
  LargeArray<ArrayGridNode> nodes_;
  LargeArray<ArrayGridCell> cells_;
  LargeArray<std::uint32_t> items_;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_array_grid_accelerator(const TriangleMesh& mesh, const ArrayGridOptions& options) {
  return std::make_unique<ArrayGridAccelerator>(mesh, options);
}

}  // namespace wavetrace
