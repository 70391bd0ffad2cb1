// Encodes a strip: header, kd-tree nodes in pre-order, indices, records.
#include "wavetrace/accel/raystrips/strip_encode.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {
namespace {

using namespace ray_strip;

Bounds3 bounds_of_triangles(const TriangleStrip& strip, std::span<const std::uint32_t> vertex_id,
                            std::span<const glm::vec3> positions, std::uint32_t first, std::uint32_t end) {
  Bounds3 bounds;
  for (std::uint32_t i = first; i < end + 2; ++i) bounds.extend(positions[vertex_id[strip.vertices[i]]]);
  return bounds;
}

// The split steps of one node, rounded outward: the decoded lower child's max at or above its
// true max, the upper child's min at or below its true min (decode_split's arithmetic).
void quantize_split(const Bounds3& frame, int axis, float lower_child_max, float upper_child_min, std::uint8_t* steps) {
  const float step = split_step(frame, axis);
  float q_max = 0.0f, q_min = 0.0f;
  if (step > 0.0f) {
    q_max = std::clamp(std::floor((frame.upper[axis] - lower_child_max) / step), 0.0f, 255.0f);
    while (q_max > 0.0f && std::fma(-q_max, step, frame.upper[axis]) < lower_child_max) q_max -= 1.0f;
    q_min = std::clamp(std::floor((upper_child_min - frame.lower[axis]) / step), 0.0f, 255.0f);
    while (q_min > 0.0f && std::fma(q_min, step, frame.lower[axis]) > upper_child_min) q_min -= 1.0f;
  }
  steps[0] = static_cast<std::uint8_t>(q_max);
  steps[1] = static_cast<std::uint8_t>(q_min);
}

struct TreeWriter {
  const TriangleStrip& strip;
  std::span<const std::uint32_t> vertex_id;
  std::span<const glm::vec3> positions;
  const Bounds3& frame;
  std::uint8_t* splits;
  std::byte* node_bits;
  std::uint32_t triangles;

  // Node `node` spans leaves [first, first + leaves), leaves >= 2.
  void write(std::uint32_t node, std::uint32_t first, std::uint32_t leaves) {
    const std::uint32_t first_leaves = (leaves + 1) / 2;
    const std::uint32_t middle = first + first_leaves;
    const std::uint32_t end = std::min(2 * (first + leaves), triangles);
    const Bounds3 a = bounds_of_triangles(strip, vertex_id, positions, 2 * first, 2 * middle);
    const Bounds3 b = bounds_of_triangles(strip, vertex_id, positions, 2 * middle, end);
    int axis = 0;
    float least = std::numeric_limits<float>::infinity();
    for (int k = 0; k < 3; ++k) {
      const float overlap = std::min(a.upper[k], b.upper[k]) - std::max(a.lower[k], b.lower[k]);
      if (overlap < least) {
        least = overlap;
        axis = k;
      }
    }
    const bool reverse = a.lower[axis] + a.upper[axis] > b.lower[axis] + b.upper[axis];
    const Bounds3& lower = reverse ? b : a;
    const Bounds3& upper = reverse ? a : b;
    quantize_split(frame, axis, lower.upper[axis], upper.lower[axis], splits + 2 * node);
    node_bits[node] = static_cast<std::byte>(axis | (reverse ? kReverse : 0));
    if (first_leaves >= 2) write(node + 1, first, first_leaves);
    if (leaves - first_leaves >= 2) write(node + first_leaves, middle, leaves - first_leaves);
  }
};

// corners = 3 c1 + c2: the strip corners of the mesh triangle's second and third vertex.
std::uint32_t corner_code(const TriangleStrip& strip, std::uint32_t k, const glm::uvec3& mesh_corners) {
  auto strip_corner = [&](std::uint32_t vertex) {
    for (std::uint32_t c = 0; c < 3; ++c) {
      if (strip.vertices[k + c] == vertex) return c;
    }
    throw std::logic_error("a strip triangle does not have its mesh triangle's corners");
  };
  return 3 * strip_corner(mesh_corners.y) + strip_corner(mesh_corners.z);
}

}  // namespace

StripEncoding choose_encoding(const TriangleStrip& strip, std::span<const std::uint32_t> vertex_id) {
  StripEncoding encoding;
  std::uint32_t low = std::numeric_limits<std::uint32_t>::max(), high = 0;
  for (const std::uint32_t vertex : strip.vertices) {
    low = std::min(low, vertex_id[vertex]);
    high = std::max(high, vertex_id[vertex]);
  }
  if (high - low <= 0xffu) {
    encoding.widths |= kByteIndices;
    encoding.vertex_base = low;
  } else if (high - low <= 0xffffu) {
    encoding.widths |= kShortIndices;
    encoding.vertex_base = low;
  }
  low = std::numeric_limits<std::uint32_t>::max();
  high = 0;
  for (const std::uint32_t triangle : strip.triangles) {
    if (triangle == kNoTriangle) continue;
    low = std::min(low, triangle);
    high = std::max(high, triangle);
  }
  if (low > high) low = high = 0;  // only swaps: unreachable after stripify, harmless anyway
  encoding.triangle_base = low;
  if (high - low < kShortDeltaLimit) {
    encoding.widths |= kShortRecords;
  } else if (high - low >= kLongDeltaLimit) {
    throw std::length_error(fmt::format("raystrips: a strip spans triangle ids {} to {}; records hold spans below 2^29",
                                        low, high));
  }
  return encoding;
}

void encode_strip(const TriangleStrip& strip, const StripEncoding& encoding, std::span<const std::uint32_t> vertex_id,
                  std::span<const glm::vec3> positions, const TriangleMesh& mesh, const Bounds3& frame, std::byte* out) {
  const auto triangles = static_cast<std::uint32_t>(strip.triangles.size());
  const StripLayout layout = strip_layout(triangles, encoding.widths);
  std::memset(out, 0, layout.size);
  const auto count16 = static_cast<std::uint16_t>(triangles);
  std::memcpy(out, &count16, 2);
  out[2] = static_cast<std::byte>(encoding.widths);
  std::memcpy(out + 4, &encoding.vertex_base, 4);
  std::memcpy(out + 8, &encoding.triangle_base, 4);

  if (has_tree(triangles)) {
    TreeWriter writer{strip, vertex_id, positions, frame, reinterpret_cast<std::uint8_t*>(out + layout.splits),
                      out + layout.node_bits, triangles};
    writer.write(0, 0, leaf_count(triangles));
  }
  for (std::uint32_t i = 0; i < triangles + 2; ++i) {
    const std::uint32_t stored = vertex_id[strip.vertices[i]] - encoding.vertex_base;
    if (encoding.widths & kByteIndices) {
      reinterpret_cast<std::uint8_t*>(out + layout.indices)[i] = static_cast<std::uint8_t>(stored);
    } else if (encoding.widths & kShortIndices) {
      reinterpret_cast<std::uint16_t*>(out + layout.indices)[i] = static_cast<std::uint16_t>(stored);
    } else {
      reinterpret_cast<std::uint32_t*>(out + layout.indices)[i] = stored;
    }
  }
  for (std::uint32_t k = 0; k < triangles; ++k) {
    const std::uint32_t triangle = strip.triangles[k];
    // A swap (zero area, never hit) keeps record 0.
    const std::uint32_t record = triangle == kNoTriangle ? 0
                                 : (triangle - encoding.triangle_base) << kCornerBits |
                                       corner_code(strip, k, mesh.triangles[triangle]);
    if (encoding.widths & kShortRecords) {
      reinterpret_cast<std::uint16_t*>(out + layout.records)[k] = static_cast<std::uint16_t>(record);
    } else {
      reinterpret_cast<std::uint32_t*>(out + layout.records)[k] = record;
    }
  }
}

}  // namespace wavetrace
