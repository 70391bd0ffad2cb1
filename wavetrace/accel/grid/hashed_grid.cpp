// Construction of the hashed grid in slabs of z layers (a slab task finds its triangles' runs
// of cells once, and from them its D bits, first-fit row displacement for O, counts and prefix
// sums for H; the slabs' parts appended in order, each list filled in triangle order) and
// 3D-DDA traversal that stops once the nearest hit found lies before the next cell.
#include "wavetrace/accel/grid/hashed_grid.hpp"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_pipeline.h>
#include <tbb/task_arena.h>

#include "wavetrace/accel/grid/cell_runs_in_lanes.hpp"
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
    domain_.assign((std::size_t(cells_.x) * cells_.y * cells_.z + 63) / 64, 0);
    build_slab_parts(clock);
    slab_triangles_ = {};
    build_macrocells(options.macrocell_factor);
    clock.lap(build_.phases, "macrocells");
    build_.seconds = clock.elapsed();
    build_.peak_bytes = memory().total() + scratch_bytes_;  // an upper bound: the parts go as they are placed
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
    std::vector<std::size_t> box_cells(blocks, 0);
    const auto slabs_of = [&](std::size_t t) {
      const CellRange r = range_of(t);
      return std::pair(r.lower.z / slab_layers_, r.upper.z / slab_layers_);
    };
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
      std::size_t* block_counts = counts.data() + block * slabs;
      for (std::size_t t = block * block_size, end = std::min(triangles, t + block_size); t < end; ++t) {
        const CellRange r = range_of(t);
        const glm::uvec3 extent = r.upper - r.lower + 1u;
        box_cells[block] += std::size_t(extent.x) * extent.y * extent.z;
        for (std::uint32_t slab = r.lower.z / slab_layers_; slab <= r.upper.z / slab_layers_; ++slab) ++block_counts[slab];
      }
    });
    entries_bound_ = 0;
    for (const std::size_t cells : box_cells) entries_bound_ += cells;
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

  // A run of cells that a triangle of a slab overlaps, in 12 bytes: the slab's row
  // (z - z_first)·My + y, and the cells first() ..= last() in it, at most kLongestRun of them
  // (a longer run is several): x in the low 21 bits of `cells` (a grid has at most 2^21 cells
  // a side), the count less one in the high 11.
  struct SlabRowRun {
    static constexpr std::uint32_t kLongestRun = 1u << 11;
    std::uint32_t triangle, row, cells;
    std::uint32_t first() const { return cells & ((1u << 21) - 1); }
    std::uint32_t last() const { return first() + (cells >> 21); }
  };
  static_assert(sizeof(SlabRowRun) == 12);

  // One slab's share of the grid: its rows' offsets and slots numbered from the slab's own
  // first slot, where each slot's list starts from the slab's own first entry, and the runs
  // its lists are filled from. Rows of different slabs never share a slot, so each slab's
  // slots and entries are one range of H and of L, in slab order. A part is reused from slab
  // to slab, so the build's scratch is a few slabs' worth, touched once.
  struct SlabPart {
    CellRunBatch batch;  // with AVX-512, the visits whose runs are cut eight at a time
    std::vector<SlabRowRun> runs;
    std::vector<std::uint64_t> occupied;     // the slab's D bits: bit row·Mx + x of the slab's rows
    std::vector<std::uint64_t> taken;        // the slots its rows took (the paper's bH)
    std::vector<std::uint32_t> row;          // one row's occupied cells
    std::vector<std::uint32_t> row_offsets;  // kEmptyRow where the row has no occupied cell
    std::vector<std::uint32_t> starts;       // the slab's H, and one past its last slot
    std::size_t entries = 0;                 // its lists' length
    std::size_t entry_base = 0;              // where its lists start in L, once placed
    double stage_seconds[3] = {};            // runs, cells, fill: summed over the slabs it held
  };
  static constexpr std::uint32_t kEmptyRow = ~std::uint32_t{0};

  // Slabs made in parallel, placed in order and filled in parallel by a pipeline, a few in
  // flight: L grows in place into room reserved for the most entries the triangles' boxes
  // allow, so each list is written once, where it stays, and L's fresh pages are first
  // touched by both cores.
  void build_slab_parts(PhaseClock& clock) {
    const std::size_t slabs = slab_starts_.size() - 1;
    offsets_.assign(std::size_t(cells_.y) * cells_.z, 0);
    starts_.clear();
    items_.clear();
    // Address space only, untouched pages cost nothing: L's room is the most entries the
    // boxes allow, H's as much (in practice it needs about one slot per cell listed). Where
    // the OS will not map that, the arrays grow by reallocation, and the lists are filled as
    // each slab is placed.
    const std::size_t most_entries = std::min<std::size_t>(entries_bound_, std::numeric_limits<std::uint32_t>::max());
    try {
      items_.reserve(most_entries);
      starts_.reserve(most_entries + 1);
      lists_in_place_ = true;
    } catch (const std::bad_alloc&) {
      lists_in_place_ = false;
    }
    const std::size_t in_flight = std::size_t(tbb::this_task_arena::max_concurrency()) + 2;
    std::vector<SlabPart> parts(in_flight);
    std::vector<SlabPart*> free_parts;  // a part per live token: one is free whenever a slab starts
    for (SlabPart& part : parts) free_parts.push_back(&part);
    std::mutex free_parts_mutex;
    struct Work {
      std::size_t slab;
      SlabPart* part;
    };
    std::size_t next = 0;
    tbb::parallel_pipeline(
        in_flight,
        tbb::make_filter<void, Work>(tbb::filter_mode::serial_in_order,
                                     [&](tbb::flow_control& control) -> Work {
                                       if (next == slabs) {
                                         control.stop();
                                         return {};
                                       }
                                       const std::scoped_lock lock(free_parts_mutex);
                                       SlabPart* part = free_parts.back();
                                       free_parts.pop_back();
                                       return {next++, part};
                                     }) &
            tbb::make_filter<Work, Work>(tbb::filter_mode::parallel,
                                         [&](Work work) {
                                           build_slab(work.slab, *work.part);
                                           return work;
                                         }) &
            tbb::make_filter<Work, Work>(tbb::filter_mode::serial_in_order,
                                         [&](Work work) {
                                           place_slab_part(work.slab, *work.part);
                                           if (!lists_in_place_) fill_slab_lists(*work.part);
                                           return work;
                                         }) &
            tbb::make_filter<Work, void>(tbb::filter_mode::parallel, [&](Work work) {
              if (lists_in_place_) fill_slab_lists(*work.part);
              const std::scoped_lock lock(free_parts_mutex);
              free_parts.push_back(work.part);
            }));
    starts_.push_back(checked_uint32(items_.size(), "grid cell entries; lower accel.grid.density"));
    slot_count_ = starts_.size() - 1;
    for (const SlabPart& part : parts) {
      for (const auto& array : {part.row_offsets, part.starts, part.row}) {
        scratch_bytes_ += array.capacity() * sizeof(std::uint32_t);
      }
      scratch_bytes_ += part.runs.capacity() * sizeof(SlabRowRun) +
                        (part.occupied.capacity() + part.taken.capacity()) * sizeof(std::uint64_t);
    }
    scratch_bytes_ += slab_triangles_.size() * sizeof(std::uint32_t);
    clock.lap(build_.phases, "lists");
    // The pipeline's stages overlap: their thread-seconds, summed over slabs.
    double seconds[3] = {};
    for (const SlabPart& part : parts) {
      for (int stage = 0; stage < 3; ++stage) seconds[stage] += part.stage_seconds[stage];
    }
    build_.phases.add("lists.runs", seconds[0]);
    build_.phases.add("lists.cells", seconds[1]);
    build_.phases.add("lists.fill", seconds[2]);
    build_.phases.add("lists.place", place_seconds_);
  }

  // A slab's part after the slabs before it: its rows' offsets and its slots after theirs,
  // and the room for its lists after theirs.
  void place_slab_part(std::size_t slab, SlabPart& part) {
    PhaseClock clock;
    const std::size_t slot_base = starts_.size();
    part.entry_base = items_.size();
    if (part.entry_base + part.entries > std::numeric_limits<std::uint32_t>::max()) {
      throw std::runtime_error("grid: more than 2^32 cell entries; lower accel.grid.density");
    }
    std::uint32_t* offsets = offsets_.data() + slab * slab_layers_ * cells_.y;
    for (std::size_t r = 0; r < part.row_offsets.size(); ++r) {
      if (part.row_offsets[r] != kEmptyRow) {
        offsets[r] = checked_uint32(slot_base + part.row_offsets[r], "grid row offset; lower accel.grid.max_cells");
      }
    }
    for (std::size_t slot = 0; slot + 1 < part.starts.size(); ++slot) {
      starts_.push_back(static_cast<std::uint32_t>(part.entry_base + part.starts[slot]));
    }
    // The slabs up to this one are made, so the lists of their triangles are read.
    release_read_pages(slab_triangles_.data(), slab_triangles_.data() + slab_starts_[slab + 1]);
    // Within the room reserved L must not move: earlier slabs' lists are being written.
    if (lists_in_place_ && part.entry_base + part.entries > items_.capacity()) {
      throw std::logic_error("grid: the lists outgrew the room their triangles' boxes allow");
    }
    items_.resize(part.entry_base + part.entries);
    place_seconds_ += clock.elapsed();
  }

  // A placed slab's lists, from its runs in their (ascending triangle) order.
  void fill_slab_lists(SlabPart& part) {
    PhaseClock clock;
    std::uint32_t* lists = items_.data() + part.entry_base;
    for (const SlabRowRun& run : part.runs) {
      std::uint32_t* cursors = part.starts.data() + part.row_offsets[run.row];
      for (std::uint32_t x = run.first(), last = run.last(); x <= last; ++x) lists[cursors[x]++] = run.triangle;
    }
    part.stage_seconds[2] += clock.elapsed();
  }

  // One slab's runs, and from them its cells' D bits, its rows' first-fit displacement (from
  // the slab's own first slot: slabs never share one), its counts and their prefix sums. A
  // slab's cells are its own, so only D's words at the slab's two ends are shared with
  // another task.
  void build_slab(std::size_t slab, SlabPart& part) {
    const std::uint32_t z_first = std::uint32_t(slab) * slab_layers_;
    const std::uint32_t z_last = std::min(cells_.z - 1, z_first + slab_layers_ - 1);
    const std::size_t rows = std::size_t(z_last - z_first + 1) * cells_.y, row_cells = cells_.x;

    PhaseClock clock;
    std::vector<SlabRowRun>& runs = part.runs;
    runs.clear();
    const CellGridFrame frame{glm::dvec3(bounds_.lower), glm::dvec3(cell_size_), glm::dvec3(cell_size_ * 1e-3f)};
    const std::size_t slab_end = slab_starts_[slab + 1];
    const auto add = [&](std::uint32_t t, std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
      const std::uint32_t row = (z - z_first) * cells_.y + y;
      for (; x_last - x_first >= SlabRowRun::kLongestRun; x_first += SlabRowRun::kLongestRun) {
        runs.push_back({t, row, x_first | ((SlabRowRun::kLongestRun - 1) << 21)});
      }
      runs.push_back({t, row, x_first | ((x_last - x_first) << 21)});
    };
    CellRunBatch& batch = part.batch;
    batch.use(kernel_isa());
    for (std::size_t k = slab_starts_[slab]; k < slab_end; ++k) {
      // A slab's triangles are scattered over the mesh: their corners fetched ahead.
      if (k + kPrefetchAhead < slab_end) {
        const glm::uvec3& ahead = mesh_.triangles[slab_triangles_[k + kPrefetchAhead]];
        for (int corner = 0; corner < 3; ++corner) __builtin_prefetch(&mesh_.positions[ahead[corner]]);
      }
      if (k + 2 * kPrefetchAhead < slab_end) __builtin_prefetch(&mesh_.triangles[slab_triangles_[k + 2 * kPrefetchAhead]]);
      const std::uint32_t t = slab_triangles_[k];
      const CellRange r = range_of(t);
      if (bounding_box_lists_) {
        for (std::uint32_t z = std::max(r.lower.z, z_first); z <= std::min(r.upper.z, z_last); ++z) {
          for (std::uint32_t y = r.lower.y; y <= r.upper.y; ++y) add(t, y, z, r.lower.x, r.upper.x);
        }
        continue;
      }
      const glm::uvec3& tri = mesh_.triangles[t];
      const TriangleCellVisit visit{mesh_.positions[tri.x], mesh_.positions[tri.y], mesh_.positions[tri.z],
                                    r.lower, r.upper, z_first, z_last};
      if (batch.lanes()) {
        batch.add(t, visit, frame, add);
      } else {
        for_each_triangle_cell_run(visit.a, visit.b, visit.c, frame, r.lower, r.upper, z_first, z_last,
                                   [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
                                     add(t, y, z, x_first, x_last);
                                   });
      }
    }
    batch.flush(frame, add);

    part.stage_seconds[0] += clock.lap();
    std::vector<std::uint64_t>& occupied = part.occupied;
    occupied.assign((rows * row_cells + 63) / 64, 0);
    for (const SlabRowRun& run : runs) set_bits(occupied, run.row * row_cells + run.first(), run.row * row_cells + run.last());
    merge_into_domain(occupied, std::size_t(z_first) * cells_.y * row_cells);

    // First fit from the last row's offset, as the paper builds O: each row's occupied cells
    // land on slots that no earlier row of the slab took.
    std::vector<std::uint64_t>& taken = part.taken;
    taken.assign(std::max<std::size_t>(taken.size(), 1024), 0);
    const auto is_taken = [&](std::size_t slot) { return slot / 64 < taken.size() && ((taken[slot / 64] >> (slot % 64)) & 1u); };
    std::vector<std::uint32_t>& row = part.row;
    part.row_offsets.assign(rows, kEmptyRow);
    std::size_t last_offset = 0, used_slots = 0;
    for (std::size_t r = 0; r < rows; ++r) {
      row.clear();
      for_each_set_bit(occupied.data(), r * row_cells, row_cells, [&](std::uint32_t x) { row.push_back(x); });
      if (row.empty()) continue;  // never read: its D bits are all clear
      std::size_t offset = last_offset;
      while (std::any_of(row.begin(), row.end(), [&](std::uint32_t x) { return is_taken(offset + x); })) ++offset;
      const std::size_t end = offset + row.back() + 1;
      if ((end + 63) / 64 > taken.size()) taken.resize(std::max(taken.size() * 2, (end + 63) / 64), 0);
      for (std::uint32_t x : row) taken[(offset + x) / 64] |= std::uint64_t{1} << ((offset + x) % 64);
      part.row_offsets[r] = checked_uint32(offset, "grid row offset; lower accel.grid.max_cells");
      used_slots = std::max(used_slots, end);
      last_offset = offset;
    }

    // Counts per slot, then their exclusive prefix sums: where each slot's list starts.
    auto& starts = part.starts;
    starts.assign(used_slots + 1, 0);
    for (const SlabRowRun& run : runs) {
      std::uint32_t* slots = starts.data() + part.row_offsets[run.row];
      for (std::uint32_t x = run.first(), last = run.last(); x <= last; ++x) ++slots[x];
    }
    std::uint64_t total = 0;
    for (std::uint32_t& start : starts) {
      const std::uint32_t count = start;
      start = static_cast<std::uint32_t>(std::min<std::uint64_t>(total, std::numeric_limits<std::uint32_t>::max()));
      total += count;
    }
    part.entries = total;
    part.stage_seconds[1] += clock.lap();
  }

  // Sets bits first ..= last.
  static void set_bits(std::vector<std::uint64_t>& bits, std::size_t first, std::size_t last) {
    for (std::size_t word = first / 64; word <= last / 64; ++word) {
      std::uint64_t mask = ~std::uint64_t{0};
      if (word == first / 64) mask &= ~std::uint64_t{0} << (first % 64);
      if (word == last / 64) mask &= ~std::uint64_t{0} >> (63 - last % 64);
      bits[word] |= mask;
    }
  }

  // ORs a slab's bits into D from D's bit `first`: atomic, since a word at either end of the
  // slab may hold another slab's cells.
  void merge_into_domain(const std::vector<std::uint64_t>& bits, std::size_t first) {
    const std::size_t first_word = first / 64, shift = first % 64;
    const auto merge = [&](std::size_t word, std::uint64_t mask) {
      if (mask != 0) std::atomic_ref<std::uint64_t>(domain_[word]).fetch_or(mask, std::memory_order_relaxed);
    };
    for (std::size_t word = 0; word < bits.size(); ++word) {
      if (bits[word] == 0) continue;
      merge(first_word + word, bits[word] << shift);
      if (shift != 0) merge(first_word + word + 1, bits[word] >> (64 - shift));
    }
  }

  // Calls f(i) for each set bit first + i of `bits`, i < count ascending: a word at a time,
  // since rows are mostly empty.
  template <typename F>
  static void for_each_set_bit(const std::uint64_t* bits, std::size_t first, std::size_t count, F&& f) {
    const std::size_t end = first + count;
    for (std::size_t word = first / 64; word * 64 < end; ++word) {
      std::uint64_t mask = bits[word];
      if (word * 64 < first) mask &= ~std::uint64_t{0} << (first - word * 64);
      if ((word + 1) * 64 > end) mask &= ~std::uint64_t{0} >> ((word + 1) * 64 - end);
      for (; mask != 0; mask &= mask - 1) f(std::uint32_t(word * 64 + std::countr_zero(mask) - first));
    }
  }

  bool occupied(std::size_t d) const { return (domain_[d / 64] >> (d % 64)) & 1u; }

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
          for_each_set_bit(domain_.data(), cell_index(0, y, z), cells_.x,
                           [&](std::uint32_t x) { mark(glm::uvec3(x, y, z) / span); });
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
  std::size_t scratch_bytes_ = 0;  // the slab lists and the parts in flight (build only)
  double place_seconds_ = 0.0;
  bool lists_in_place_ = true;  // L's room reserved: slabs' lists filled in parallel (build only)
  std::size_t entries_bound_ = 0;  // L's length at most: the cells the triangles' boxes overlap
  // About this many slabs of z layers: enough that a slab's runs (a part's scratch) stay a
  // few MiB, few enough that a triangle is visited again in only a few neighbouring slabs
  // (room:8M: 2 layers a slab; 4 build as fast and hold more runs at once).
  static constexpr std::uint32_t kTargetSlabs = 512;
  static constexpr std::size_t kTriangleBlocks = 64;
  static constexpr std::size_t kPrefetchAhead = 8;  // triangles
  std::uint32_t slab_layers_ = 1;
  std::vector<std::size_t> slab_starts_;      // slab s lists slab_triangles_[starts[s] .. starts[s + 1])
  UnfilledLargeArray<std::uint32_t> slab_triangles_;  // build temporary: sized unwritten, filled, handed back as read
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
  UnfilledLargeArray<std::uint32_t> items_;  // L: grown unwritten, filled slab by slab
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
