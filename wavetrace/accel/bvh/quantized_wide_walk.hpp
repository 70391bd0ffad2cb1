// One ray through a tree of quantized wide nodes (quantized_wide_node.hpp): the eight child
// boxes decoded and slab-tested in AVX2 lanes, the entered ones sorted by distance and
// pushed, with their decoded boxes as the frames below, in one pass. HMQ's and Ray-Strips'
// wide layouts share it; their leaves plug in as a callback.
#pragma once

#include "wavetrace/build_config.hpp"

#if WAVETRACE_AVX2 && WAVETRACE_FMA

#include <bit>
#include <cstdint>
#include <limits>
#include <type_traits>

#include <immintrin.h>

#include "wavetrace/accel/bvh/quantized_wide_node.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/kernels/lane_sort.hpp"
#include "wavetrace/kernels/lane_transpose.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {

// A stack or child reference: a node index, or with this bit a leaf reference.
inline constexpr std::uint32_t kWideLeafReference = 0x8000'0000u;

// The traversal stack, one column per field (SoA) so that eight children are pushed with one
// store per field. Depth first: a level pushes at most eight and pops one. About 25 KiB: one
// per batch call, not per ray.
struct QuantizedWideStack {
  static constexpr std::size_t kEntries = kMaxTreeDepth * QuantizedWideNode::kWidth + QuantizedWideNode::kWidth;
  alignas(32) std::uint32_t reference[kEntries];
  alignas(32) float distance[kEntries];
  alignas(32) float bound[6][kEntries];  // lower x, y, z, upper x, y, z: the child's frame
};

namespace quantized_wide {

// Each child's reference: inner children number from child_base in slot order, leaves from
// leaf_base by the weights of the leaf slots before them (exclusive prefix sums over the meta
// bytes in 16-bit lanes: leaf weights in bits 0-10, the inner count in bits 11-14).
[[gnu::always_inline]] inline __m256i child_references(const QuantizedWideNode& node) {
  const __m128i meta = _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.meta)));
  const __m128i inner = _mm_cmpeq_epi16(meta, _mm_set1_epi16(QuantizedWideNode::kInnerMeta));
  const __m128i counts = _mm_or_si128(_mm_andnot_si128(inner, meta), _mm_and_si128(inner, _mm_set1_epi16(1 << 11)));
  __m128i sums = _mm_add_epi16(counts, _mm_slli_si128(counts, 2));
  sums = _mm_add_epi16(sums, _mm_slli_si128(sums, 4));
  sums = _mm_add_epi16(sums, _mm_slli_si128(sums, 8));
  const __m256i before = _mm256_cvtepu16_epi32(_mm_sub_epi16(sums, counts));
  const __m256i leaf = _mm256_or_si256(_mm256_add_epi32(_mm256_set1_epi32(int(node.leaf_base)),
                                                        _mm256_and_si256(before, _mm256_set1_epi32(2047))),
                                       _mm256_set1_epi32(int(kWideLeafReference)));
  const __m256i child = _mm256_add_epi32(_mm256_set1_epi32(int(node.child_base)), _mm256_srli_epi32(before, 11));
  return _mm256_blendv_epi8(leaf, child, _mm256_cvtepi16_epi32(inner));
}

// The eight child boxes of `node`, decoded against its frame: bound[0..2] lower x, y, z,
// bound[3..5] upper x, y, z, lane k = slot k (the arithmetic of decode_wide_child).
[[gnu::always_inline]] inline void decode_children(const QuantizedWideNode& node, const Bounds3& frame, __m256 bound[6]) {
  for (int axis = 0; axis < 3; ++axis) {
    const __m256 step = _mm256_set1_ps(frame_step(frame, axis));
    const __m256 q_lower =
        _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.lower(axis)))));
    const __m256 q_upper =
        _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.upper(axis)))));
    bound[axis] = _mm256_fmadd_ps(q_lower, step, _mm256_set1_ps(frame.lower[axis]));
    bound[3 + axis] = _mm256_fnmadd_ps(q_upper, step, _mm256_set1_ps(frame.upper[axis]));
  }
}

// The robust slab test of one ray against the eight boxes: writes the entry distances to
// `near` and returns the mask of the lanes entered within [tmin, pruning_distance(tmax)].
[[gnu::always_inline]] inline unsigned enter_children(const __m256 bound[6], const __m256 origin[3],
                                                      const __m256 inverse[3], float tmin, float tmax, __m256& near) {
  near = _mm256_set1_ps(tmin);
  __m256 far = _mm256_set1_ps(std::numeric_limits<float>::infinity());
  for (int axis = 0; axis < 3; ++axis) {
    const __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(bound[axis], origin[axis]), inverse[axis]);
    const __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(bound[3 + axis], origin[axis]), inverse[axis]);
    // A NaN slab distance (origin on a plane the ray runs parallel to) leaves the interval as
    // it was, as clip_slab does: max/min return their second operand when one is NaN.
    near = _mm256_max_ps(_mm256_min_ps(t1, t0), near);
    far = _mm256_min_ps(_mm256_max_ps(t0, t1), far);
  }
  far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(kSlabFarScale)), _mm256_set1_ps(pruning_distance(tmax)));
  return static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ)));
}

// Bit k set: slot k holds a child.
[[gnu::always_inline]] inline unsigned occupied_slots(const QuantizedWideNode& node) {
  const __m128i meta = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.meta));
  return ~static_cast<unsigned>(_mm_movemask_epi8(_mm_cmpeq_epi8(meta, _mm_setzero_si128()))) & 0xffu;
}

}  // namespace quantized_wide

// A leaf_address for walks whose leaves are not worth prefetching.
struct NoLeafPrefetch {
  const void* operator()(std::uint32_t) const { return nullptr; }
};

// `visit_leaf(reference, box)` handles a leaf (its reference without the leaf bit, its
// decoded box) and returns true to end the walk (an any-hit query found one); it may shrink
// `tmax`, which prunes what is left on the stack. `leaf_address(reference)`, where it gives
// one, is where the leaf's data starts: with the nodes of the inner children, its first two
// lines are asked for as soon as a node's children are entered, before the walk goes down the
// nearest, so that the others are in cache when it comes back for them (plain walks only).
template <KernelIsa kIsa, typename Probe, typename VisitLeaf, typename LeafAddress = NoLeafPrefetch>
[[gnu::always_inline]] inline void walk_quantized_wide(const QuantizedWideNode* nodes, const Bounds3& root_frame,
                                                       const SingleRay& ray, const float& tmax, Probe& probe,
                                                       QuantizedWideStack& stack, VisitLeaf&& visit_leaf,
                                                       LeafAddress&& leaf_address = {}) {
  using namespace quantized_wide;
  const glm::vec3 &origin = ray.origin, &inverse = ray.box.inverse_direction;
  const __m256 origin_lanes[3] = {_mm256_set1_ps(origin.x), _mm256_set1_ps(origin.y), _mm256_set1_ps(origin.z)};
  const __m256 inverse_lanes[3] = {_mm256_set1_ps(inverse.x), _mm256_set1_ps(inverse.y), _mm256_set1_ps(inverse.z)};
  std::uint32_t current = 0, top = 0;
  Bounds3 frame = root_frame;
  while (true) {
    if (!(current & kWideLeafReference)) {
      const QuantizedWideNode& node = *probe.resident(nodes + current, sizeof(QuantizedWideNode));
      __m256 bound[6], near;
      decode_children(node, frame, bound);
      const unsigned entered_mask =
          enter_children(bound, origin_lanes, inverse_lanes, ray.tmin, tmax, near) & occupied_slots(node);
      if (std::has_single_bit(entered_mask)) {  // one child: go down, nothing to order or stack
        const int lane = std::countr_zero(entered_mask);
        alignas(32) std::uint32_t reference[8];
        alignas(32) float lanes[6][8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(reference), child_references(node));
        for (int b = 0; b < 6; ++b) _mm256_store_ps(lanes[b], bound[b]);
        current = reference[lane];
        frame.lower = {lanes[0][lane], lanes[1][lane], lanes[2][lane]};
        frame.upper = {lanes[3][lane], lanes[4][lane], lanes[5][lane]};
        continue;
      }
      if (entered_mask != 0) {  // nearest first, by sorting
        const __m256i references = child_references(node);
        // Not in probed walks: finding a leaf's address may read the world (Ray-Strips' leaf
        // words), and a read no probe announced would fault a paged world's page in.
        if constexpr (!Probe::kRecords && !std::is_same_v<std::remove_cvref_t<LeafAddress>, NoLeafPrefetch>) {
          alignas(32) std::uint32_t reference[8];
          _mm256_store_si256(reinterpret_cast<__m256i*>(reference), references);
          for (unsigned mask = entered_mask; mask != 0; mask &= mask - 1) {
            const std::uint32_t child = reference[std::countr_zero(mask)];
            const char* line = child & kWideLeafReference
                                   ? static_cast<const char*>(static_cast<const void*>(leaf_address(child & ~kWideLeafReference)))
                                   : reinterpret_cast<const char*>(nodes + child);
            _mm_prefetch(line, _MM_HINT_T0);
            _mm_prefetch(line + 64, _MM_HINT_T0);
          }
        }
        if (std::popcount(entered_mask) == 2) {  // two: one comparison orders them, the farther is stacked
          alignas(32) std::uint32_t reference[8];
          alignas(32) float distance[8];
          alignas(32) float lanes[6][8];
          _mm256_store_si256(reinterpret_cast<__m256i*>(reference), references);
          _mm256_store_ps(distance, near);
          for (int b = 0; b < 6; ++b) _mm256_store_ps(lanes[b], bound[b]);
          int nearer = std::countr_zero(entered_mask);
          int farther = std::countr_zero(entered_mask & (entered_mask - 1));
          if (distance[farther] < distance[nearer]) std::swap(nearer, farther);
          stack.reference[top] = reference[farther];
          stack.distance[top] = distance[farther];
          for (int b = 0; b < 6; ++b) stack.bound[b][top] = lanes[b][farther];
          ++top;
          current = reference[nearer];
          frame.lower = {lanes[0][nearer], lanes[1][nearer], lanes[2][nearer]};
          frame.upper = {lanes[3][nearer], lanes[4][nearer], lanes[5][nearer]};
          continue;
        }
        const __m256i order = lane_sort::nearest_last_for<kIsa>(near, entered_mask);
        _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.reference + top),
                            _mm256_permutevar8x32_epi32(references, order));
        _mm256_storeu_ps(stack.distance + top, _mm256_permutevar8x32_ps(near, order));
        for (int b = 0; b < 6; ++b) _mm256_storeu_ps(stack.bound[b] + top, _mm256_permutevar8x32_ps(bound[b], order));
        top += static_cast<std::uint32_t>(std::popcount(entered_mask));
      }
    } else if (visit_leaf(current & ~kWideLeafReference, frame)) {
      return;
    }
    while (top > 0 && stack.distance[top - 1] > pruning_distance(tmax)) --top;
    if (top == 0) return;
    --top;
    current = stack.reference[top];
    frame.lower = {stack.bound[0][top], stack.bound[1][top], stack.bound[2][top]};
    frame.upper = {stack.bound[3][top], stack.bound[4][top], stack.bound[5][top]};
  }
}


// Up to eight coherent rays (two 2x2 pixel quads) through the tree together: each node's boxes
// are decoded once for the packet and slab-tested per ray, and each child is visited once
// with the mask of the rays that entered it, nearest first for the packet (by the least
// entry distance among its rays). A ray leaves a subtree once its own nearest hit lies
// before its entry there.
inline constexpr int kWidePacketRays = 8;

struct QuantizedWidePacketStack {
  static constexpr std::size_t kEntries = kMaxTreeDepth * QuantizedWideNode::kWidth + QuantizedWideNode::kWidth;
  struct Entry {
    alignas(32) float distance[kWidePacketRays];  // ray r's entry distance (valid where its bit is set)
    std::uint32_t reference;
    std::uint32_t rays;                   // bit r: ray r entered this child
    Bounds3 frame;
  };
  Entry entries[kEntries];
};

// `visit_leaf(reference, box, rays)` handles a leaf for the rays in the mask `rays`, shrinking
// their `tmax`; `live` marks the rays of `rays_in` that take part.
template <KernelIsa kIsa, typename Probe, typename VisitLeaf>
[[gnu::always_inline]] inline void walk_quantized_wide_packet(const QuantizedWideNode* nodes, const Bounds3& root_frame,
                                                              const SingleRay* rays_in, unsigned live,
                                                              const float* tmax, Probe& probe,
                                                              QuantizedWidePacketStack& stack, VisitLeaf&& visit_leaf) {
  using namespace quantized_wide;
  using Entry = QuantizedWidePacketStack::Entry;
  __m256 origin[kWidePacketRays][3], inverse[kWidePacketRays][3];
  for (unsigned bits = live; bits != 0; bits &= bits - 1) {
    const int r = std::countr_zero(bits);
    for (int axis = 0; axis < 3; ++axis) {
      origin[r][axis] = _mm256_set1_ps(rays_in[r].origin[axis]);
      inverse[r][axis] = _mm256_set1_ps(rays_in[r].box.inverse_direction[axis]);
    }
  }
  Entry current{{}, 0, live, root_frame};
  std::uint32_t top = 0;
  while (true) {
    if (!(current.reference & kWideLeafReference)) {
      const QuantizedWideNode& node = *probe.resident(nodes + current.reference, sizeof(QuantizedWideNode));
      __m256 bound[6];
      decode_children(node, current.frame, bound);
      const unsigned occupied = occupied_slots(node);
      PacketChildren children;
      for (unsigned bits = current.rays; bits != 0; bits &= bits - 1) {
        const int r = std::countr_zero(bits);
        __m256 entry;
        const unsigned entered = enter_children(bound, origin[r], inverse[r], rays_in[r].tmin, tmax[r], entry) & occupied;
        children.add(r, entered, entry);
      }
      const unsigned any = children.any();
      if (any != 0) {
        const std::uint64_t rays_by_child = children.rays_by_child();  // byte k: the rays in child k
        children.turn_to_children();                                   // row k: their distances to it
        alignas(32) std::int32_t order[8];
        alignas(32) std::uint32_t reference[8];
        alignas(32) float lanes[6][8];
        _mm256_store_si256(reinterpret_cast<__m256i*>(order), lane_sort::nearest_last_for<kIsa>(children.least, any));
        _mm256_store_si256(reinterpret_cast<__m256i*>(reference), child_references(node));
        for (int b = 0; b < 6; ++b) _mm256_store_ps(lanes[b], bound[b]);
        for (int n = 0, count = std::popcount(any); n < count; ++n) {  // farthest first: the nearest ends on top
          const int k = order[n];
          Entry& pushed = stack.entries[top++];
          _mm256_store_ps(pushed.distance, children.near[k]);
          pushed.reference = reference[k];
          pushed.rays = unsigned(rays_by_child >> (8 * k)) & 0xFFu;
          pushed.frame.lower = {lanes[0][k], lanes[1][k], lanes[2][k]};
          pushed.frame.upper = {lanes[3][k], lanes[4][k], lanes[5][k]};
        }
      }
    } else {
      visit_leaf(current.reference & ~kWideLeafReference, current.frame, current.rays);
    }
    // Pop the nearest subtree some ray can still improve on (not past its nearest hit).
    const __m256 limits = _mm256_mul_ps(_mm256_loadu_ps(tmax), _mm256_set1_ps(kPruningSlack));  // pruning_distance
    while (true) {
      if (top == 0) return;
      current = stack.entries[--top];
      const __m256 within = _mm256_cmp_ps(_mm256_load_ps(current.distance), limits, _CMP_NGT_UQ);
      current.rays &= unsigned(_mm256_movemask_ps(within));
      if (current.rays != 0) break;
    }
  }
}

}  // namespace wavetrace

#endif
