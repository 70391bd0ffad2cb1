// `hmq:width=8`: HMQ's global grid and leaf records under 8-wide nodes quantized against
// their frames (wide_hmq_node.hpp). Build: the binary SAH tree collapsed to eight children
// a node, the cut chosen by surface area; traversal: one ray at a time, the eight child
// boxes decoded and tested in AVX2 lanes, the entered ones sorted by distance onto the stack.
#include <algorithm>
#include <array>
#include <bit>
#include <chrono>
#include <cmath>
#include <limits>
#include <stdexcept>

#include <fmt/format.h>

#include "accel/ray_loop.hpp"
#include "accel/hmq/hmq_accelerator.hpp"
#include "accel/hmq/leaf_hit.hpp"
#include "accel/hmq/snapped_tree.hpp"
#include "accel/hmq/wide_hmq_node.hpp"
#include "accel/probed_accelerator.hpp"
#include "accel/section_archive.hpp"
#include "kernels/checked_narrowing.hpp"
#include "kernels/ray_box.hpp"
#include "memory/cache_aligned_allocator.hpp"

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif


namespace wavetrace {

#if defined(__AVX2__) && defined(__FMA__)
namespace {

using namespace hmq;
constexpr int kWidth = WideHmqNode::kWidth;
constexpr std::size_t kUnit = WideHmqNode::kLeafUnitBytes;
constexpr float kInfinity = std::numeric_limits<float>::infinity();
// A stack or child reference: a node index, or with this bit a leaf record's offset in units.
constexpr std::uint32_t kLeafRef = 0x8000'0000u;

float half_area(const Bounds3& b) {
  const glm::vec3 e = b.extent();
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

// q for one plane: the largest (lower) step count whose decoded plane stays at or below
// the child's lower bound, or (upper) at or above its upper bound.
std::uint8_t quantize_lower(float frame_lower, float step, float lower) {
  if (!(step > 0.0f)) return 0;
  float q = std::clamp(std::floor((lower - frame_lower) / step), 0.0f, 255.0f);
  while (q > 0.0f && std::fma(q, step, frame_lower) > lower) q -= 1.0f;
  return static_cast<std::uint8_t>(q);
}
std::uint8_t quantize_upper(float frame_upper, float step, float upper) {
  if (!(step > 0.0f)) return 0;
  float q = std::clamp(std::floor((frame_upper - upper) / step), 0.0f, 255.0f);
  while (q > 0.0f && std::fma(-q, step, frame_upper) < upper) q -= 1.0f;
  return static_cast<std::uint8_t>(q);
}

// Which binary nodes become wide nodes (Ylitie et al. 2017, §3.1, without their leaf
// choices: HMQ's leaves are fixed by its records): the cut of the binary tree into nodes of
// at most eight children that minimizes the summed cost of the wide nodes, each priced at its
// surface area (the chance a ray visits it) plus a constant that stands for its 64 bytes and
// the visit's fixed work. Greedy collapsing (open the widest child until eight) leaves
// nodes half empty near the leaves: 4.0 children a node on room:1M against 5.x here.
class CollapsePlan {
 public:
  explicit CollapsePlan(const BuildTree& tree)
      : best_(tree.nodes.size() * kWidth), split_(tree.nodes.size() * kWidth), opened_split(tree.nodes.size()) {
    const float root_area = std::max(half_area(tree.nodes[0].bounds), std::numeric_limits<float>::min());
    // Children before parents: an explicit post-order, the tree may be deeper than the call stack likes.
    std::vector<std::uint32_t> order, pending = {0};
    order.reserve(tree.nodes.size());
    while (!pending.empty()) {
      const std::uint32_t n = pending.back();
      pending.pop_back();
      order.push_back(n);
      if (!tree.nodes[n].leaf()) pending.insert(pending.end(), {tree.nodes[n].left, tree.nodes[n].right});
    }
    for (auto n = order.rbegin(); n != order.rend(); ++n) {
      const BuildNode& node = tree.nodes[*n];
      float* best = &best_[std::size_t(*n) * kWidth];
      std::uint8_t* split = &split_[std::size_t(*n) * kWidth];
      if (node.leaf()) {  // a leaf is one child wherever it goes; its own cost is the same in every cut
        std::fill(best, best + kWidth, 0.0f);
        std::fill(split, split + kWidth, std::uint8_t{0});
        continue;
      }
      const float* left = &best_[std::size_t(node.left) * kWidth];
      const float* right = &best_[std::size_t(node.right) * kWidth];
      // best[k - 1]: the cheapest way to hang the subtree below a node as at most k children.
      auto cheapest_split = [&](int k, std::uint8_t& chosen) {
        float cost = std::numeric_limits<float>::infinity();
        for (int j = 1; j < k; ++j) {
          const float c = left[j - 1] + right[k - j - 1];
          if (c < cost) cost = c, chosen = static_cast<std::uint8_t>(j);
        }
        return cost;
      };
      std::uint8_t opened = 1;
      const float as_node = half_area(node.bounds) / root_area + kNodeCost + cheapest_split(kWidth, opened);
      opened_split[*n] = opened;
      best[0] = as_node;
      split[0] = 0;
      for (int k = 2; k <= kWidth; ++k) {
        std::uint8_t chosen = 0;
        const float spread = cheapest_split(k, chosen);
        best[k - 1] = spread < as_node ? spread : as_node;
        split[k - 1] = spread < as_node ? chosen : 0;
      }
    }
  }

  // Appends the children that binary node `n` becomes when it may take `k` slots.
  void frontier(const BuildTree& tree, std::uint32_t n, int k, std::vector<std::uint32_t>& out) const {
    const std::uint8_t j = split_[std::size_t(n) * kWidth + k - 1];
    if (j == 0) return out.push_back(n);
    frontier(tree, tree.nodes[n].left, j, out);
    frontier(tree, tree.nodes[n].right, k - j, out);
  }

 private:
  // No price per node beyond its area: 1e-4 of the root's (8% fewer nodes on room:1M, 0.2
  // B/tri) measured no faster and would tie the cut to the scene's size.
  static constexpr float kNodeCost = 0.0f;
  std::vector<float> best_;
  std::vector<std::uint8_t> split_;  // 0: the node itself is the child; j: left gets j slots

 public:
  std::vector<std::uint8_t> opened_split;  // a wide node's split of its eight slots, left : right
};

struct PartBytes {
  std::size_t hierarchy = 0, geometry = 0, other = 0;
};

class WideEncoder {
 public:
  WideEncoder(const SnappedTree& snapped, LargeArray<WideHmqNode>& nodes, std::vector<std::byte>& leaves,
              PartBytes& parts)
      : tree_(snapped.tree), quantized_(snapped.quantized), grid_(snapped.grid), plan_(snapped.tree), nodes_(nodes),
        leaves_(leaves), parts_(parts) {}

  // Fills node `index` with the children of binary node `root` (collapsed to at most eight),
  // allocates its inner children next to each other, and fills them depth first.
  void encode(std::uint32_t root, std::uint32_t index, const Box& frame) {
    const std::vector<std::uint32_t> children = collapse(root);
    WideHmqNode node{};
    Box child_box[kWidth];
    for (int slot = 0; slot < int(children.size()); ++slot) {
      const Bounds3& bounds = tree_.nodes[children[slot]].bounds;
      for (int axis = 0; axis < 3; ++axis) {
        const float step = frame_step(frame, axis);
        node.lower(axis)[slot] = quantize_lower(frame.lower[axis], step, bounds.lower[axis]);
        node.upper(axis)[slot] = quantize_upper(frame.upper[axis], step, bounds.upper[axis]);
      }
      child_box[slot] = decode_wide_child(node, slot, frame);
    }

    node.leaf_base = checked_uint32(leaves_.size() / kUnit, "hmq:width=8 leaf offset");
    std::uint32_t inner_count = 0;
    for (int slot = 0; slot < int(children.size()); ++slot) {
      const BuildNode& child = tree_.nodes[children[slot]];
      if (!child.leaf()) {
        node.meta[slot] = WideHmqNode::kInnerMeta;
        ++inner_count;
        continue;
      }
      node.meta[slot] = static_cast<std::uint8_t>(encode_leaf_record(child, child_box[slot]));
    }
    if (leaves_.size() / kUnit >= kLeafRef) {
      throw std::length_error("hmq:width=8: the leaf records pass 4 GiB; build in smaller chunks (build.chunk_triangles)");
    }
    node.child_base = checked_uint32(nodes_.size(), "hmq:width=8 nodes");
    nodes_.resize(nodes_.size() + inner_count);
    nodes_[index] = node;
    parts_.hierarchy += sizeof(WideHmqNode);
    std::uint32_t next = node.child_base;
    for (int slot = 0; slot < kWidth; ++slot) {
      if (node.meta[slot] == WideHmqNode::kInnerMeta) encode(children[slot], next++, child_box[slot]);
    }
  }

 private:
  // The children of the wide node for binary node `root`, as the collapse plan chose them.
  std::vector<std::uint32_t> collapse(std::uint32_t root) const {
    std::vector<std::uint32_t> children;
    if (tree_.nodes[root].leaf()) return {root};
    const BuildNode& node = tree_.nodes[root];
    const int left = plan_.opened_split[root];
    plan_.frontier(tree_, node.left, left, children);
    plan_.frontier(tree_, node.right, kWidth - left, children);
    return children;
  }

  // Appends the leaf's record, zero-padded to whole 2-byte units; returns its units.
  std::uint32_t encode_leaf_record(const BuildNode& leaf, const Box& box) {
    const std::size_t start = leaves_.size();
    encode_leaf(quantized_, std::span(tree_.primitive_order.data() + leaf.first, leaf.count), snap_outward(grid_, box),
                leaves_);
    const LeafHeader header = read_leaf_header(leaves_.data() + start);
    const std::size_t identity = stream_bytes(header.id_bits, leaf.count) + stream_bytes(3, leaf.count);
    const std::size_t record = leaves_.size() - start;
    leaves_.resize(start + (record + kUnit - 1) / kUnit * kUnit, std::byte{0});
    parts_.other += identity;
    parts_.geometry += record - identity;
    parts_.hierarchy += leaves_.size() - start - record;
    const std::size_t units = (leaves_.size() - start) / kUnit;
    if (units > WideHmqNode::kMaxLeafUnits) throw std::logic_error("hmq:width=8: a leaf record over 508 bytes");
    return static_cast<std::uint32_t>(units);
  }

  const BuildTree& tree_;
  const QuantizedMesh& quantized_;
  const GlobalGrid& grid_;
  const CollapsePlan plan_;
  LargeArray<WideHmqNode>& nodes_;
  std::vector<std::byte>& leaves_;
  PartBytes& parts_;
};

// Bitonic network over eight int32 lanes, descending: per stage, lane i meets lane i ^ j and
// keeps the larger when `kTakeMax` says so.
struct SortStage {
  int partner[8];
  int take_max[8];
};
constexpr std::array<SortStage, 6> kDescendingStages = [] {
  std::array<SortStage, 6> stages{};
  int n = 0;
  for (int k = 2; k <= 8; k *= 2) {
    for (int j = k / 2; j >= 1; j /= 2, ++n) {
      for (int i = 0; i < 8; ++i) {
        stages[n].partner[i] = i ^ j;
        const bool upper = (i & j) != 0, descending_block = (i & k) != 0;
        stages[n].take_max[i] = (upper != descending_block) ? 0 : -1;  // descending overall
      }
    }
  }
  return stages;
}();

[[gnu::always_inline]] inline __m256i sort_descending(__m256i keys) {
  for (const SortStage& stage : kDescendingStages) {
    const __m256i other = _mm256_permutevar8x32_epi32(keys, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(stage.partner)));
    keys = _mm256_blendv_epi8(_mm256_min_epi32(keys, other), _mm256_max_epi32(keys, other),
                              _mm256_loadu_si256(reinterpret_cast<const __m256i*>(stage.take_max)));
  }
  return keys;
}

// Each child's reference: inner children number from child_base in slot order, leaf
// records from leaf_base by the units of the leaf slots before them (exclusive prefix sums
// over the meta bytes, in 16-bit lanes: leaf units in bits 0-10, inner count in bits 11-14).
[[gnu::always_inline]] inline __m256i child_references(const WideHmqNode& node) {
  const __m128i meta = _mm_cvtepu8_epi16(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.meta)));
  const __m128i inner = _mm_cmpeq_epi16(meta, _mm_set1_epi16(WideHmqNode::kInnerMeta));
  const __m128i counts = _mm_or_si128(_mm_andnot_si128(inner, meta), _mm_and_si128(inner, _mm_set1_epi16(1 << 11)));
  __m128i sums = _mm_add_epi16(counts, _mm_slli_si128(counts, 2));
  sums = _mm_add_epi16(sums, _mm_slli_si128(sums, 4));
  sums = _mm_add_epi16(sums, _mm_slli_si128(sums, 8));
  const __m256i before = _mm256_cvtepu16_epi32(_mm_sub_epi16(sums, counts));
  const __m256i leaf = _mm256_or_si256(_mm256_add_epi32(_mm256_set1_epi32(int(node.leaf_base)),
                                                        _mm256_and_si256(before, _mm256_set1_epi32(2047))),
                                       _mm256_set1_epi32(int(kLeafRef)));
  const __m256i child = _mm256_add_epi32(_mm256_set1_epi32(int(node.child_base)), _mm256_srli_epi32(before, 11));
  return _mm256_blendv_epi8(leaf, child, _mm256_cvtepi16_epi32(inner));
}

// What an hmq:width=8 world saves besides its arrays, `PREFIX` + "hmq8.state" (112 bytes):
//   offset  size  field
//        0    56  the global grid, as in "hmq.state" (hmq_accelerator.cpp)
//       56    12  root frame lower, float x, y, z (the binary tree's root box)
//       68    12  root frame upper
//       80     8  hierarchy bytes (nodes and record padding)
//       88     8  geometry bytes of the leaf records (vertices and connectivity)
//       96     8  other bytes of the leaf records (triangle ids and corners)
//      104     4  binary tree nodes, uint32
//      108     4  leaves, uint32
// Arrays: "hmq8.nodes" (WideHmqNode, node 0 the root) and "hmq8.leaves" (bytes, 8 of slack).
struct WideHmqSavedState {
  GlobalGrid grid;
  Box root;
  std::uint64_t hierarchy_bytes, geometry_bytes, other_bytes;
  std::uint32_t binary_nodes, leaves;
};
static_assert(sizeof(WideHmqSavedState) == 112);
constexpr std::uint32_t kWideHmqSavedVersion = 1;

class WideHmqAccelerator final : public ProbedAccelerator<WideHmqAccelerator> {
  friend class ProbedAccelerator<WideHmqAccelerator>;

 public:
  WideHmqAccelerator(const TriangleMesh& mesh, const HmqOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const SnappedTree snapped = build_snapped_tree(mesh, options);
    grid_ = snapped.grid;
    root_ = {snapped.tree.nodes[0].bounds.lower, snapped.tree.nodes[0].bounds.upper};
    LargeArray<WideHmqNode> nodes(1);
    std::vector<std::byte> leaves;
    PartBytes parts;
    WideEncoder(snapped, nodes, leaves, parts).encode(0, 0, root_);
    leaves.resize(leaves.size() + 8, std::byte{0});  // read slack for unaligned 8-byte stream loads
    parts.hierarchy += 8;
    const std::size_t encode_peak = nodes.capacity() * sizeof(WideHmqNode) + leaves.capacity();
    nodes_ = StoredArray<WideHmqNode>(std::move(nodes));
    leaves_ = StoredArray<std::byte>(LargeArray<std::byte>(leaves.begin(), leaves.end()));
    parts_ = parts;
    triangles_ = mesh.triangle_count();
    binary_nodes_ = snapped.tree.nodes.size();
    leaf_count_ = 0;
    for (const BuildNode& node : snapped.tree.nodes) leaf_count_ += node.leaf();
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = std::max(snapped.peak_bytes, encode_peak) + snapped.quantized.lines.size() * sizeof(glm::ivec3) +
                        snapped.tree.nodes.size() * sizeof(BuildNode) + memory().total();
  }

  explicit WideHmqAccelerator(const SectionLoader& loader) {
    loader.expect_kind("hmq8", kWideHmqSavedVersion);
    SectionLoader in = loader;
    archive(*this, in);
  }

  template <typename Archive>
  static void archive(auto& self, Archive& a) {
    WideHmqSavedState state{self.grid_,
                            self.root_,
                            self.parts_.hierarchy,
                            self.parts_.geometry,
                            self.parts_.other,
                            static_cast<std::uint32_t>(self.binary_nodes_),
                            static_cast<std::uint32_t>(self.leaf_count_)};
    a.value("hmq8.state", state);
    a.array("hmq8.nodes", self.nodes_);
    a.array("hmq8.leaves", self.leaves_);
    archive_common_state(a, self.triangles_, self.build_);
    if constexpr (Archive::kLoading) {
      self.grid_ = state.grid;
      self.root_ = state.root;
      self.parts_ = {state.hierarchy_bytes, state.geometry_bytes, state.other_bytes};
      self.binary_nodes_ = state.binary_nodes;
      self.leaf_count_ = state.leaves;
      if (self.nodes_.empty() || self.leaves_.size() < 8) a.fail("hmq8.nodes", "is empty: no hmq8 structure was saved");
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    out.add_value(prefix + "kind", saved_kind("hmq8", kWideHmqSavedVersion));
    SectionSaver saver(out, prefix);
    archive(*this, saver);
  }

  std::string name() const override { return "hmq8"; }

  MemoryReport memory() const override { return {parts_.hierarchy, parts_.geometry, parts_.other}; }
  BuildReport build() const override { return build_; }

  std::string build_notes() const override {
    const double triangles = double(std::max<std::size_t>(1, triangles_));
    return fmt::format(
        "grid {}x{}x{} bits, vertex error <= {:.3g}; {} 8-wide nodes ({:.2f} children each) over {} leaves ({:.1f} "
        "triangles each); bytes/tri: nodes+padding {:.2f}, vertices+connectivity {:.2f}, ids+corners {:.2f}",
        grid_.bits.x, grid_.bits.y, grid_.bits.z, grid_.max_vertex_error, nodes_.size(),
        double(leaf_count_ + nodes_.size() - 1) / double(std::max<std::size_t>(1, nodes_.size())), leaf_count_,
        triangles / double(std::max<std::size_t>(1, leaf_count_)), double(parts_.hierarchy) / triangles,
        double(parts_.geometry) / triangles, double(parts_.other) / triangles);
  }

  std::vector<std::span<const std::byte>> memory_spans() const override { return {nodes_.bytes(), leaves_.bytes()}; }

  std::optional<TriangleMesh> represented_mesh(const TriangleMesh& source) const override {
    TriangleMesh snapped = source;
    for (glm::vec3& p : snapped.positions) p = grid_.point(grid_.snap(p));
    return snapped;
  }

 private:
  // The traversal stack, one column per field (SoA) so that eight children are pushed with
  // one store per field. Depth first: a level pushes at most eight and pops one.
  struct Stack {
    static constexpr std::size_t kEntries = kMaxTreeDepth * kWidth + kWidth;
    alignas(32) std::uint32_t reference[kEntries];
    alignas(32) float distance[kEntries];
    alignas(32) float bound[6][kEntries];  // lower x, y, z, upper x, y, z: the child's frame
  };

  template <bool kAnyHit, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    Stack stack;
    const WideHmqNode* nodes = nodes_.data();
    const std::byte* leaves = leaves_.data();
    const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      const glm::vec3 &origin = ray.origin, &inverse = ray.box.inverse_direction;
      const __m256 origin_lanes[3] = {_mm256_set1_ps(origin.x), _mm256_set1_ps(origin.y), _mm256_set1_ps(origin.z)};
      const __m256 inverse_lanes[3] = {_mm256_set1_ps(inverse.x), _mm256_set1_ps(inverse.y), _mm256_set1_ps(inverse.z)};
      const WatertightRay& sheared = ray.sheared;
      const float tmin = ray.tmin;
      float tmax = ray.tmax;
      LeafHit best;
      std::uint32_t current = 0, top = 0;
      Box frame = root_;
      while (true) {
        if (!(current & kLeafRef)) {
          const WideHmqNode& node = nodes[current];
          probe.read(&node, sizeof node);
          __m256 near = _mm256_set1_ps(tmin), far = _mm256_set1_ps(kInfinity);
          __m256 bound[6];
          for (int axis = 0; axis < 3; ++axis) {
            const __m256 step = _mm256_set1_ps(frame_step(frame, axis));
            const __m256 q_lower = _mm256_cvtepi32_ps(
                _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.lower(axis)))));
            const __m256 q_upper = _mm256_cvtepi32_ps(
                _mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.upper(axis)))));
            bound[axis] = _mm256_fmadd_ps(q_lower, step, _mm256_set1_ps(frame.lower[axis]));
            bound[3 + axis] = _mm256_fnmadd_ps(q_upper, step, _mm256_set1_ps(frame.upper[axis]));
            const __m256 t0 = _mm256_mul_ps(_mm256_sub_ps(bound[axis], origin_lanes[axis]), inverse_lanes[axis]);
            const __m256 t1 = _mm256_mul_ps(_mm256_sub_ps(bound[3 + axis], origin_lanes[axis]), inverse_lanes[axis]);
            // A NaN slab distance (origin on a plane the ray runs parallel to) leaves the
            // interval as it was: max/min return their second operand when one is NaN.
            near = _mm256_max_ps(_mm256_min_ps(t1, t0), near);
            far = _mm256_min_ps(_mm256_max_ps(t0, t1), far);
          }
          far = _mm256_min_ps(_mm256_mul_ps(far, _mm256_set1_ps(kSlabFarScale)), _mm256_set1_ps(tmax));
          const __m256i empty = _mm256_cvtepi8_epi32(
              _mm_cmpeq_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.meta)), _mm_setzero_si128()));
          const __m256 entered = _mm256_andnot_ps(_mm256_castsi256_ps(empty), _mm256_cmp_ps(near, far, _CMP_LE_OQ));
          const auto entered_mask = static_cast<unsigned>(_mm256_movemask_ps(entered));
          if (std::has_single_bit(entered_mask)) {  // one child: go down, nothing to order or stack
            const int lane = std::countr_zero(entered_mask);
            alignas(32) std::uint32_t reference[kWidth];
            alignas(32) float lanes[6][kWidth];
            _mm256_store_si256(reinterpret_cast<__m256i*>(reference), child_references(node));
            for (int b = 0; b < 6; ++b) _mm256_store_ps(lanes[b], bound[b]);
            current = reference[lane];
            frame = {{lanes[0][lane], lanes[1][lane], lanes[2][lane]}, {lanes[3][lane], lanes[4][lane], lanes[5][lane]}};
            continue;
          }
          if (entered_mask != 0) {
            // Nearest first, by sorting: keys are the entry distance's bits (>= 0, so they order
            // as integers) with the lane in the low three, lanes not entered -1, sorted
            // descending so that the nearest child lands on top of the stack.
            const __m256i keys = _mm256_blendv_epi8(
                _mm256_set1_epi32(-1),
                _mm256_or_si256(_mm256_and_si256(_mm256_castps_si256(near), _mm256_set1_epi32(~7)), lane_index),
                _mm256_castps_si256(entered));
            const __m256i order = _mm256_and_si256(sort_descending(keys), _mm256_set1_epi32(7));
            _mm256_storeu_si256(reinterpret_cast<__m256i*>(stack.reference + top),
                                _mm256_permutevar8x32_epi32(child_references(node), order));
            _mm256_storeu_ps(stack.distance + top, _mm256_permutevar8x32_ps(near, order));
            for (int b = 0; b < 6; ++b) _mm256_storeu_ps(stack.bound[b] + top, _mm256_permutevar8x32_ps(bound[b], order));
            top += static_cast<std::uint32_t>(std::popcount(entered_mask));
          }
        } else {
          test_leaf_record<kAnyHit>(leaves + std::size_t(current & ~kLeafRef) * kUnit, grid_, frame, sheared, tmin, tmax,
                                    best, probe);
          if (kAnyHit && best.found) break;
        }
        while (top > 0 && stack.distance[top - 1] > tmax) --top;
        if (top == 0) break;
        --top;
        current = stack.reference[top];
        frame = {{stack.bound[0][top], stack.bound[1][top], stack.bound[2][top]},
                 {stack.bound[3][top], stack.bound[4][top], stack.bound[5][top]}};
      }
      write_leaf_hit<!kAnyHit>(best, hits, i);
    });
  }

  GlobalGrid grid_;
  Box root_{};
  StoredArray<WideHmqNode> nodes_;
  StoredArray<std::byte> leaves_;
  PartBytes parts_;
  std::size_t binary_nodes_ = 0, leaf_count_ = 0, triangles_ = 0;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_wide_hmq_accelerator(const TriangleMesh& mesh, const HmqOptions& options) {
  return std::make_unique<WideHmqAccelerator>(mesh, options);
}

std::unique_ptr<Accelerator> load_wide_hmq_accelerator(const SectionLoader& loader) {
  return std::make_unique<WideHmqAccelerator>(loader);
}

#else  // a build below x86-64-v3

constexpr const char* kNeedsAvx2 = "hmq:width=8 traverses in AVX2 and FMA lanes: build with WAVETRACE_ARCH=x86-64-v3 or newer";
std::unique_ptr<Accelerator> make_wide_hmq_accelerator(const TriangleMesh&, const HmqOptions&) {
  throw std::invalid_argument(kNeedsAvx2);
}
std::unique_ptr<Accelerator> load_wide_hmq_accelerator(const SectionLoader& loader) { loader.fail("kind", kNeedsAvx2); }

#endif

}  // namespace wavetrace
