// What the binary and the 8-wide BVH share per ray: the nearest hit so far, the leaf test
// over an indexed face set, and writing the answer into the hit batch.
#pragma once

#include <algorithm>
#include <bit>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/triangle_block.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/kernels/watertight_lanes.hpp"
#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

class LeafQuery {
 public:
  // `leaf_index` maps leaf slots to face-set slots; empty when the face set is in leaf order.
  LeafQuery(const IndexedFaceSet& geometry, std::span<const std::uint32_t> leaf_index, const SingleRay& ray)
      : tmin(ray.tmin),
        tmax(ray.tmax),
        geometry_(geometry),
        leaf_index_(leaf_index.empty() ? nullptr : leaf_index.data()),
        ray_(ray.sheared) {}

  float tmin;
  float tmax;  // shrinks to the nearest hit found

  bool found() const { return found_ != kInvalidPrimitive; }

  // Tests leaf slots [first, first + count); with kAnyHit stops at the first hit. Reports
  // each index, triangle and vertex read to `probe`.
  template <bool kAnyHit, typename Probe>
  void test_leaf(std::uint32_t first, std::uint32_t count, Probe& probe) {
    const glm::vec3* positions = geometry_.positions();
    const glm::uvec3* triangles = geometry_.triangles();
    for (std::uint32_t slot = first; slot < first + count; ++slot) {
      if (leaf_index_) probe.read(leaf_index_ + slot, sizeof(std::uint32_t));
      const std::uint32_t triangle = leaf_index_ ? leaf_index_[slot] : slot;
      const glm::uvec3& tri = triangles[triangle];
      if constexpr (Probe::kRecords) {
        probe.read(&tri, sizeof tri);
        for (int corner = 0; corner < 3; ++corner) probe.read(positions + tri[corner], sizeof(glm::vec3));
      }
      TriangleHit hit;
      if (intersect_watertight(ray_, positions[tri.x], positions[tri.y], positions[tri.z], tmin, tmax, hit) &&
          accept(triangle, hit)) {
        if constexpr (kAnyHit) return;
      }
    }
  }

  // Tests a leaf of `count` triangles stored as consecutive blocks from `block`, two blocks a
  // pass of eight lanes and a last odd block in four; the same hits as test_leaf over the same
  // triangles, bit for bit (the lanes compute what the scalar test does, and a candidate is
  // then taken against the tmax of the moment, in triangle order, as the scalar loop takes it).
  template <bool kAnyHit, typename Probe>
  [[gnu::always_inline]] void test_blocks(const TriangleBlock* block, std::uint32_t count, Probe& probe) {
#if WAVETRACE_AVX2
    constexpr std::ptrdiff_t kBlockFloats = sizeof(TriangleBlock) / sizeof(float);
    static_assert(sizeof(TriangleBlock) % sizeof(float) == 0);
    for (std::uint32_t base = 0; base < count;) {
      const std::uint32_t left = count - base;
      if (left > TriangleBlock::kLanes) {
        probe.read(block, sizeof *block);
        probe.read(block + 1, sizeof *block);
        WatertightLanes<2 * TriangleBlock::kLanes> result;
        intersect_watertight_lanes(ray_, block->corners, (1u << std::min(2 * TriangleBlock::kLanes, left)) - 1, tmin, tmax,
                                   result, 0, kBlockFloats);
        if (take_candidates<kAnyHit>(result, block)) return;
        base += 2 * TriangleBlock::kLanes, block += 2;
      } else {
        probe.read(block, sizeof *block);
        WatertightLanes<TriangleBlock::kLanes> result;
        intersect_watertight_lanes(ray_, block->corners, (1u << left) - 1, tmin, tmax, result);
        if (take_candidates<kAnyHit>(result, block)) return;
        base += TriangleBlock::kLanes, ++block;
      }
    }
#else
    for (std::uint32_t base = 0; base < count; base += TriangleBlock::kLanes, ++block) {
      probe.read(block, sizeof *block);
      const std::uint32_t used = (1u << std::min(TriangleBlock::kLanes, count - base)) - 1;
      for (unsigned lane = 0; used >> lane & 1u; ++lane) {
        TriangleHit hit;
        if (intersect_watertight(ray_, block->corner(lane, 0), block->corner(lane, 1), block->corner(lane, 2), tmin, tmax,
                                 hit) &&
            accept(block->slot[lane], hit, block, lane)) {
          if constexpr (kAnyHit) return;
        }
      }
    }
#endif
  }

  // The answer in the mesh's triangle numbering (a miss if nothing was found); with
  // kSurface (closest-hit queries) also the hit's point and normal.
  template <bool kSurface, typename Probe>
  void write(HitBatch& hits, std::uint32_t i, Probe& probe) const {
    if (!found()) return hits.set_miss(i);
    if constexpr (Probe::kRecords) {
      if (const std::uint32_t* id = geometry_.input_id_address(found_)) probe.read(id, sizeof *id);
    }
    hits.set_hit(i, best_.t, geometry_.input_id(found_), best_.u, best_.v);
    if constexpr (!kSurface) return;
    if (found_block_) {  // the corners are in the block just tested, no face-set read
      const std::uint32_t k = found_lane_;
      return hits.set_surface(i, found_block_->corner(k, 0), found_block_->corner(k, 1), found_block_->corner(k, 2));
    }
    const glm::uvec3& tri = geometry_.triangles()[found_];
    const glm::vec3* positions = geometry_.positions();
    hits.set_surface(i, positions[tri.x], positions[tri.y], positions[tri.z]);
  }

 private:
  // True when `hit` on face-set slot `triangle` (in lane `lane` of `block` when a block was
  // tested) becomes the nearest (nearest_hit.hpp).
  bool accept(std::uint32_t triangle, const TriangleHit& hit, const TriangleBlock* block = nullptr,
              std::uint32_t lane = 0) {
    if (!replaces_nearest(
            hit.t, tmax, found(), [&] { return geometry_.input_id(triangle); },
            [&] { return geometry_.input_id(found_); })) {
      return false;
    }
    tmax = hit.t;
    best_ = hit;
    found_ = triangle;
    found_block_ = block, found_lane_ = lane;
    return true;
  }

#if WAVETRACE_AVX2
  // Takes a pass's candidates over the blocks from `first` (lane k in block k / 4) in lane
  // order against the tmax of the moment, lanes on an edge redone by the scalar test; true
  // when kAnyHit and one was taken.
  template <bool kAnyHit, int kLanes>
  [[gnu::always_inline]] bool take_candidates(const WatertightLanes<kLanes>& result, const TriangleBlock* first) {
    for (unsigned pending = result.candidates | result.on_edge; pending != 0; pending &= pending - 1) {
      const int lane = std::countr_zero(pending);
      const TriangleBlock* block = first + lane / TriangleBlock::kLanes;
      const auto block_lane = static_cast<std::uint32_t>(lane) % TriangleBlock::kLanes;
      TriangleHit hit;
      if (result.on_edge >> lane & 1u) {
        if (!intersect_watertight(ray_, block->corner(block_lane, 0), block->corner(block_lane, 1),
                                  block->corner(block_lane, 2), tmin, tmax, hit)) {
          continue;
        }
      } else {
        if (result.t[lane] > tmax) continue;
        hit = {result.t[lane], result.u[lane], result.v[lane]};
      }
      if (accept(block->slot[block_lane], hit, block, block_lane) && kAnyHit) return true;
    }
    return false;
  }
#endif

  const IndexedFaceSet& geometry_;
  const std::uint32_t* leaf_index_;
  WatertightRay ray_;
  std::uint32_t found_ = kInvalidPrimitive;
  const TriangleBlock* found_block_ = nullptr;  // where test_blocks found it
  std::uint32_t found_lane_ = 0;
  TriangleHit best_{std::numeric_limits<float>::infinity(), 0.0f, 0.0f};
};

// The byte ranges a BVH's traversal reads, for the pager.
template <typename NodeArray, typename IndexArray>
std::vector<std::span<const std::byte>> bvh_memory_spans(const NodeArray& nodes, const IndexArray& leaf_index,
                                                         const IndexedFaceSet& geometry) {
  std::vector<std::span<const std::byte>> spans = {std::as_bytes(std::span(nodes)), std::as_bytes(std::span(leaf_index))};
  for (const auto& span : geometry.spans()) spans.push_back(span);
  return spans;
}

}  // namespace wavetrace
