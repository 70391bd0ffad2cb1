// strip_problem: the strip's layout from its header, then each part read as traversal reads it.
#include "wavetrace/accel/raystrips/strip_check.hpp"

#include <fmt/format.h>

#include "wavetrace/accel/raystrips/ray_strip_format.hpp"

namespace wavetrace::ray_strip {

std::optional<std::string> strip_problem(std::span<const std::byte> bytes, std::uint64_t at, std::size_t vertices,
                                         std::size_t triangles, std::size_t& size) {
  if (at % 4 != 0 || at + kHeaderBytes > bytes.size()) return fmt::format("a strip at byte {} lies past the strips", at);
  const StripView strip(bytes.data() + at);
  if (strip.triangles() == 0) return fmt::format("the strip at byte {} has no triangles", at);
  if ((strip.widths() & ~kKnownWidths) != 0 || (strip.widths() & kShortIndices && strip.widths() & kByteIndices)) {
    return fmt::format("the strip at byte {} has index or record widths this version does not know", at);
  }
  if (at + strip.size() > bytes.size()) return fmt::format("the strip at byte {} runs past the strips", at);
  for (std::uint32_t node = 0; node < node_count(strip.triangles()); ++node) {
    if ((strip.node_bits(node) & kAxisMask) > 2) return fmt::format("the strip at byte {} splits on no axis", at);
  }
  for (std::uint32_t i = 0; i < strip.triangles() + 2; ++i) {
    if (strip.vertex(i) >= vertices) return fmt::format("the strip at byte {} names a vertex that does not exist", at);
  }
  for (std::uint32_t k = 0; k < strip.triangles(); ++k) {
    if (std::uint64_t(strip.triangle(k)) >= triangles) {
      return fmt::format("the strip at byte {} names a triangle that does not exist", at);
    }
  }
  size = strip.size();
  return std::nullopt;
}

}  // namespace wavetrace::ray_strip
