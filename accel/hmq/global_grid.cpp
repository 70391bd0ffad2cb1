// Choosing the global grid from bits or from an error bound.
#include "accel/hmq/global_grid.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {
namespace {

inline constexpr std::uint32_t kMaxBits = 24;  // grid coordinates stay exact in a float

double error_of(const glm::vec3& cell) {
  return 0.5 * std::sqrt(double(cell.x) * cell.x + double(cell.y) * cell.y + double(cell.z) * cell.z);
}

}  // namespace

GlobalGrid grid_from_bits(const Bounds3& bounds, std::uint32_t bits) {
  if (bits < 1 || bits > kMaxBits) throw std::invalid_argument(fmt::format("hmq: bits = {}: must be 1 .. 24", bits));
  GlobalGrid grid;
  grid.origin = bounds.lower;
  grid.bits = glm::uvec3(bits);
  for (int axis = 0; axis < 3; ++axis) {
    const float extent = bounds.upper[axis] - bounds.lower[axis];
    // A flat axis still needs a positive cell; any will do, every vertex sits at line 0.
    grid.cell[axis] = extent > 0.0f ? extent / float((1u << bits) - 1) : 1.0f;
  }
  grid.inverse_cell = 1.0f / grid.cell;
  grid.max_vertex_error = error_of(grid.cell);
  return grid;
}

GlobalGrid grid_from_epsilon(const Bounds3& bounds, double epsilon) {
  if (!(epsilon > 0.0) || !std::isfinite(epsilon)) {
    throw std::invalid_argument(fmt::format("hmq: epsilon = {}: must be a positive distance", epsilon));
  }
  // Half a cube cell's diagonal is at most epsilon: cell = 2 epsilon / sqrt(3).
  const double cell = 2.0 * epsilon / std::sqrt(3.0);
  GlobalGrid grid;
  grid.origin = bounds.lower;
  for (int axis = 0; axis < 3; ++axis) {
    const double extent = double(bounds.upper[axis]) - double(bounds.lower[axis]);
    std::uint32_t bits = 1;
    while (bits <= kMaxBits && extent / cell > double((1u << bits) - 1)) ++bits;
    if (bits > kMaxBits) {
      throw std::invalid_argument(fmt::format(
          "hmq: epsilon = {} needs more than {} bits on axis {} (extent {}); choose a larger epsilon", epsilon,
          kMaxBits, "xyz"[axis], extent));
    }
    grid.bits[axis] = bits;
    grid.cell[axis] = static_cast<float>(cell);
  }
  grid.inverse_cell = 1.0f / grid.cell;
  grid.max_vertex_error = error_of(grid.cell);
  return grid;
}

}  // namespace wavetrace
