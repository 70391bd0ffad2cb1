// The 8-wide BVH: the binary SAH tree cut into nodes of up to eight children by the
// surface-area plan (collapse_plan.hpp), traversed one ray at a time (camera rays eight at
// a time) with all eight child boxes tested in one AVX2 pass, nearest child first; leaves
// are blocks of four triangles tested two blocks to a pass of eight lanes.
#include "wavetrace/accel/bvh/wide_bvh_accelerator.hpp"
#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <algorithm>
#include <bit>
#include <chrono>
#include <cstddef>
#include <limits>

#include <fmt/format.h>

#if WAVETRACE_AVX2
#include <immintrin.h>
#endif

#include "wavetrace/accel/bvh/bvh_build.hpp"
#include "wavetrace/accel/bvh/collapse_plan.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/triangle_block.hpp"
#include "wavetrace/accel/bvh/wide_bvh_node.hpp"
#include "wavetrace/kernels/lane_sort.hpp"
#include "wavetrace/kernels/lane_transpose.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/accel/bvh/leaf_query.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr int kWidth = WideBvhNode::kWidth;

// Per-ray constants of the eight-box test.
struct WideRay {
  glm::vec3 origin;
  glm::vec3 inverse;
  int zero_axes;  // bit a set: direction[a] == 0, that slab is tested by comparison
  // Per axis, the byte offset in a node of the planes the ray enters by: lower_a where it
  // moves up the axis, upper_a where down. The exit planes are the other row (offset ^ 32).
  std::uint32_t entry_row[3];

  static_assert(offsetof(WideBvhNode, upper_x) == 32 && offsetof(WideBvhNode, lower_y) == 64 &&
                offsetof(WideBvhNode, upper_y) == 96 && offsetof(WideBvhNode, lower_z) == 128 &&
                offsetof(WideBvhNode, upper_z) == 160, "a node's rows of planes, lower and upper by turns, 32 bytes each");
  WideRay() = default;
  WideRay(const glm::vec3& origin_, const glm::vec3& inverse_, const glm::vec3& direction)
      : origin(origin_), inverse(inverse_),
        zero_axes((direction.x == 0.0f) | (direction.y == 0.0f) << 1 | (direction.z == 0.0f) << 2) {
    for (int axis = 0; axis < 3; ++axis) entry_row[axis] = 64u * axis + (direction[axis] < 0.0f ? 32u : 0u);
  }
};

// The traversal stack, one column per field so that the entered children are pushed with one
// store per field. A level pushes at most eight and pops one; the stores write eight lanes.
struct WideStack {
  static constexpr std::size_t kEntries = kMaxTreeDepth * kWidth + kWidth;
  alignas(32) std::uint32_t child[kEntries];
  alignas(32) std::uint32_t count[kEntries];
  alignas(32) float distance[kEntries];
};

// Entry distances of the ray into the node's eight child boxes; returns the mask of the
// lanes entered (bit k: child k), whose distances are valid. One source for both kernel sets:
// the AVX-512 walk inlines it in EVEX form. A copy comparing into mask registers duplicated
// this loop for no measurable gain (docs/measurements.md, "Kernel sets").
[[gnu::always_inline]] inline unsigned intersect_children(const WideBvhNode& node, const WideRay& ray, float tmin,
                                                          float tmax, float distance[kWidth]) {
#if WAVETRACE_AVX2
  const __m256 infinity = _mm256_set1_ps(kInfinity);
  __m256 near = _mm256_set1_ps(tmin);
  __m256 far = infinity;
  const char* planes = reinterpret_cast<const char*>(&node);
  for (int axis = 0; axis < 3; ++axis) {
    // The planes it enters and leaves by, chosen once a ray, not sorted by a min and a max
    // a node (as Embree's walks do).
    const __m256 entry_plane = _mm256_load_ps(reinterpret_cast<const float*>(planes + ray.entry_row[axis]));
    const __m256 exit_plane = _mm256_load_ps(reinterpret_cast<const float*>(planes + (ray.entry_row[axis] ^ 32u)));
    const __m256 origin = _mm256_set1_ps(ray.origin[axis]);
    __m256 entry, exit;
    if (ray.zero_axes & (1 << axis)) {
      // The ray never moves along this axis: inside the slab for all t, or never.
      const __m256 inside =
          _mm256_and_ps(_mm256_cmp_ps(entry_plane, origin, _CMP_LE_OQ), _mm256_cmp_ps(origin, exit_plane, _CMP_LE_OQ));
      entry = _mm256_blendv_ps(infinity, _mm256_set1_ps(-kInfinity), inside);
      exit = _mm256_blendv_ps(_mm256_set1_ps(-kInfinity), infinity, inside);
    } else {
      const __m256 inverse = _mm256_set1_ps(ray.inverse[axis]);
      entry = _mm256_mul_ps(_mm256_sub_ps(entry_plane, origin), inverse);
      exit = _mm256_mul_ps(_mm256_sub_ps(exit_plane, origin), inverse);
    }
    near = _mm256_max_ps(near, entry);
    far = _mm256_min_ps(far, exit);
  }
  far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(kSlabFarScale)), _mm256_set1_ps(tmax));
  _mm256_store_ps(distance, near);
  // near < inf as well: an unused lane (bounds +inf) gives near = far = +inf when tmax is +inf.
  const __m256 entered = _mm256_and_ps(_mm256_cmp_ps(near, far, _CMP_LE_OQ), _mm256_cmp_ps(near, infinity, _CMP_LT_OQ));
  return static_cast<unsigned>(_mm256_movemask_ps(entered));
#else
  unsigned mask = 0;
  for (int k = 0; k < kWidth; ++k) {
    const BoxRay box{ray.origin, ray.inverse};
    distance[k] = intersect_box(box, {node.lower_x[k], node.lower_y[k], node.lower_z[k]},
                                {node.upper_x[k], node.upper_y[k], node.upper_z[k]}, tmin, tmax);
    if (distance[k] != kInfinity) mask |= 1u << k;
  }
  return mask;
#endif
}

// Pushes the children in `mask` (their entry distances in `distance`) farthest first, so that
// the nearest is on top: with AVX2 by the bitonic lane sort and one permute per column.
template <KernelIsa kIsa>
[[gnu::always_inline]] inline void push_nearest_last(const WideBvhNode& node, unsigned mask, const float distance[kWidth],
                                                     WideStack& stack, std::uint32_t& top) {
  if (mask == 0) return;
#if WAVETRACE_AVX2
  const __m256 near = _mm256_load_ps(distance);
  // The sort keys are the distances' bits, which order as integers only from +0 up: a -0
  // (max_ps keeps its second operand on a tie with tmin = 0) would sort below the lanes not
  // entered and be lost.
  const __m256i order = lane_sort::nearest_last_for<kIsa>(_mm256_max_ps(near, _mm256_setzero_ps()), mask);
  const __m256i children = _mm256_load_si256(reinterpret_cast<const __m256i*>(node.child));
  const __m256i counts = _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.count)));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.child + top), _mm256_permutevar8x32_epi32(children, order));
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.count + top), _mm256_permutevar8x32_epi32(counts, order));
  _mm256_storeu_ps(stack.distance + top, _mm256_permutevar8x32_ps(near, order));
  top += static_cast<std::uint32_t>(std::popcount(mask));
#else
  const std::uint32_t first = top;
  for (; mask != 0; mask &= mask - 1) {  // insertion by descending distance
    const int k = std::countr_zero(mask);
    std::uint32_t slot = top++;
    for (; slot > first && stack.distance[slot - 1] < distance[k]; --slot) {
      stack.child[slot] = stack.child[slot - 1];
      stack.count[slot] = stack.count[slot - 1];
      stack.distance[slot] = stack.distance[slot - 1];
    }
    stack.child[slot] = node.child[k], stack.count[slot] = node.count[k], stack.distance[slot] = distance[k];
  }
#endif
}

// Asks for the lines of every child in `mask` before any is visited: the walk goes down the
// nearest first, and by the time it pops the others their node or block is in cache
// (measured: 8% faster on room:1M diffuse and camera rays, 1 thread, median ratio to Embree
// over three alternating rounds). All four lines of a node, and both blocks of a leaf's first
// pass (docs/measurements.md, "bvh:width=8's leaves two blocks a pass").
[[gnu::always_inline]] inline void prefetch_children(const WideBvhNode& node, unsigned mask, const WideBvhNode* nodes,
                                                     const TriangleBlock* blocks) {
#if WAVETRACE_AVX2
  for (; mask != 0; mask &= mask - 1) {
    const int k = std::countr_zero(mask);
    if (node.count[k] == 0) {  // a node: its boxes, and the fourth line, its children and counts
      const char* child = reinterpret_cast<const char*>(nodes + node.child[k]);
      for (int line = 0; line < 4; ++line) _mm_prefetch(child + 64 * line, _MM_HINT_T0);
    } else {  // a leaf: the blocks of its first pass (two when it has more than four triangles)
      const TriangleBlock* first = blocks + node.child[k];
      const char* begin = reinterpret_cast<const char*>(first);
      const char* last = reinterpret_cast<const char*>(first + (node.count[k] > TriangleBlock::kLanes ? 2 : 1)) - 1;
      for (const char* line = begin; line < last; line += 64) _mm_prefetch(line, _MM_HINT_T0);
      _mm_prefetch(last, _MM_HINT_T0);
    }
  }
#else
  (void)node, (void)mask, (void)nodes, (void)blocks;
#endif
}

class WideBvhAccelerator final : public ProbedAccelerator<WideBvhAccelerator> {
  friend class ProbedAccelerator<WideBvhAccelerator>;

 public:
  explicit WideBvhAccelerator(SectionLoader& in) : geometry_(in) {
    load_bvh(in, "bvh8.nodes", nodes_, "bvh8.triangle_blocks", blocks_, build_, [&](std::uint64_t first, std::uint64_t count) {
      if (count == 0 || first + TriangleBlock::blocks_for(count) > blocks_.size()) {
        in.fail("bvh8.nodes", fmt::format("has a leaf of {} triangles in blocks from {} beyond its {} triangle blocks", count,
                                          first, blocks_.size()));
      }
    });
    for (const TriangleBlock& block : blocks_) {
      for (const std::uint32_t slot : block.slot) {
        if (slot >= geometry_.triangle_count()) in.fail("bvh8.triangle_blocks", "names a triangle that does not exist");
      }
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    save_bvh(out, prefix, geometry_, "bvh8.nodes", nodes_, "bvh8.triangle_blocks", blocks_, build_);
  }

  WideBvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options) : WideBvhAccelerator(mesh, options, PhaseClock{}) {}

  std::string name() const override { return "bvh8"; }

  // The face set stays for the hit's surface, the id map and saving; the walk reads blocks.
  MemoryReport memory() const override {
    return {nodes_.size() * sizeof(WideBvhNode), blocks_.size() * sizeof(TriangleBlock) + geometry_.geometry_bytes(),
            geometry_.id_map_bytes()};
  }
  BuildReport build() const override { return build_; }

#if WAVETRACE_AVX2
  // Camera rays eight at a time (two 2x2 pixel quads, as hmq:width=8 walks them): a node is
  // fetched once a packet and its eight boxes slab-tested per ray, each child entered visited
  // once with the mask of the rays that entered it, nearest first by the least entry distance
  // among them; each ray tests a leaf's blocks alone. The hits are the single rays' (ties
  // resolve by id, not by the order a walk meets them: kernels/nearest_hit.hpp).
  void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    walk_with(kernel_isa(), [&]<KernelIsa kIsa>() {
      PacketStack stack;
      for (std::uint32_t begin = range.begin; begin < range.end; begin += kPacketRays) {
        trace_packet<kIsa>(rays, hits, begin, std::min<std::uint32_t>(begin + kPacketRays, range.end), stack);
      }
    });
  }
#endif

  std::vector<std::span<const std::byte>> memory_spans() const override {
    std::vector<std::span<const std::byte>> spans = {std::as_bytes(std::span(nodes_)), std::as_bytes(std::span(blocks_))};
    for (const auto& span : geometry_.spans()) spans.push_back(span);
    return spans;
  }

 private:
  // The clock starts before the face set is made (a member), so that its copy is timed too.
  WideBvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options, PhaseClock clock)
      : geometry_(mesh, options.triangle_order) {
    const BuildTree tree = build_bvh_tree_timed(geometry_, options, clock, build_);
    LargeArray<std::uint32_t> leaf_triangles;
    leaf_triangles.reserve(geometry_.triangle_count());
    build_nodes_.reserve(tree.nodes.size() / 4 + 1);
    collapse(tree, CollapsePlan(tree), 0, leaf_triangles);
    clock.lap(build_.phases, "collapse");
    adopt_leaf_order(options, geometry_, leaf_triangles);
    LargeArray<TriangleBlock> blocks = block_leaves(leaf_triangles);
    nodes_ = StoredArray<WideBvhNode>(std::move(build_nodes_));
    blocks_ = StoredArray<TriangleBlock>(std::move(blocks));
    clock.lap(build_.phases, "blocks");
    build_.seconds = clock.elapsed();
    build_.peak_bytes = bvh_build_peak_bytes(tree, geometry_, memory().total());
  }

  // Writes the wide node for binary node `root` (and, depth-first, everything below it);
  // returns its index. A binary leaf at the root becomes a wide node with one leaf lane, whose
  // child is its first slot in `leaf_triangles` until block_leaves makes it a block.
  std::uint32_t collapse(const BuildTree& tree, const CollapsePlan& plan, std::uint32_t root,
                         LargeArray<std::uint32_t>& leaf_triangles) {
    const std::vector<std::uint32_t> lanes = plan.children(tree, root);
    const auto index = static_cast<std::uint32_t>(build_nodes_.size());
    build_nodes_.emplace_back();
    WideBvhNode node{};
    for (int k = 0; k < kWidth; ++k) {
      node.lower_x[k] = node.lower_y[k] = node.lower_z[k] = kInfinity;
      node.upper_x[k] = node.upper_y[k] = node.upper_z[k] = kInfinity;
    }
    for (std::size_t k = 0; k < lanes.size(); ++k) {
      const BuildNode& child = tree.nodes[lanes[k]];
      node.lower_x[k] = child.bounds.lower.x, node.lower_y[k] = child.bounds.lower.y, node.lower_z[k] = child.bounds.lower.z;
      node.upper_x[k] = child.bounds.upper.x, node.upper_y[k] = child.bounds.upper.y, node.upper_z[k] = child.bounds.upper.z;
      if (child.leaf()) {
        node.child[k] = static_cast<std::uint32_t>(leaf_triangles.size());
        node.count[k] = static_cast<std::uint8_t>(child.count);
        for (std::uint32_t i = 0; i < child.count; ++i) leaf_triangles.push_back(tree.primitive_order[child.first + i]);
      } else {
        node.child[k] = collapse(tree, plan, lanes[k], leaf_triangles);
        node.count[k] = 0;
      }
    }
    build_nodes_[index] = node;
    return index;
  }

  // Copies each leaf's triangles into blocks, leaves in node order, and points the leaf lanes
  // at them. `leaf_index` maps leaf slots to face-set slots (empty: the same).
  LargeArray<TriangleBlock> block_leaves(const LargeArray<std::uint32_t>& leaf_index) {
    // Counted first: grown by doubling, the blocks (most of a bvh8's bytes) were copied and
    // their pages touched twice over.
    std::size_t block_count = 0;
    for (const WideBvhNode& node : build_nodes_) {
      for (int k = 0; k < kWidth; ++k) block_count += (node.count[k] + TriangleBlock::kLanes - 1) / TriangleBlock::kLanes;
    }
    LargeArray<TriangleBlock> blocks;
    blocks.reserve(block_count);
    const glm::vec3* positions = geometry_.positions();
    for (WideBvhNode& node : build_nodes_) {
      for (int k = 0; k < kWidth; ++k) {
        if (node.count[k] == 0) continue;  // an inner or unused lane
        const std::uint32_t first_slot = node.child[k];
        node.child[k] = static_cast<std::uint32_t>(blocks.size());
        for (std::uint32_t base = 0; base < node.count[k]; base += TriangleBlock::kLanes) {
          TriangleBlock block{};
          for (std::uint32_t lane = 0; lane < TriangleBlock::kLanes && base + lane < node.count[k]; ++lane) {
            const std::uint32_t slot = first_slot + base + lane;
            const std::uint32_t triangle = leaf_index.empty() ? slot : leaf_index[slot];
            const glm::uvec3 corners = geometry_.triangles()[triangle];
            block.slot[lane] = triangle;
            for (int c = 0; c < 3; ++c) {
              for (int axis = 0; axis < 3; ++axis) block.corners.corner[c][axis][lane] = positions[corners[c]][axis];
            }
          }
          blocks.push_back(block);
        }
      }
    }
    return blocks;
  }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    WideStack stack;
    const WideBvhNode* nodes = nodes_.data();
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      const WideRay box_ray(ray.origin, ray.box.inverse_direction, ray.direction);
      LeafQuery query(geometry_, {}, ray);
      const float tmin = query.tmin;
      float& tmax = query.tmax;

      std::uint32_t top = 0;
      std::uint32_t child = 0, count = 0;  // the root
      while (true) {
        if (count == 0) {
          alignas(32) float distance[kWidth];
          const WideBvhNode& node = nodes[child];
          probe.read(&node, sizeof node);
          const unsigned mask = intersect_children(node, box_ray, tmin, pruning_distance(tmax), distance);
          if (std::has_single_bit(mask)) {  // one child entered: nothing to order or stack
            const int k = std::countr_zero(mask);
            child = node.child[k], count = node.count[k];
            continue;
          }
          prefetch_children(node, mask, nodes, blocks_.data());
          if (std::popcount(mask) == 2) {  // two: one comparison orders them, the farther is stacked
            int near = std::countr_zero(mask);
            int far = std::countr_zero(mask & (mask - 1));
            if (distance[far] < distance[near]) std::swap(near, far);
            stack.child[top] = node.child[far], stack.count[top] = node.count[far], stack.distance[top] = distance[far];
            ++top;
            child = node.child[near], count = node.count[near];
            continue;
          }
          push_nearest_last<kIsa>(node, mask, distance, stack, top);
        } else {
          query.test_blocks<kAnyHit>(blocks_.data() + child, count, probe);
          if (kAnyHit && query.found()) break;
        }
        while (top > 0 && stack.distance[top - 1] > pruning_distance(tmax)) --top;
        if (top == 0) break;
        --top;
        child = stack.child[top], count = stack.count[top];
      }
      query.write<!kAnyHit>(hits, i, probe);
    });
  }

#if WAVETRACE_AVX2
  static constexpr int kPacketRays = 8;
  // A subtree some of the packet's rays entered: their mask and each one's entry distance
  // (lane r: ray r's, valid where its bit is set).
  struct PacketEntry {
    alignas(32) float distance[kPacketRays];
    std::uint32_t child, count, rays;
  };
  // A level pushes at most eight entries and pops one, as the single ray's stack.
  struct PacketStack {
    PacketEntry entries[kMaxTreeDepth * kWidth + kWidth];
  };

  template <KernelIsa kIsa>
  [[gnu::always_inline]] void trace_packet(const RayBatch& rays, HitBatch& hits, std::uint32_t begin, std::uint32_t end,
                                           PacketStack& stack) const {
    NullProbe probe;
    const WideBvhNode* nodes = nodes_.data();
    // Slots past `end` repeat the last ray and are never live: LeafQuery has no empty state.
    SingleRay packet[kPacketRays];
    for (std::uint32_t r = 0; r < kPacketRays; ++r) packet[r] = load_ray(rays, std::min(begin + r, end - 1));
    LeafQuery query[kPacketRays] = {
        LeafQuery(geometry_, {}, packet[0]), LeafQuery(geometry_, {}, packet[1]), LeafQuery(geometry_, {}, packet[2]),
        LeafQuery(geometry_, {}, packet[3]), LeafQuery(geometry_, {}, packet[4]), LeafQuery(geometry_, {}, packet[5]),
        LeafQuery(geometry_, {}, packet[6]), LeafQuery(geometry_, {}, packet[7])};
    WideRay box_ray[kPacketRays];
    alignas(32) float limit[kPacketRays];  // pruning_distance of each ray's nearest hit so far
    unsigned live = 0;
    for (std::uint32_t r = 0; r < kPacketRays; ++r) {
      const std::uint32_t i = begin + r;
      limit[r] = i < end ? pruning_distance(query[r].tmax) : -kInfinity;
      if (i >= end || !(rays.flags[i] & ray_flags::alive)) continue;
      box_ray[r] = WideRay(packet[r].origin, packet[r].box.inverse_direction, packet[r].direction);
      live |= 1u << r;
    }
    PacketEntry current{{}, 0, 0, live};  // the root
    std::uint32_t top = 0;
    while (live != 0) {  // until no entry is left for any ray (the pop below breaks out)
      if (current.count == 0) {
        const WideBvhNode& node = nodes[current.child];
        PacketChildren children;
        for (unsigned bits = current.rays; bits != 0; bits &= bits - 1) {
          const int r = std::countr_zero(bits);
          alignas(32) float distance[kWidth];
          const unsigned entered = intersect_children(node, box_ray[r], query[r].tmin, limit[r], distance);
          children.add(r, entered, _mm256_load_ps(distance));
        }
        const unsigned any = children.any();
        const std::uint64_t rays_by_child = children.rays_by_child();  // byte k: the rays that entered child k
        if (std::has_single_bit(any)) {  // one child entered: nothing to order or stack
          const int k = std::countr_zero(any);
          current.child = node.child[k], current.count = node.count[k];
          current.rays = unsigned(rays_by_child >> (8 * k)) & 0xFFu;
          continue;
        }
        if (any != 0) {
          prefetch_children(node, any, nodes, blocks_.data());
          children.turn_to_children();  // row k: the rays' entry distances into child k
          // Distances as integers order only from +0 up (push_nearest_last).
          alignas(32) std::int32_t order[kWidth];
          _mm256_store_si256(reinterpret_cast<__m256i*>(order),
                             lane_sort::nearest_last_for<kIsa>(_mm256_max_ps(children.least, _mm256_setzero_ps()), any));
          for (int n = 0, count = std::popcount(any); n < count; ++n) {  // farthest first: the nearest ends on top
            const int k = order[n];
            PacketEntry& pushed = stack.entries[top++];
            _mm256_store_ps(pushed.distance, children.near[k]);
            pushed.child = node.child[k], pushed.count = node.count[k];
            pushed.rays = unsigned(rays_by_child >> (8 * k)) & 0xFFu;
          }
        }
      } else {
        for (unsigned bits = current.rays; bits != 0; bits &= bits - 1) {
          const int r = std::countr_zero(bits);
          query[r].template test_blocks<false>(blocks_.data() + current.child, current.count, probe);
          limit[r] = pruning_distance(query[r].tmax);
        }
      }
      // Pop the nearest subtree some ray can still improve on (not past its nearest hit).
      unsigned still = 0;
      const __m256 limits = _mm256_load_ps(limit);
      while (still == 0 && top > 0) {
        current = stack.entries[--top];
        const __m256 within = _mm256_cmp_ps(_mm256_load_ps(current.distance), limits, _CMP_NGT_UQ);
        still = unsigned(_mm256_movemask_ps(within)) & current.rays;
      }
      if (still == 0) break;
      current.rays = still;
    }
    for (std::uint32_t i = begin; i < end; ++i) {
      if (live >> (i - begin) & 1u) {
        query[i - begin].template write<true>(hits, i, probe);
      } else {
        hits.set_miss(i);
      }
    }
  }
#endif

  IndexedFaceSet geometry_;
  StoredArray<WideBvhNode> nodes_;
  StoredArray<TriangleBlock> blocks_;
  LargeArray<WideBvhNode> build_nodes_;  // while collapsing; empty once built
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> load_wide_bvh_accelerator(SectionLoader& in) {
  return std::make_unique<WideBvhAccelerator>(in);
}

std::unique_ptr<Accelerator> make_wide_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options) {
  return std::make_unique<WideBvhAccelerator>(mesh, options);
}

}  // namespace wavetrace
