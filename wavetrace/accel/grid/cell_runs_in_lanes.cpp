// triangle_cell_runs_in_eight_lanes. In the default (AVX2) build this file alone is compiled
// for x86-64-v4 (CMakeLists.txt), so that GCC's generic vectors of eight doubles become
// AVX-512 instructions; behind a target attribute it split them lane by lane and ran the runs
// slower than one triangle at a time. Nothing here may be an inline function or template that
// another file also instantiates (the linker keeps one copy, which must not be this file's):
// its helpers live in an anonymous namespace and call no std::min, std::max or glm operator.
#include "wavetrace/accel/grid/cell_runs_in_lanes.hpp"

#include <cstring>
#include <limits>

namespace wavetrace {
#if WAVETRACE_AVX512_DISPATCH || WAVETRACE_AVX512F
namespace {

constexpr int kLanes = 8;
using Real = double __attribute__((vector_size(64)));
using Mask = std::int64_t __attribute__((vector_size(64)));  // all ones where true
using Cell = std::int32_t __attribute__((vector_size(32)));
constexpr double kInfinity = std::numeric_limits<double>::infinity();

// std::min(a, b) is (b < a) ? b : a and std::max(a, b) is (a < b) ? b : a: written so, lane by lane.
inline Real min_of(Real a, Real b) { return b < a ? b : a; }
inline Real max_of(Real a, Real b) { return a < b ? b : a; }

inline unsigned lanes_set(Mask mask) {
  unsigned bits = 0;
  for (int lane = 0; lane < kLanes; ++lane) bits |= unsigned(mask[lane] != 0) << lane;
  return bits;
}

// One axis of the grid's frame, as cells_spanned reads it.
struct Axis {
  double lower, cell_size, slack, inverse_cell_size;
};

// cells_spanned in lanes: the cells [first, last] of the box that [least, most] meets. The
// scalar clamps floor(v) to [first, last]; for integers 0 <= first <= last that is v clamped
// to them, then truncated.
inline void cells_spanned(const Axis& axis, Real least, Real most, Real first, Real last, Cell& low, Cell& high) {
  const Real from = (least - axis.slack - axis.lower) * axis.inverse_cell_size;
  const Real to = (most + axis.slack - axis.lower) * axis.inverse_cell_size;
  low = __builtin_convertvector(from < first ? first : (last < from ? last : from), Cell);
  high = __builtin_convertvector(to < first ? first : (last < to ? last : to), Cell);
}

struct Point {
  Real x, y;
};

// An edge of a layer's section as EdgesAlongY keeps it; `on` says in which lanes it exists.
struct LaneEdge {
  Real y_low, y_high, x_at_y_low, x_per_y, x_other;
  Mask on;

  LaneEdge(const Point& from, const Point& to, Mask on_lanes) : on(on_lanes) {
    const Mask swap = to.y < from.y;
    const Real ax = swap ? to.x : from.x, ay = swap ? to.y : from.y;
    const Real bx = swap ? from.x : to.x, by = swap ? from.y : to.y;
    const Real dy = by - ay;
    const Mask rising = dy > 0.0;
    y_low = ay, y_high = by, x_at_y_low = ax;
    x_per_y = rising ? (bx - ax) / dy : Real{};
    x_other = rising ? ax : bx;
  }
  // EdgesAlongY::x_extent's step for this edge.
  void widen(Real lo, Real hi, Real& least, Real& most) const {
    const Real from = max_of(lo, y_low), to = min_of(hi, y_high);
    const Mask meets = on & ~(from > to);
    const Real x0 = x_at_y_low + (from - y_low) * x_per_y;
    const Real x1 = x_per_y != 0.0 ? x_at_y_low + (to - y_low) * x_per_y : x_other;
    least = meets ? min_of(min_of(least, x0), x1) : least;
    most = meets ? max_of(max_of(most, x0), x1) : most;
  }
};

// A vector's lanes as an array, stored once rather than extracted lane by lane.
struct CellLanes {
  std::int32_t lane[kLanes];
  explicit CellLanes(Cell v) { std::memcpy(lane, &v, sizeof v); }
};

struct Corner {
  Real x, y, z;
};

}  // namespace

void triangle_cell_runs_in_eight_lanes(const TriangleCellVisit* const* visits, int count, const CellGridFrame& frame,
                                       CellRunList* const* out) {
  const Axis along_x{frame.lower.x, frame.cell_size.x, frame.slack.x, frame.inverse_cell_size.x};
  const Axis along_y{frame.lower.y, frame.cell_size.y, frame.slack.y, frame.inverse_cell_size.y};

  // Lanes past `count` repeat the first visit into spare lists: every lane stores its runs and
  // counts those it takes, and none branches on its own. Gathered as scalars, then loaded a
  // row of lanes at a time.
  CellRunList spare[kLanes - 1];
  CellRunList* lists[kLanes];
  alignas(64) double gathered[17][kLanes];  // corners' x y z (9 rows), boxes' lower and upper (6), layers (2)
  for (int lane = 0; lane < kLanes; ++lane) {
    const TriangleCellVisit& v = *visits[lane < count ? lane : 0];
    lists[lane] = lane < count ? out[lane] : &spare[lane - 1];
    lists[lane]->count = 0;
    const glm::vec3* corners[3] = {&v.a, &v.b, &v.c};
    for (int c = 0; c < 3; ++c) {
      gathered[3 * c][lane] = corners[c]->x, gathered[3 * c + 1][lane] = corners[c]->y, gathered[3 * c + 2][lane] = corners[c]->z;
    }
    gathered[9][lane] = v.box_lower.x, gathered[10][lane] = v.box_lower.y, gathered[11][lane] = v.box_lower.z;
    gathered[12][lane] = v.box_upper.x, gathered[13][lane] = v.box_upper.y, gathered[14][lane] = v.box_upper.z;
    gathered[15][lane] = v.box_lower.z > v.z_first ? v.box_lower.z : v.z_first;
    gathered[16][lane] = v.box_upper.z < v.z_last ? v.box_upper.z : v.z_last;
  }
  const auto row = [&](int r) {
    Real value;
    std::memcpy(&value, gathered[r], sizeof value);
    return value;
  };
  const Real box_lower_x = row(9), box_lower_y = row(10), box_upper_x = row(12), box_upper_y = row(13);
  const Real z_first = row(15), z_last = row(16);

  // TriangleLayers: the corners sorted by z, and each edge's (x, y) per unit of z.
  Corner low{row(0), row(1), row(2)}, middle{row(3), row(4), row(5)}, high{row(6), row(7), row(8)};
  const auto swap_where = [](Mask swap, Corner& p, Corner& q) {
    const Corner was = p;
    p = {swap ? q.x : p.x, swap ? q.y : p.y, swap ? q.z : p.z};
    q = {swap ? was.x : q.x, swap ? was.y : q.y, swap ? was.z : q.z};
  };
  swap_where(middle.z < low.z, low, middle);
  swap_where(high.z < middle.z, middle, high);
  swap_where(middle.z < low.z, low, middle);
  const auto per_z = [](const Corner& from, const Corner& to) {
    const Real rise = to.z - from.z;
    const Mask rising = rise > 0.0;
    return Point{rising ? (to.x - from.x) / rise : Real{}, rising ? (to.y - from.y) / rise : Real{}};
  };
  const Point low_to_middle = per_z(low, middle), middle_to_high = per_z(middle, high), low_to_high = per_z(low, high);
  const auto on_long = [&](Real z) {
    return Point{low.x + low_to_high.x * (z - low.z), low.y + low_to_high.y * (z - low.z)};
  };
  const auto on_short = [&](Real z) {
    const Mask below = z < middle.z;
    return Point{below ? low.x + low_to_middle.x * (z - low.z) : middle.x + middle_to_high.x * (z - middle.z),
                 below ? low.y + low_to_middle.y * (z - low.z) : middle.y + middle_to_high.y * (z - middle.z)};
  };

  const Mask thin_x = box_lower_x == box_upper_x, thin_z = row(11) == row(14);
  const Mask all = z_first == z_first;
  double layers = 0.0;
  for (int lane = 0; lane < kLanes; ++lane) {
    const double of_lane = gathered[16][lane] - gathered[15][lane] + 1.0;
    layers = of_lane > layers ? of_lane : layers;
  }

  for (double layer = 0.0; layer < layers; layer += 1.0) {
    const Real z = z_first + layer;
    const Real bottom_z = frame.lower.z + z * frame.cell_size.z;
    // A box one layer thick takes the whole triangle, as the scalar function's section does.
    const Real lo = thin_z ? Real{} - kInfinity : bottom_z - frame.slack.z;
    const Real hi = thin_z ? Real{} + kInfinity : bottom_z + frame.cell_size.z + frame.slack.z;
    // TriangleLayers::section: the part of the triangle in this layer (never level here).
    const Mask live = ~((hi < low.z) | (lo > high.z) | (z_last < z));
    if (lanes_set(live) == 0) continue;
    const Real bottom = max_of(lo, low.z), top = min_of(hi, high.z);
    const Point p0 = on_long(bottom), p1 = on_long(top), p2 = on_short(top), p4 = on_short(bottom);
    const Point p3{middle.x, middle.y};
    const Mask with_middle = (bottom < middle.z) & (middle.z < top);
    // The section's extents over its corners in the scalar order (p0 p1 p2 [p3] p4).
    const auto extent = [&](Real Point::*axis, Real& least, Real& most) {
      least = min_of(min_of(p0.*axis, p1.*axis), p2.*axis);
      most = max_of(max_of(p0.*axis, p1.*axis), p2.*axis);
      least = min_of(with_middle ? min_of(least, p3.*axis) : least, p4.*axis);
      most = max_of(with_middle ? max_of(most, p3.*axis) : most, p4.*axis);
    };
    Real least_y, most_y, least_x, most_x;
    extent(&Point::y, least_y, most_y);
    extent(&Point::x, least_x, most_x);
    // A box one cell across clamps any extent to its cell: the scalar function's shortcut.
    Cell row_first, row_last, one_row_first, one_row_last;
    cells_spanned(along_y, least_y, most_y, box_lower_y, box_upper_y, row_first, row_last);
    cells_spanned(along_x, least_x, most_x, box_lower_x, box_upper_x, one_row_first, one_row_last);

    // A section in one row gives its run now (x from its corners); in several, a run a row
    // below (x from its edges; a box one cell wide in x, a column of rows, takes every row).
    const Mask one_row = __builtin_convertvector(row_first == row_last, Mask) & live;
    const Mask several_rows = live & ~one_row;
    const unsigned one_row_lanes = lanes_set(one_row);
    const Cell layer_cells = __builtin_convertvector(z, Cell);
    const CellLanes first_rows(row_first), layer_of(layer_cells), one_first(one_row_first), one_last(one_row_last);
    const CellLanes rows_of((row_last - row_first + 1) & __builtin_convertvector(several_rows, Cell));
    std::int32_t rows = 0;
    for (int lane = 0; lane < kLanes; ++lane) {
      CellRunList& list = *lists[lane];
      list.runs[list.count] = {std::uint32_t(first_rows.lane[lane]), std::uint32_t(layer_of.lane[lane]),
                               std::uint32_t(one_first.lane[lane]), std::uint32_t(one_last.lane[lane])};
      list.count += (one_row_lanes >> lane) & 1u;
      rows = rows_of.lane[lane] > rows ? rows_of.lane[lane] : rows;
    }
    if (rows == 0) continue;

    // EdgesAlongY over the section: four corners (p0 p1 p2 p4) or five (p0 p1 p2 p3 p4).
    const LaneEdge edges[6] = {LaneEdge(p0, p1, all),         LaneEdge(p1, p2, all),
                               LaneEdge(p2, p3, with_middle), LaneEdge(p3, p4, with_middle),
                               LaneEdge(p2, p4, ~with_middle), LaneEdge(p4, p0, all)};
    const Real first_y = __builtin_convertvector(row_first, Real), last_y = __builtin_convertvector(row_last, Real);
    for (std::int32_t r = 0; r < rows; ++r) {
      const Real y = first_y + double(r);
      const Real bottom_y = frame.lower.y + y * frame.cell_size.y;
      const Real row_lo = bottom_y - frame.slack.y, row_hi = bottom_y + frame.cell_size.y + frame.slack.y;
      Real least = Real{} + kInfinity, most = Real{} - kInfinity;
      for (const LaneEdge& edge : edges) edge.widen(row_lo, row_hi, least, most);
      const unsigned taking = lanes_set(several_rows & (y <= last_y) & (thin_x | (least <= most)));
      if (taking == 0) continue;
      Cell x_first, x_last;
      cells_spanned(along_x, least, most, box_lower_x, box_upper_x, x_first, x_last);
      const CellLanes first(x_first), last(x_last), row_of(row_first + r);
      for (int lane = 0; lane < kLanes; ++lane) {
        CellRunList& list = *lists[lane];
        list.runs[list.count] = {std::uint32_t(row_of.lane[lane]), std::uint32_t(layer_of.lane[lane]),
                                 std::uint32_t(first.lane[lane]), std::uint32_t(last.lane[lane])};
        list.count += (taking >> lane) & 1u;
      }
    }
  }
}
#endif

}  // namespace wavetrace
