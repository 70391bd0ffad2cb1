// Counting construction of the hashed grid (triangles bucketed by slabs of z layers, D bits,
// first-fit row displacement for O, counts and prefix sums for H, insertion in triangle order
// for L, each slab's cells filled by one task) and 3D-DDA traversal that stops once the
// nearest hit found lies before the next cell.
#include "wavetrace/accel/grid/hashed_grid.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
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
#include "wavetrace/kernels/triangle_cell_runs.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct CellRange {
  glm::uvec3 lower, upper;  // inclusive
};

class HashedGridAccelerator final : public ProbedAccelerator<HashedGridAccelerator> {
  friend class ProbedAccelerator<HashedGridAccelerator>;

 public:
  HashedGridAccelerator(const TriangleMesh& mesh, const HashedGridOptions& options)
      : mesh_(mesh), bounding_box_lists_(options.bounding_box_lists) {
    PhaseClock clock;
    choose_resolution(options);
    clock.lap(build_.phases, "bounds");
    bucket_by_slab();
    clock.lap(build_.phases, "slabs");
    mark_cells();
    clock.lap(build_.phases, "mark");
    displace_rows();
    clock.lap(build_.phases, "displace");
    fill_lists(clock);
    const std::size_t slab_bytes = slab_triangles_.size() * sizeof(std::uint32_t);
    slab_triangles_ = {};
    build_macrocells(options.macrocell_factor);
    clock.lap(build_.phases, "macrocells");
    build_.seconds = clock.elapsed();
    build_.peak_bytes = memory().total() + row_scratch_bytes_ + slab_bytes;  // an upper bound: the slabs go first
  }

  std::string name() const override { return macrocell_factor_ > 0 ? "mlgrid" : "grid"; }


  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = domain_.size() * sizeof(std::uint64_t) + offsets_.size() * sizeof(std::uint32_t) +
                       starts_.size() * sizeof(std::uint32_t) + items_.size() * sizeof(std::uint32_t);
    for (const MacrocellLevel& level : macrocells_) report.hierarchy += level.bits.size() * sizeof(std::uint64_t);
    report.geometry = mesh_.positions.size() * sizeof(glm::vec3) + mesh_.triangles.size() * sizeof(glm::uvec3);
    return report;
  }
  BuildReport build() const override { return build_; }
  std::string build_notes() const override {
    std::size_t occupied_cells = 0;
    for (std::uint64_t word : domain_) occupied_cells += std::size_t(std::popcount(word));
    std::string notes = fmt::format("{}x{}x{} cells, {} non-empty, {} slots in H, {:.2f} entries per triangle",
                                    cells_.x, cells_.y, cells_.z, occupied_cells, slot_count_,
                                    double(items_.size()) / double(mesh_.triangle_count()));
    for (std::size_t k = 0; k < macrocells_.size(); ++k) {
      notes += fmt::format("; macrocells level {}: {}x{}x{}", k + 1, macrocells_[k].cells.x, macrocells_[k].cells.y,
                           macrocells_[k].cells.z);
    }
    if (capped_) notes += fmt::format("; resolution guard: density lowered to {:.3g} to stay under {} cells",
                                      effective_density_, max_cells_);
    return notes;
  }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    std::vector<std::span<const std::byte>> spans = {
        std::as_bytes(std::span(domain_)), std::as_bytes(std::span(offsets_)), std::as_bytes(std::span(starts_)),
        std::as_bytes(std::span(items_)), std::as_bytes(std::span(mesh_.positions)),
        std::as_bytes(std::span(mesh_.triangles))};
    for (const MacrocellLevel& level : macrocells_) spans.push_back(std::as_bytes(std::span(level.bits)));
    return spans;
  }

 private:
  void choose_resolution(const HashedGridOptions& options) {
    bounds_ = mesh_.bounds();
    const GridResolution resolution = hashed_grid_resolution(bounds_, mesh_.triangle_count(), options);
    cells_ = resolution.cells;
    capped_ = resolution.capped;
    const glm::dvec3 size = resolution.size;
    max_cells_ = options.max_cells;
    effective_density_ = double(cells_.x) * cells_.y * cells_.z / double(mesh_.triangle_count());
    cell_size_ = glm::vec3(size) / glm::vec3(cells_);
    inverse_cell_size_ = 1.0f / cell_size_;
    // Pad the box by a cell's thousandth so points on its upper faces fall inside.
    upper_ = bounds_.lower + cell_size_ * glm::vec3(cells_) * (1.0f + 1e-6f) + cell_size_ * 1e-3f;
  }

  glm::uvec3 cell_of(const glm::vec3& point) const {
    const glm::vec3 index = glm::floor((point - bounds_.lower) * inverse_cell_size_);
    return glm::uvec3(glm::clamp(index, glm::vec3(0.0f), glm::vec3(cells_) - 1.0f));
  }

  // The cells triangle t's box overlaps, the box grown by a thousandth of a cell so that
  // DDA rounding at cell faces never skips a cell holding a triangle it passes. Recomputed
  // in each pass rather than stored: cheaper than 24 bytes per triangle of fresh memory.
  CellRange range_of(std::size_t t) const {
    const glm::uvec3& tri = mesh_.triangles[t];
    const glm::vec3 a = mesh_.positions[tri.x], b = mesh_.positions[tri.y], c = mesh_.positions[tri.z];
    const glm::vec3 slack = cell_size_ * 1e-3f;
    return {cell_of(glm::min(a, glm::min(b, c)) - slack), cell_of(glm::max(a, glm::max(b, c)) + slack)};
  }

  std::size_t cell_index(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
    return (std::size_t(z) * cells_.y + y) * cells_.x + x;
  }

  // Triangles bucketed by slabs of z layers, each slab's list ascending: a slab task then owns
  // every cell (D bit, H slot, L range) of its layers, so the passes below need no atomic
  // per cell entry, and each cell's list fills in ascending order without a sort. A stable
  // counting sort in parallel: counts per (block of triangles, slab), then each block writes
  // its triangles at its own offsets.
  void bucket_by_slab() {
    const std::size_t triangles = mesh_.triangle_count();
    slab_layers_ = std::max<std::uint32_t>(1, (cells_.z + kTargetSlabs - 1) / kTargetSlabs);
    const std::size_t slabs = (cells_.z + slab_layers_ - 1) / slab_layers_;
    const std::size_t block_size = std::max<std::size_t>(4096, (triangles + kTriangleBlocks - 1) / kTriangleBlocks);
    const std::size_t blocks = (triangles + block_size - 1) / block_size;
    std::vector<std::size_t> counts(blocks * slabs, 0);  // [block][slab], then each one's offset
    const auto slabs_of = [&](std::size_t t) {
      const CellRange r = range_of(t);
      return std::pair(r.lower.z / slab_layers_, r.upper.z / slab_layers_);
    };
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
      std::size_t* block_counts = counts.data() + block * slabs;
      for (std::size_t t = block * block_size, end = std::min(triangles, t + block_size); t < end; ++t) {
        const auto [first, last] = slabs_of(t);
        for (std::uint32_t slab = first; slab <= last; ++slab) ++block_counts[slab];
      }
    });
    slab_starts_.assign(slabs + 1, 0);
    std::size_t total = 0;
    for (std::size_t slab = 0; slab < slabs; ++slab) {
      slab_starts_[slab] = total;
      for (std::size_t block = 0; block < blocks; ++block) {
        const std::size_t count = counts[block * slabs + slab];
        counts[block * slabs + slab] = total;
        total += count;
      }
    }
    slab_starts_[slabs] = total;
    slab_triangles_.resize(total);
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
      std::size_t* cursor = counts.data() + block * slabs;
      for (std::size_t t = block * block_size, end = std::min(triangles, t + block_size); t < end; ++t) {
        const auto [first, last] = slabs_of(t);
        for (std::uint32_t slab = first; slab <= last; ++slab) slab_triangles_[cursor[slab]++] = std::uint32_t(t);
      }
    });
  }

  // Calls row_run(t, y, z, x_lower, x_upper) for each row of cells (y, z) that triangle t of a
  // slab overlaps (its bounding box does, with kBoundingBoxes or bounding-box lists), within
  // the slab's layers, triangles in ascending order; slabs in parallel.
  template <bool kBoundingBoxes = false, typename RowRun>
  void for_each_slab_row_run(RowRun&& row_run) const {
    const CellGridFrame frame{glm::dvec3(bounds_.lower), glm::dvec3(cell_size_), glm::dvec3(cell_size_ * 1e-3f)};
    tbb::parallel_for(std::size_t{0}, slab_starts_.size() - 1, [&](std::size_t slab) {
      const std::uint32_t z_first = std::uint32_t(slab) * slab_layers_;
      const std::uint32_t z_last = std::min(cells_.z - 1, z_first + slab_layers_ - 1);
      for (std::size_t k = slab_starts_[slab]; k < slab_starts_[slab + 1]; ++k) {
        const std::uint32_t t = slab_triangles_[k];
        const CellRange r = range_of(t);
        if (kBoundingBoxes || bounding_box_lists_) {
          for (std::uint32_t z = std::max(r.lower.z, z_first); z <= std::min(r.upper.z, z_last); ++z) {
            for (std::uint32_t y = r.lower.y; y <= r.upper.y; ++y) row_run(t, y, z, r.lower.x, r.upper.x);
          }
        } else {
          const glm::uvec3& tri = mesh_.triangles[t];
          for_each_triangle_cell_run(mesh_.positions[tri.x], mesh_.positions[tri.y], mesh_.positions[tri.z], frame,
                                     r.lower, r.upper, z_first, z_last,
                                     [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                                       row_run(t, y, z, x_first, x_last);
                                     });
        }
      }
    });
  }

  void mark_cells() {
    const std::size_t cell_count = std::size_t(cells_.x) * cells_.y * cells_.z;
    domain_.assign((cell_count + 63) / 64, 0);
    // By bounding boxes whatever the lists (the header says why); a row run's bits a word at
    // a time, atomic since a word may straddle two slabs' layers.
    for_each_slab_row_run<true>([&](std::uint32_t, std::uint32_t y, std::uint32_t z, std::uint32_t x_lower, std::uint32_t x_upper) {
      const std::size_t first = cell_index(x_lower, y, z), last = cell_index(x_upper, y, z);
      for (std::size_t word = first / 64; word <= last / 64; ++word) {
        std::uint64_t bits = ~std::uint64_t{0};
        if (word == first / 64) bits &= ~std::uint64_t{0} << (first % 64);
        if (word == last / 64) bits &= ~std::uint64_t{0} >> (63 - last % 64);
        std::atomic_ref<std::uint64_t>(domain_[word]).fetch_or(bits, std::memory_order_relaxed);
      }
    });
  }

  bool occupied(std::size_t d) const { return (domain_[d / 64] >> (d % 64)) & 1u; }

  // Calls f(x) for each occupied cell of row (y, z), x ascending: the row's D bits a word at
  // a time, since rows are mostly empty.
  template <typename F>
  void for_each_occupied_cell_of_row(std::uint32_t y, std::uint32_t z, F&& f) const {
    const std::size_t first = cell_index(0, y, z), row_end = first + cells_.x;
    for (std::size_t word = first / 64; word * 64 < row_end; ++word) {
      std::uint64_t bits = domain_[word];
      if (word * 64 < first) bits &= ~std::uint64_t{0} << (first - word * 64);
      if ((word + 1) * 64 > row_end) bits &= ~std::uint64_t{0} >> ((word + 1) * 64 - row_end);
      for (; bits != 0; bits &= bits - 1) f(std::uint32_t(word * 64 + std::countr_zero(bits) - first));
    }
  }

  // First fit from the last row's offset, as the paper builds O: each row's set cells land on
  // slots of the shared bit array bH that no earlier row took.
  void displace_rows() {
    offsets_.assign(std::size_t(cells_.y) * cells_.z, 0);
    std::vector<std::uint64_t> taken(1024, 0);
    const auto is_taken = [&](std::size_t slot) { return slot / 64 < taken.size() && ((taken[slot / 64] >> (slot % 64)) & 1u); };
    std::vector<std::uint32_t> row;
    std::size_t last_offset = 0, used_slots = 0;
    for (std::uint32_t z = 0; z < cells_.z; ++z) {
      for (std::uint32_t y = 0; y < cells_.y; ++y) {
        row.clear();
        for_each_occupied_cell_of_row(y, z, [&](std::uint32_t x) { row.push_back(x); });
        if (row.empty()) continue;  // never read: its D bits are all clear
        std::size_t offset = last_offset;
        while (std::any_of(row.begin(), row.end(), [&](std::uint32_t x) { return is_taken(offset + x); })) ++offset;
        const std::size_t end = offset + row.back() + 1;
        if ((end + 63) / 64 > taken.size()) taken.resize(std::max(taken.size() * 2, (end + 63) / 64), 0);
        for (std::uint32_t x : row) taken[(offset + x) / 64] |= std::uint64_t{1} << ((offset + x) % 64);
        offsets_[std::size_t(z) * cells_.y + y] = checked_uint32(offset, "grid row offset; lower accel.grid.max_cells");
        used_slots = std::max(used_slots, end);
        last_offset = offset;
      }
    }
    slot_count_ = used_slots;
    row_scratch_bytes_ = taken.size() * sizeof(std::uint64_t);
  }

  std::size_t slot_of(std::uint32_t x, std::uint32_t y, std::uint32_t z) const {
    return offsets_[std::size_t(z) * cells_.y + y] + x;
  }

  // Counts per slot, exclusive prefix sums, then the lists: each slot belongs to one cell and
  // each cell to one slab task, so counts and cursors are plain; H itself is the cursor (after
  // the fill, H[slot] holds where slot + 1 starts, and one shift restores it).
  void fill_lists(PhaseClock& clock) {
    starts_.assign(slot_count_ + 1, 0);
    for_each_slab_row_run([&](std::uint32_t, std::uint32_t y, std::uint32_t z, std::uint32_t x_lower, std::uint32_t x_upper) {
      std::uint32_t* row = starts_.data() + slot_of(0, y, z);
      for (std::uint32_t x = x_lower; x <= x_upper; ++x) ++row[x];
    });
    clock.lap(build_.phases, "count");
    std::uint64_t total = 0;
    for (std::uint32_t& start : starts_) {
      const std::uint32_t count = start;
      start = static_cast<std::uint32_t>(total);
      total += count;
    }
    if (total > std::numeric_limits<std::uint32_t>::max()) {
      throw std::runtime_error("grid: more than 2^32 cell entries; lower accel.grid.density");
    }
    clock.lap(build_.phases, "prefix");
    items_.resize(total);
    clock.lap(build_.phases, "allocate");
    for_each_slab_row_run([&](std::uint32_t t, std::uint32_t y, std::uint32_t z, std::uint32_t x_lower, std::uint32_t x_upper) {
      std::uint32_t* row = starts_.data() + slot_of(0, y, z);
      for (std::uint32_t x = x_lower; x <= x_upper; ++x) items_[row[x]++] = t;
    });
    std::move_backward(starts_.begin(), starts_.end() - 1, starts_.end());
    starts_[0] = 0;
    clock.lap(build_.phases, "insert");
  }

  // Macrocells (Wald et al. 2006, as the paper uses them): level k is a bit per block of
  // factor^k fine cells, set when any cell in the block holds items; levels stop at one block.
  // Level 1 is read off D's rows in parallel; each level above off the one below, since a
  // block holds items when one of its factor^3 sub-blocks does.
  void build_macrocells(std::uint32_t factor) {
    macrocell_factor_ = factor;
    if (factor < 2) return;
    std::uint32_t span = 1;
    glm::uvec3 cells = cells_;
    while (macrocells_.size() < 4 && (cells.x > 1 || cells.y > 1 || cells.z > 1)) {
      span *= factor;
      MacrocellLevel level;
      level.span = span;
      level.cells = (cells_ + span - 1u) / span;
      level.bits.assign((std::size_t(level.cells.x) * level.cells.y * level.cells.z + 63) / 64, 0);
      const auto mark = [&level](const glm::uvec3& block) {
        const std::size_t m = level.index(block);
        std::atomic_ref<std::uint64_t>(level.bits[m / 64]).fetch_or(std::uint64_t{1} << (m % 64), std::memory_order_relaxed);
      };
      if (macrocells_.empty()) {
        tbb::parallel_for(std::size_t{0}, std::size_t(cells_.y) * cells_.z, [&](std::size_t row) {
          const auto y = std::uint32_t(row % cells_.y), z = std::uint32_t(row / cells_.y);
          for_each_occupied_cell_of_row(y, z, [&](std::uint32_t x) { mark(glm::uvec3(x, y, z) / span); });
        });
      } else {
        const MacrocellLevel& below = macrocells_.back();
        for (std::size_t word = 0; word < below.bits.size(); ++word) {
          for (std::uint64_t bits = below.bits[word]; bits != 0; bits &= bits - 1) {
            const std::size_t b = word * 64 + std::size_t(std::countr_zero(bits));
            const glm::uvec3 block(std::uint32_t(b % below.cells.x), std::uint32_t(b / below.cells.x % below.cells.y),
                                   std::uint32_t(b / (std::size_t(below.cells.x) * below.cells.y)));
            mark(block / factor);
          }
        }
      }
      cells = level.cells;
      macrocells_.push_back(std::move(level));
    }
  }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    const glm::vec3* positions = mesh_.positions.data();
    const glm::uvec3* triangles = mesh_.triangles.data();
    for_each_ray(rays, hits, range, [&](const SingleRay& single, std::uint32_t i) {
      hits.set_miss(i);
      const glm::vec3 &origin = single.origin, &direction = single.direction;
      const float tmin = single.tmin;
      float near = 0.0f, far = 0.0f;
      if (!clip_to_box(single.box, bounds_.lower, upper_, tmin, single.tmax, near, far)) return;

      GridWalk walk(bounds_.lower, cell_size_, origin, direction, glm::ivec3(cell_of(origin + direction * near)));
      const WatertightRay& ray = single.sheared;
      float best = single.tmax;
      TriangleHit found{kInfinity, 0.0f, 0.0f};
      std::uint32_t found_triangle = kInvalidPrimitive;
      while (true) {
        // In an empty macrocell, jump past its block: out through the face the ray leaves by.
        const glm::uvec3 cell(walk.cell);
        if (const MacrocellLevel* empty = coarsest_empty_macrocell(cell, probe)) {
          const glm::ivec3 lower = glm::ivec3(cell / empty->span * empty->span);
          const glm::ivec3 upper = glm::min(lower + int(empty->span) - 1, glm::ivec3(cells_) - 1);
          float exit = kInfinity;
          int exit_axis = 0;
          for (int axis = 0; axis < 3; ++axis) {
            if (walk.step[axis] == 0) continue;
            const float t = walk.face_crossing(axis, walk.step[axis] > 0 ? upper[axis] + 1 : lower[axis]);
            if (t < exit) exit = t, exit_axis = axis;
          }
          if (exit > pruning_distance(best) || exit > far) break;
          glm::ivec3 next = glm::clamp(glm::ivec3(cell_of(origin + direction * exit)), lower, upper);
          next[exit_axis] = walk.step[exit_axis] > 0 ? upper[exit_axis] + 1 : lower[exit_axis] - 1;
          if (next[exit_axis] < 0 || next[exit_axis] >= int(cells_[exit_axis])) break;
          walk.enter(next);
          continue;
        }
        const std::size_t d = cell_index(cell.x, cell.y, cell.z);
        probe.read(&domain_[d / 64], sizeof(std::uint64_t));
        if (occupied(d)) {
          const std::size_t row = std::size_t(cell.z) * cells_.y + cell.y;
          probe.read(&offsets_[row], sizeof(std::uint32_t));
          const std::size_t slot = offsets_[row] + cell.x;
          probe.read(&starts_[slot], 2 * sizeof(std::uint32_t));
          for (std::uint32_t k = starts_[slot]; k < starts_[slot + 1]; ++k) {
            const glm::uvec3& tri = triangles[items_[k]];
            if constexpr (Probe::kRecords) {
              probe.read(&items_[k], sizeof(std::uint32_t));
              probe.read(&tri, sizeof tri);
              for (int corner = 0; corner < 3; ++corner) probe.read(positions + tri[corner], sizeof(glm::vec3));
            }
            TriangleHit hit;
            if (intersect_watertight(ray, positions[tri.x], positions[tri.y], positions[tri.z], tmin, best, hit) &&
                replaces_nearest(
                    hit.t, best, found_triangle != kInvalidPrimitive, [&] { return items_[k]; },
                    [&] { return found_triangle; })) {
              best = hit.t;
              found = hit;
              found_triangle = items_[k];
              if constexpr (kAnyHit) break;
            }
          }
          if (kAnyHit && found_triangle != kInvalidPrimitive) break;
        }
        // Leave the cell: done once the nearest hit lies before the next cell begins.
        const int axis = walk.exit_axis();
        if (walk.next_crossing[axis] > pruning_distance(best) || walk.next_crossing[axis] > far) break;
        if (!walk.advance(axis, cells_)) break;
      }
      if (found_triangle != kInvalidPrimitive) {
        hits.set_hit(i, found.t, found_triangle, found.u, found.v);
        set_surface_from_mesh(hits, i, mesh_, found_triangle);
      }
    });
  }

  const TriangleMesh& mesh_;
  bool bounding_box_lists_ = false;
  Bounds3 bounds_;
  glm::vec3 upper_{0.0f};
  glm::uvec3 cells_{1};
  glm::vec3 cell_size_{1.0f}, inverse_cell_size_{1.0f};
  bool capped_ = false;
  double effective_density_ = 0.0;
  std::size_t max_cells_ = 0;
  std::size_t slot_count_ = 0;
  std::size_t row_scratch_bytes_ = 0;
  // About this many slabs of z layers: enough for both cores to balance dense and empty ones,
  // few enough that a triangle's box rarely crosses more than two.
  static constexpr std::uint32_t kTargetSlabs = 256;
  static constexpr std::size_t kTriangleBlocks = 64;
  std::uint32_t slab_layers_ = 1;
  std::vector<std::size_t> slab_starts_;      // slab s lists slab_triangles_[starts[s] .. starts[s + 1])
  UnfilledLargeArray<std::uint32_t> slab_triangles_;  // build temporary: sized unwritten, filled, freed after the lists
  struct MacrocellLevel {
    std::uint32_t span = 1;  // fine cells per block side
    glm::uvec3 cells{1};
    std::vector<std::uint64_t> bits;
    std::size_t index(const glm::uvec3& block) const { return (std::size_t(block.z) * cells.y + block.y) * cells.x + block.x; }
    bool occupied(const glm::uvec3& block) const {
      const std::size_t m = index(block);
      return (bits[m / 64] >> (m % 64)) & 1u;
    }
  };
  // The coarsest level whose block around `cell` is empty (levels nest, so checking from the
  // finest up stops at the first occupied one); null when the finest block holds items.
  template <typename Probe>
  const MacrocellLevel* coarsest_empty_macrocell(const glm::uvec3& cell, Probe& probe) const {
    const MacrocellLevel* empty = nullptr;
    for (const MacrocellLevel& level : macrocells_) {
      const std::size_t m = level.index(cell / level.span);
      probe.read(&level.bits[m / 64], sizeof(std::uint64_t));
      if (level.occupied(cell / level.span)) break;
      empty = &level;
    }
    return empty;
  }

  std::uint32_t macrocell_factor_ = 0;
  std::vector<MacrocellLevel> macrocells_;
  LargeArray<std::uint64_t> domain_;   // D
  LargeArray<std::uint32_t> offsets_;  // O
  LargeArray<std::uint32_t> starts_;   // H
  UnfilledLargeArray<std::uint32_t> items_;  // L: sized unwritten, first touched by the slab tasks that fill it
  BuildReport build_;
};

}  // namespace

// Woo's heuristic: M_i = S_i · cbrt(ρN / V), capped so that Mx·My·Mz stays in the guard.
GridResolution hashed_grid_resolution(const Bounds3& bounds, std::size_t triangles, const HashedGridOptions& options) {
  GridResolution resolution;
  const glm::vec3 extent = bounds.extent();
  const float floor_extent = std::max(1e-6f * bounds.diagonal(), 1e-30f);
  resolution.size = glm::dvec3(std::max(extent.x, floor_extent), std::max(extent.y, floor_extent),
                               std::max(extent.z, floor_extent));
  const glm::dvec3& size = resolution.size;
  glm::uvec3& cells = resolution.cells;
  double scale = std::cbrt(options.density * double(std::max<std::size_t>(triangles, 1)) / (size.x * size.y * size.z));
  for (int attempt = 0; attempt < 64; ++attempt) {
    for (int axis = 0; axis < 3; ++axis) {
      cells[axis] = static_cast<std::uint32_t>(std::clamp(std::ceil(size[axis] * scale), 1.0, double(1 << 21)));
    }
    if (double(cells.x) * cells.y * cells.z <= double(options.max_cells)) break;
    resolution.capped = true;
    scale *= 0.97 * std::cbrt(double(options.max_cells) / (double(cells.x) * cells.y * cells.z));
  }
  return resolution;
}

std::unique_ptr<Accelerator> make_hashed_grid_accelerator(const TriangleMesh& mesh, const HashedGridOptions& options) {
  return std::make_unique<HashedGridAccelerator>(mesh, options);
}

}  // namespace wavetrace
