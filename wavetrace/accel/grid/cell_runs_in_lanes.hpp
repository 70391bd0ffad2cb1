// The grids' runs of cells (kernels/triangle_cell_runs.hpp) for eight triangles at once, a
// triangle a lane of AVX-512 doubles, where the CPU has it: half of a grid's build is finding
// such runs, most of it for triangles whose boxes span several cells on every axis (a strand
// of fur), for which the scalar function's branches a layer and a row cost the most.
#pragma once

#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX512_DISPATCH, WAVETRACE_AVX512F

#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/vec3.hpp>

#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/kernels/triangle_cell_runs.hpp"

namespace wavetrace {

// One call's worth of for_each_triangle_cell_run: a triangle, its box of cells and the layers asked.
struct TriangleCellVisit {
  glm::vec3 a, b, c;
  glm::uvec3 box_lower, box_upper;
  std::uint32_t z_first, z_last;
};

// A visit's runs as for_each_triangle_cell_run calls them back, (y, z, x_first, x_last), in its order.
struct CellRunList {
  static constexpr std::uint32_t kMaxLayers = 4, kMaxRows = 16;
  struct Run {
    std::uint32_t y, z, x_first, x_last;
  };
  std::uint32_t count;
  Run runs[kMaxLayers * kMaxRows + 1];  // and one that a lane stores to without taking it
};

// Whether walks of this kernel set find runs in lanes: the AVX-512 set, whether chosen at start
// or the build's own. (In AVX2's four lanes of doubles the runs took as long as one at a time.)
inline bool cell_runs_in_lanes(KernelIsa isa) {
#if WAVETRACE_AVX512_DISPATCH
  return isa == KernelIsa::avx512;
#elif WAVETRACE_AVX512F
  return true;
#else
  (void)isa;
  return false;
#endif
}

// Whether the lanes take this visit: its box at most one cell thick on one axis (a line of
// cells has the scalar function's shortcut, without geometry), not level in z (a case of its
// own), and within a list's room: at most kMaxLayers layers asked, kMaxRows rows across.
inline bool fits_cell_run_lanes(const TriangleCellVisit& visit) {
  const std::uint32_t z_first = visit.box_lower.z > visit.z_first ? visit.box_lower.z : visit.z_first;
  const std::uint32_t z_last = visit.box_upper.z < visit.z_last ? visit.box_upper.z : visit.z_last;
  const int thin_axes = int(visit.box_lower.x == visit.box_upper.x) + int(visit.box_lower.y == visit.box_upper.y) +
                        int(visit.box_lower.z == visit.box_upper.z);
  const bool level = visit.a.z == visit.b.z && visit.b.z == visit.c.z;
  return thin_axes < 2 && !level && z_first <= z_last && z_last - z_first < CellRunList::kMaxLayers &&
         visit.box_upper.y - visit.box_lower.y < CellRunList::kMaxRows;
}

#if WAVETRACE_AVX512_DISPATCH || WAVETRACE_AVX512F
// The runs of up to eight visits that fits_cell_run_lanes takes, visit k's into *out[k]: each
// lane makes for_each_triangle_cell_run's operations in its order (no contraction), so each
// visit gets the same runs, bit for bit, in the same order. Only where cell_runs_in_lanes.
void triangle_cell_runs_in_eight_lanes(const TriangleCellVisit* const* visits, int count, const CellGridFrame& frame,
                                       CellRunList* const* out);
#endif

// A batch of a slab's triangle visits: where the kernel set has the lanes, those they take
// are cut eight at a time, the others one at a time; then every visit's runs are handed on in
// the order the visits came, so that a grid's lists stay in triangle order.
class CellRunBatch {
 public:
  static constexpr std::size_t kVisits = 32;

  void use(KernelIsa isa) { lanes_ = cell_runs_in_lanes(isa); }
  bool lanes() const { return lanes_; }

  // Takes a visit of `triangle`; a full batch is handed on: run(triangle, y, z, x_first, x_last).
  template <typename Run>
  void add(std::uint32_t triangle, const TriangleCellVisit& visit, const CellGridFrame& frame, Run&& run) {
    visits_[count_] = visit;
    in_lanes_[count_] = lanes_ && fits_cell_run_lanes(visit);
    triangles_[count_] = triangle;
    if (++count_ == kVisits) flush(frame, run);
  }

  template <typename Run>
  void flush(const CellGridFrame& frame, Run&& run) {
#if WAVETRACE_AVX512_DISPATCH || WAVETRACE_AVX512F
    const TriangleCellVisit* lane_visits[8];
    CellRunList* lane_lists[8];
    int lanes = 0;
    for (std::size_t i = 0; i < count_; ++i) {
      if (!in_lanes_[i]) continue;
      lane_visits[lanes] = &visits_[i], lane_lists[lanes] = &lists_[i];
      if (++lanes == 8) triangle_cell_runs_in_eight_lanes(lane_visits, lanes, frame, lane_lists), lanes = 0;
    }
    if (lanes != 0) triangle_cell_runs_in_eight_lanes(lane_visits, lanes, frame, lane_lists);
#endif
    for (std::size_t i = 0; i < count_; ++i) {
      const std::uint32_t triangle = triangles_[i];
      const auto of_triangle = [&](std::uint32_t y, std::uint32_t z, std::uint32_t x_first, std::uint32_t x_last) {
        run(triangle, y, z, x_first, x_last);
      };
      if (in_lanes_[i]) {
        for (const CellRunList::Run& r : std::span(lists_[i].runs, lists_[i].count)) of_triangle(r.y, r.z, r.x_first, r.x_last);
      } else {
        const TriangleCellVisit& v = visits_[i];
        for_each_triangle_cell_run(v.a, v.b, v.c, frame, v.box_lower, v.box_upper, v.z_first, v.z_last, of_triangle);
      }
    }
    count_ = 0;
  }

 private:
  bool lanes_ = false;
  std::size_t count_ = 0;
  std::uint32_t triangles_[kVisits];
  bool in_lanes_[kVisits];
  TriangleCellVisit visits_[kVisits];
  CellRunList lists_[kVisits];
};

}  // namespace wavetrace
