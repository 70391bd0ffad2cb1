// The cells of a uniform grid that a triangle itself overlaps, as runs along x, row by row:
// the triangle's section by each layer of cells (z), that section cut by each row (y), the
// run the x extent of what is left. A grid that lists a triangle in every cell of its
// bounding box lists a thin triangle lying across the grid in about n^3 cells where it
// overlaps about n; these runs list it in those n.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>

namespace wavetrace {

// A uniform grid's placement: cell (x, y, z) spans lower + (x, y, z) · cell_size to one cell
// further, grown by `slack` on every side so that a walk's rounding at a cell face never
// skips a cell holding a triangle the ray meets there.
struct CellGridFrame {
  glm::dvec3 lower{0.0};
  glm::dvec3 cell_size{1.0};
  glm::dvec3 slack{0.0};
  glm::dvec3 inverse_cell_size = 1.0 / cell_size;  // a row's cells found without a division
};

namespace triangle_cell_runs_detail {

// A triangle's sections by layers of z: its corners sorted by z, the part between two heights
// is the quadrilateral (or pentagon, with the middle corner between them) between the long
// edge (lowest corner to highest) and the two short ones, so a layer costs no clipping and
// no division. Only x and y are kept: the rows are cut in the layer's plane.
class TriangleLayers {
 public:
  TriangleLayers(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c) {
    corners_[0] = glm::dvec3(a), corners_[1] = glm::dvec3(b), corners_[2] = glm::dvec3(c);
    if (corners_[1].z < corners_[0].z) std::swap(corners_[0], corners_[1]);
    if (corners_[2].z < corners_[1].z) std::swap(corners_[1], corners_[2]);
    if (corners_[1].z < corners_[0].z) std::swap(corners_[0], corners_[1]);
    for (int edge = 0; edge < 3; ++edge) {  // 0: lowest to middle, 1: middle to highest, 2: lowest to highest
      const glm::dvec3 &from = corners_[edge == 1 ? 1 : 0], &to = corners_[edge == 0 ? 1 : 2];
      const double rise = to.z - from.z;
      per_z_[edge] = rise > 0.0 ? glm::dvec2(to - from) / rise : glm::dvec2(0.0);
    }
  }

  // The corners, in order around, of the part with lo <= z <= hi; 0 when none.
  int section(double lo, double hi, glm::dvec2* out) const {
    const glm::dvec3 &low = corners_[0], &middle = corners_[1], &high = corners_[2];
    if (hi < low.z || lo > high.z) return 0;
    if (high.z == low.z) {  // level: all of it
      for (int i = 0; i < 3; ++i) out[i] = glm::dvec2(corners_[i]);
      return 3;
    }
    const double bottom = std::max(lo, low.z), top = std::min(hi, high.z);
    const auto on_long = [&](double z) { return glm::dvec2(low) + per_z_[2] * (z - low.z); };
    const auto on_short = [&](double z) {
      // At the middle corner's height its upper edge, which starts there: right also where
      // the lower edge is level (the middle corner as high as the lowest).
      return z < middle.z ? glm::dvec2(low) + per_z_[0] * (z - low.z) : glm::dvec2(middle) + per_z_[1] * (z - middle.z);
    };
    int n = 0;
    out[n++] = on_long(bottom);
    out[n++] = on_long(top);
    out[n++] = on_short(top);
    if (bottom < middle.z && middle.z < top) out[n++] = glm::dvec2(middle);
    out[n++] = on_short(bottom);
    return n;
  }

 private:
  glm::dvec3 corners_[3];
  glm::dvec2 per_z_[3];  // (x, y) per unit of z along each edge
};

// A convex polygon's edges ready to be cut by rows of cells: the polygon's part within
// lo <= y <= hi has as corners the polygon's corners inside the slab and its edges' crossings
// of the slab's planes, so its x extent is that of the edges each clipped to the slab.
// Each edge is kept as its y span and x as a line in y, so that a row costs no division.
struct EdgesAlongY {
  struct Edge {
    double y_low, y_high;  // the edge's y span
    double x_at_y_low, x_per_y;  // x = x_at_y_low + (y - y_low) · x_per_y; a level edge: x_per_y = 0,
    double x_other;              // and x_other its other end's x
  };
  Edge edges[5];
  int count = 0;

  EdgesAlongY(const glm::dvec2* polygon, int n) {
    for (int i = 0; i < n; ++i) {
      glm::dvec2 a = polygon[i], b = polygon[i + 1 == n ? 0 : i + 1];
      if (b.y < a.y) std::swap(a, b);
      const double dy = b.y - a.y;
      edges[count++] = {a.y, b.y, a.x, dy > 0.0 ? (b.x - a.x) / dy : 0.0, dy > 0.0 ? a.x : b.x};
    }
  }

  // False when no part of the polygon lies in the slab.
  bool x_extent(double lo, double hi, double& least, double& most) const {
    least = std::numeric_limits<double>::infinity();
    most = -least;
    for (int i = 0; i < count; ++i) {
      const Edge& e = edges[i];
      const double from = std::max(lo, e.y_low), to = std::min(hi, e.y_high);
      if (from > to) continue;
      const double x0 = e.x_at_y_low + (from - e.y_low) * e.x_per_y;
      const double x1 = e.x_per_y != 0.0 ? e.x_at_y_low + (to - e.y_low) * e.x_per_y : e.x_other;
      least = std::min({least, x0, x1});
      most = std::max({most, x0, x1});
    }
    return least <= most;
  }
};

// The cells along `axis` that the values [least, most] overlap (cells grown by the slack),
// within the bounding box's cells [first, last].
inline void cells_spanned(const CellGridFrame& frame, int axis, double least, double most, std::uint32_t first,
                          std::uint32_t last, std::uint32_t& low, std::uint32_t& high) {
  const double from = std::floor((least - frame.slack[axis] - frame.lower[axis]) * frame.inverse_cell_size[axis]);
  const double to = std::floor((most + frame.slack[axis] - frame.lower[axis]) * frame.inverse_cell_size[axis]);
  low = std::uint32_t(std::clamp(from, double(first), double(last)));
  high = std::uint32_t(std::clamp(to, double(first), double(last)));
}

}  // namespace triangle_cell_runs_detail

// Calls run(y, z, x_first, x_last) for each row of cells (y, z), z within [z_first, z_last],
// that triangle (a, b, c) overlaps, rows in (z, y) order, never outside the cells of its
// bounding box [box_lower, box_upper] (inclusive; grown by the slack as the caller finds
// them). The triangle lies in the grid, as a grid spans its mesh (a part outside would widen
// its border rows' runs). Degenerate triangles (segments, points) give the runs of what they are.
template <typename Run>
void for_each_triangle_cell_run(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const CellGridFrame& frame,
                                const glm::uvec3& box_lower, const glm::uvec3& box_upper, std::uint32_t z_first,
                                std::uint32_t z_last, Run&& run) {
  using namespace triangle_cell_runs_detail;
  z_first = std::max(box_lower.z, z_first);
  z_last = std::min(box_upper.z, z_last);
  const bool thin_x = box_lower.x == box_upper.x, thin_y = box_lower.y == box_upper.y, thin_z = box_lower.z == box_upper.z;
  if (int(thin_x) + int(thin_y) + int(thin_z) >= 2) {
    // A line of cells: the triangle, connected and within the slack of each, meets them all.
    for (std::uint32_t z = z_first; z <= z_last; ++z) {
      for (std::uint32_t y = box_lower.y; y <= box_upper.y; ++y) run(y, z, box_lower.x, box_upper.x);
    }
    return;
  }
  const TriangleLayers layers(a, b, c);
  for (std::uint32_t z = z_first; z <= z_last; ++z) {
    glm::dvec2 layer[5];  // the triangle's part in layer z
    const double bottom = frame.lower.z + double(z) * frame.cell_size.z;
    const int corners = thin_z  // in a box one layer thick: all of it
                            ? layers.section(-std::numeric_limits<double>::infinity(),
                                             std::numeric_limits<double>::infinity(), layer)
                            : layers.section(bottom - frame.slack.z, bottom + frame.cell_size.z + frame.slack.z, layer);
    if (corners == 0) continue;
    std::uint32_t y_first = box_lower.y, y_last = box_upper.y;
    if (y_first != y_last) {
      double least = layer[0].y, most = layer[0].y;
      for (int i = 1; i < corners; ++i) least = std::min(least, layer[i].y), most = std::max(most, layer[i].y);
      cells_spanned(frame, 1, least, most, box_lower.y, box_upper.y, y_first, y_last);
    }
    if (y_first == y_last) {  // the part lies in this row (or the box ends at it): all of it
      std::uint32_t x_first = box_lower.x, x_last = box_upper.x;
      if (x_first != x_last) {
        double least = layer[0].x, most = layer[0].x;
        for (int i = 1; i < corners; ++i) least = std::min(least, layer[i].x), most = std::max(most, layer[i].x);
        cells_spanned(frame, 0, least, most, box_lower.x, box_upper.x, x_first, x_last);
      }
      run(y_first, z, x_first, x_last);
      continue;
    }
    if (thin_x) {  // a column of rows one cell long: the part, connected, meets each
      for (std::uint32_t y = y_first; y <= y_last; ++y) run(y, z, box_lower.x, box_lower.x);
      continue;
    }
    const EdgesAlongY edges(layer, corners);
    for (std::uint32_t y = y_first; y <= y_last; ++y) {
      const double bottom = frame.lower.y + double(y) * frame.cell_size.y;
      double least, most;
      if (!edges.x_extent(bottom - frame.slack.y, bottom + frame.cell_size.y + frame.slack.y, least, most)) continue;
      std::uint32_t x_first = box_lower.x, x_last = box_upper.x;
      if (x_first != x_last) cells_spanned(frame, 0, least, most, box_lower.x, box_upper.x, x_first, x_last);
      run(y, z, x_first, x_last);
    }
  }
}

}  // namespace wavetrace
