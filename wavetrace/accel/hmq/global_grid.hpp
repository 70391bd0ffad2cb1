// The global quantization grid of HMQ (Segovia and Ernst 2010, §4): every vertex and every
// leaf box is snapped to it, so two leaves decode a shared vertex to the same float and
// no crack opens between them (Figure 2).
#pragma once

#include <cmath>
#include <cstdint>

#include <glm/vec3.hpp>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// Grid point g (integer, 0 .. 2^bits - 1 per axis) sits at origin + g * cell.
struct GlobalGrid {
  glm::vec3 origin{0.0f};
  glm::vec3 cell{1.0f};
  glm::vec3 inverse_cell{1.0f};  // 1 / cell, for re-snapping leaf boxes without dividing
  glm::uvec3 bits{16};
  // What snapping promises: no vertex moves more than this (half a cell diagonal, plus the
  // float rounding of decoding).
  double max_vertex_error = 0.0;

  glm::ivec3 snap(const glm::vec3& p) const {
    glm::ivec3 g;
    for (int axis = 0; axis < 3; ++axis) {
      const float scaled = std::round((p[axis] - origin[axis]) / cell[axis]);
      const float top = float((1u << bits[axis]) - 1);
      g[axis] = static_cast<int>(std::fmin(std::fmax(scaled, 0.0f), top));
    }
    return g;
  }
  glm::vec3 point(const glm::ivec3& g) const {
    return {origin.x + float(g.x) * cell.x, origin.y + float(g.y) * cell.y, origin.z + float(g.z) * cell.z};
  }
  // The grid lines at or below / at or above a coordinate (for re-snapping leaf boxes).
  // The encoder and the decoder both re-snap through these, so their rounding is shared.
  int floor_line(float value, int axis) const { return to_line(std::floor((value - origin[axis]) * inverse_cell[axis])); }
  int ceil_line(float value, int axis) const { return to_line(std::ceil((value - origin[axis]) * inverse_cell[axis])); }

 private:
  // Lines of boxes the encoder writes lie inside the grid (< 2^24) and pass unchanged; a box
  // from a crafted world file may lie far outside it, or be NaN, and is clamped so that the
  // conversion to int is defined.
  // Comparisons, not std::fmin/fmax, which GCC leaves as two libm calls (six pairs a leaf
  // decoded); the same answer, NaN included (to -2^30, as fmax(NaN, -2^30) gives).
  static int to_line(float line) {
    constexpr float kLimit = 1073741824.0f;  // 2^30
    return static_cast<int>(line >= -kLimit ? (line <= kLimit ? line : kLimit) : -kLimit);
  }
};

// From a bit count per axis (1 .. 24): the scene box spans 2^bits - 1 cells on each axis.
GlobalGrid grid_from_bits(const Bounds3& bounds, std::uint32_t bits);
// From an error bound in scene units: the coarsest grid on which no vertex moves more than
// `epsilon`; throws std::invalid_argument when that needs more than 24 bits on an axis.
GlobalGrid grid_from_epsilon(const Bounds3& bounds, double epsilon);

}  // namespace wavetrace
