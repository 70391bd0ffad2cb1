// Encoding one strip into the byte layout of ray_strip_format.hpp: the widths its indices
// and records need, and its implicit kd-tree (median splits, least-overlap axis).
#pragma once

#include <cstddef>
#include <cstdint>
#include <span>

#include "wavetrace/accel/raystrips/ray_strip_format.hpp"
#include "wavetrace/accel/raystrips/stripify.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// What a strip needs besides its triangles: widths and bases (the header's bytes 2-11).
struct StripEncoding {
  std::uint8_t widths = 0;
  std::uint32_t vertex_base = 0;
  std::uint32_t triangle_base = 0;
  std::size_t size(std::uint32_t triangles) const { return ray_strip::strip_layout(triangles, widths).size; }
};

// `vertex_id` maps mesh vertex ids to the accelerator's vertex numbering. Throws
// std::length_error when a strip's triangle ids span 2^29 or more.
StripEncoding choose_encoding(const TriangleStrip& strip, std::span<const std::uint32_t> vertex_id);

// Writes the strip at `out` (encoding.size(n) bytes, 4-byte aligned); `positions` are in
// the accelerator's vertex numbering, `mesh` gives each triangle's corner order, `frame` is
// the box of the top leaf holding the strip, which its split planes are quantized against.
void encode_strip(const TriangleStrip& strip, const StripEncoding& encoding, std::span<const std::uint32_t> vertex_id,
                  std::span<const glm::vec3> positions, const TriangleMesh& mesh, const Bounds3& frame, std::byte* out);

}  // namespace wavetrace
