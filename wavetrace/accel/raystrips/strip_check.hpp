// Checks Ray-Strips (ray_strip_format.hpp) as loaded from a world file, before any ray
// decodes them (accel/bvh/tree_check.hpp says why).
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace wavetrace::ray_strip {

// The strip at byte `at` of `bytes`: what is wrong with it, if anything, else its size in
// `size`. Right means: its header and every part lie inside `bytes`, it has at least one
// triangle, each kd-tree node's axis is x, y or z, each vertex index names one of `vertices`
// and each record one of `triangles`. (Corner codes are not checked: the repeats at a
// strip's turns hold codes of equal corners, and set_surface_from_strip keeps any code in
// range.)
std::optional<std::string> strip_problem(std::span<const std::byte> bytes, std::uint64_t at, std::size_t vertices,
                                         std::size_t triangles, std::size_t& size);

}  // namespace wavetrace::ray_strip
