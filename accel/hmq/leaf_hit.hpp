// What both HMQ layouts do at a leaf: decode its record against its grid box, test its
// triangles, keep the nearest hit in leaf terms, and write it out in the mesh's terms.
#pragma once

#include <cstdint>
#include <limits>

#include "accel/bvh/leaf_query.hpp"
#include "accel/hit_surface.hpp"
#include "accel/hmq/global_grid.hpp"
#include "accel/hmq/hmq_format.hpp"
#include "accel/hmq/leaf_codec.hpp"
#include "kernels/triangle_intersect.hpp"
#include "memory/ray_batch.hpp"

namespace wavetrace::hmq {

// The nearest hit of one ray, kept in leaf terms until written.
struct LeafHit {
  float t = std::numeric_limits<float>::infinity();
  float u = 0.0f, v = 0.0f;  // weights of the strip triangle's second and third corner
  LeafHeader header{};
  const std::byte* ids = nullptr;
  const std::byte* corners = nullptr;
  std::uint32_t triangle = 0;
  glm::vec3 corner[3];  // the strip triangle's decoded corners, for the hit's point and normal
  bool found = false;
};

// Tests the triangles of the leaf record at `record`, whose decoded box is `box`; a hit
// nearer than `tmax` shrinks it and replaces `best` (with kAnyHit, the first one ends the test).
template <bool kAnyHit, typename Probe>
[[gnu::always_inline]] inline void test_leaf_record(const std::byte* record, const GlobalGrid& grid, const Box& box,
                                                    const WatertightRay& sheared, float tmin, float& tmax,
                                                    LeafHit& best, Probe& probe) {
  if constexpr (Probe::kRecords) probe.read(record, leaf_record_bytes(record));
  DecodedLeaf decoded;
  decode_leaf(record, grid, snap_outward(grid, box), decoded);
  const StripLayoutEntry& layout = *decoded.layout;
  for (std::uint32_t k = 0; k < layout.triangles; ++k) {
    const glm::vec3* corner = decoded.slot_position + layout.first_slot[k];
    TriangleHit hit;
    if (intersect_watertight(sheared, corner[0], corner[1], corner[2], tmin, tmax, hit)) {
      tmax = hit.t;
      best = {hit.t, hit.u, hit.v, decoded.header, decoded.ids, decoded.corners, k, {}, true};
      if constexpr (kAnyHit) return;
      best.corner[0] = corner[0];
      best.corner[1] = corner[1];
      best.corner[2] = corner[2];
    }
  }
}

// With kSurface (closest hits, whose corners test_leaf_record kept) also the point and normal.
template <bool kSurface>
inline void write_leaf_hit(const LeafHit& best, HitBatch& hits, std::uint32_t i) {
  if (!best.found) return write_miss(hits, i);
  std::uint32_t delta[kMaxLeafTriangles], code[kMaxLeafTriangles];
  read_stream(best.ids, best.header.id_bits, best.triangle + 1, delta);
  read_stream(best.corners, 3, best.triangle + 1, code);
  const float weight[3] = {1.0f - best.u - best.v, best.u, best.v};
  hits.set_hit(i, best.t, best.header.id_base + delta[best.triangle], weight[code[best.triangle] / 3],
               weight[code[best.triangle] % 3]);
  if constexpr (kSurface) set_surface_from_strip(hits, i, best.corner, code[best.triangle]);
}

}  // namespace wavetrace::hmq
