// One ray's walk through a uniform grid's cells (Amanatides & Woo's 3D-DDA), shared by the
// hashed grids and the nested array grid: the current cell, and for each axis the distance at
// which the ray next crosses a cell face and the distance between crossings.
#pragma once

#include <cmath>
#include <limits>

#include <glm/vec3.hpp>

namespace wavetrace {

struct GridWalk {
  glm::ivec3 cell{0};
  glm::ivec3 step{0};           // +1, -1, or 0 where the direction has no component
  glm::vec3 next_crossing{0.0f};
  glm::vec3 interval{0.0f};

  // A grid of cells of `cell_size` from `lower`; the walk begins in `start`.
  GridWalk(const glm::vec3& lower, const glm::vec3& cell_size, const glm::vec3& origin, const glm::vec3& direction,
           const glm::ivec3& start)
      : lower_(lower), cell_size_(cell_size), origin_(origin), direction_(direction) {
    for (int axis = 0; axis < 3; ++axis) {
      step[axis] = direction[axis] > 0.0f ? 1 : direction[axis] < 0.0f ? -1 : 0;
      interval[axis] = step[axis] != 0 ? cell_size[axis] / std::fabs(direction[axis])
                                       : std::numeric_limits<float>::infinity();
    }
    enter(start);
  }

  // Moves the walk to `next` (after a jump over empty space), recomputing the crossings.
  void enter(const glm::ivec3& next) {
    cell = next;
    for (int axis = 0; axis < 3; ++axis) {
      next_crossing[axis] = step[axis] == 0 ? std::numeric_limits<float>::infinity()
                                            : face_crossing(axis, cell[axis] + (step[axis] > 0 ? 1 : 0));
    }
  }

  // Where the ray crosses the plane of face index `face` (in cells from `lower`) on `axis`.
  float face_crossing(int axis, int face) const {
    return (lower_[axis] + float(face) * cell_size_[axis] - origin_[axis]) / direction_[axis];
  }

  // The axis whose face the ray leaves the current cell by.
  int exit_axis() const {
    return next_crossing.x < next_crossing.y ? (next_crossing.x < next_crossing.z ? 0 : 2)
                                             : (next_crossing.y < next_crossing.z ? 1 : 2);
  }

  // Steps into the neighbour across `axis`; false when that leaves a grid of `cells`.
  bool advance(int axis, const glm::uvec3& cells) {
    cell[axis] += step[axis];
    if (cell[axis] < 0 || cell[axis] >= int(cells[axis])) return false;
    next_crossing[axis] += interval[axis];
    return true;
  }

 private:
  glm::vec3 lower_, cell_size_, origin_, direction_;
};

}  // namespace wavetrace
