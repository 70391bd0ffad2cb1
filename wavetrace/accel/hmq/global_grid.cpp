// Choosing the global grid from bits or from an error bound.
#include "wavetrace/accel/hmq/global_grid.hpp"

#include <algorithm>
#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {
namespace {

inline constexpr std::uint32_t kMaxBits = 24;  // grid coordinates stay exact in a float

// A decoded coordinate origin + g * cell is rounded twice in float: at most one ulp of the
// largest coordinate of the scene, per axis.
double rounding_of(const Bounds3& bounds, int axis) {
  const double largest = std::max(std::fabs(double(bounds.lower[axis])), std::fabs(double(bounds.upper[axis])));
  return largest * std::ldexp(1.0, -23);
}

// Half a cell per axis, plus the rounding, over the three axes.
double error_of(const glm::vec3& cell, const Bounds3& bounds) {
  double sum = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double error = 0.5 * double(cell[axis]) + rounding_of(bounds, axis);
    sum += error * error;
  }
  return std::sqrt(sum);
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
  grid.max_vertex_error = error_of(grid.cell, bounds);
  return grid;
}

GlobalGrid grid_from_epsilon(const Bounds3& bounds, double epsilon) {
  if (!(epsilon > 0.0) || !std::isfinite(epsilon)) {
    throw std::invalid_argument(fmt::format("hmq: epsilon = {}: must be a positive distance", epsilon));
  }
  // Half a cube cell's diagonal plus the float rounding of decoding is at most epsilon.
  double rounding = 0.0;
  for (int axis = 0; axis < 3; ++axis) rounding = std::max(rounding, rounding_of(bounds, axis));
  const double cell = 2.0 * (epsilon / std::sqrt(3.0) - rounding) * 0.999;
  if (!(cell > 0.0)) {
    throw std::invalid_argument(fmt::format(
        "hmq: epsilon = {} is below the float precision of the scene's coordinates ({:.3g})", epsilon, rounding));
  }
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
  grid.max_vertex_error = error_of(grid.cell, bounds);
  return grid;
}

}  // namespace wavetrace
