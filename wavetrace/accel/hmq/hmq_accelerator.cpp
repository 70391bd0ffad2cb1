// HMQ build (grid, snapping, SAH tree over the snapped triangles, uncompressed top, blocks
// of quantized nodes with leaf records) and single-ray traversal decoding on the fly.
#include "wavetrace/accel/hmq/hmq_accelerator.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/bvh_walk.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/hmq/block_check.hpp"
#include "wavetrace/accel/bvh/leaf_query.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/hmq/child_pair.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/accel/hmq/leaf_codec.hpp"
#include "wavetrace/accel/hmq/leaf_hit.hpp"
#include "wavetrace/accel/hmq/snapped_tree.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/kernels/triangle_intersect.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {
namespace {

using namespace hmq;
using Clock = std::chrono::steady_clock;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

Box box_of(const Bounds3& bounds) { return {bounds.lower, bounds.upper}; }

// The 24 box bits of `child` against its parent's decoded box, rounded outward.
std::uint32_t quantize_child(const Box& parent, const Bounds3& child) {
  std::uint32_t bits = 0;
  for (int axis = 0; axis < 3; ++axis) {
    const float step = (parent.upper[axis] - parent.lower[axis]) * 0.0625f;
    std::uint32_t low = 0, high = 0;
    if (step > 0.0f) {
      low = static_cast<std::uint32_t>(std::clamp(std::floor((child.lower[axis] - parent.lower[axis]) / step), 0.0f, 15.0f));
      while (low > 0 && parent.lower[axis] + float(low) * step > child.lower[axis]) --low;
      high = static_cast<std::uint32_t>(std::clamp(std::floor((parent.upper[axis] - child.upper[axis]) / step), 0.0f, 15.0f));
      while (high > 0 && parent.upper[axis] - float(high) * step < child.upper[axis]) --high;
    }
    bits |= low << (4 * axis) | high << (12 + 4 * axis);
  }
  return bits;
}

class BlockEncoder {
 public:
  BlockEncoder(const BuildTree& tree, const QuantizedMesh& quantized, const GlobalGrid& grid,
               std::vector<std::byte>& blocks, PartBytes& parts)
      : tree_(tree), quantized_(quantized), grid_(grid), blocks_(blocks), parts_(parts) {}

  // Encodes the treelet under `roots` (whose parent box is `parent`) into a block and its
  // descendants; returns the block's word offset.
  std::uint32_t encode(const std::vector<std::uint32_t>& roots, const Box& parent) {
    struct Slot {
      std::uint32_t build_node;
      Box box;  // decoded
      std::uint32_t bits;
      std::uint32_t index = 0;
      bool forwarded = false;
    };
    std::vector<Slot> slots;
    for (const std::uint32_t root : roots) {
      const std::uint32_t bits = quantize_child(parent, tree_.nodes[root].bounds);
      slots.push_back({root, decode_child_box(parent, bits), bits});
    }
    std::vector<std::uint32_t> forwarded;  // slot numbers, in forward-slot order
    for (std::size_t i = 0; i < slots.size(); ++i) {
      const BuildNode& node = tree_.nodes[slots[i].build_node];
      if (node.leaf()) continue;
      // Keep room for a forward slot for every inner node not yet expanded, the new
      // children included, so that node and forward slots never pass 64.
      std::size_t unexpanded = 0;
      for (std::size_t j = i + 1; j < slots.size(); ++j) unexpanded += !tree_.nodes[slots[j].build_node].leaf();
      unexpanded += !tree_.nodes[node.left].leaf() + !tree_.nodes[node.right].leaf();
      if (slots.size() + 2 + forwarded.size() + unexpanded <= kMaxBlockSlots) {
        slots[i].index = static_cast<std::uint32_t>(slots.size());
        const Box box = slots[i].box;
        for (const std::uint32_t child : {node.left, node.right}) {
          const std::uint32_t bits = quantize_child(box, tree_.nodes[child].bounds);
          slots.push_back({child, decode_child_box(box, bits), bits});
        }
      } else {
        slots[i].forwarded = true;
        forwarded.push_back(static_cast<std::uint32_t>(i));
      }
    }
    const auto node_slots = static_cast<std::uint32_t>(slots.size());
    const auto forward_slots = static_cast<std::uint32_t>(forwarded.size());
    if (node_slots + forward_slots > kMaxBlockSlots) throw std::logic_error("hmq: a block over 64 slots");
    for (std::uint32_t f = 0; f < forward_slots; ++f) slots[forwarded[f]].index = node_slots + f;

    // Leaf records, in slot order.
    LargeArray<std::byte> records;
    std::vector<std::uint32_t> record_offset;
    for (Slot& slot : slots) {
      const BuildNode& node = tree_.nodes[slot.build_node];
      if (!node.leaf()) continue;
      slot.index = static_cast<std::uint32_t>(record_offset.size());
      record_offset.push_back(static_cast<std::uint32_t>(records.size()));
      const std::size_t before = records.size();
      const std::size_t identity =
          encode_leaf(quantized_, std::span(tree_.primitive_order.data() + node.first, node.count),
                      snap_outward(grid_, slot.box), records) /
          8;  // its whole bytes
      parts_.other += identity;
      parts_.geometry += records.size() - before - identity;
    }
    if (record_offset.size() > 255) throw std::logic_error("hmq: more than 255 leaves in a block");

    const std::size_t table_end = kBlockHeaderBytes + 4 * (node_slots + forward_slots) + 2 * record_offset.size();
    const std::size_t size = (table_end + records.size() + 3) / 4 * 4;
    if (table_end + records.size() > 0xffff) throw std::logic_error("hmq: a block over 64 KiB");
    const std::size_t start = blocks_.size();
    blocks_.resize(start + size, std::byte{0});
    parts_.hierarchy += table_end + (size - table_end - records.size());
    std::byte* block = blocks_.data() + start;
    block[0] = static_cast<std::byte>(node_slots);
    block[1] = static_cast<std::byte>(forward_slots);
    block[2] = static_cast<std::byte>(record_offset.size());
    for (std::uint32_t s = 0; s < node_slots; ++s) {
      const Slot& slot = slots[s];
      const bool inner = !tree_.nodes[slot.build_node].leaf();
      const std::uint32_t word = slot.bits | slot.index << 24 | (inner ? kInnerBit : 0u);
      std::memcpy(block + kBlockHeaderBytes + 4 * s, &word, 4);
    }
    for (std::size_t l = 0; l < record_offset.size(); ++l) {
      const auto offset = static_cast<std::uint16_t>(table_end + record_offset[l]);
      std::memcpy(block + kBlockHeaderBytes + 4 * (node_slots + forward_slots) + 2 * l, &offset, 2);
    }
    if (!records.empty()) std::memcpy(block + table_end, records.data(), records.size());  // data() may be null

    // Child blocks after this one; their offsets patched into the forward slots.
    for (std::uint32_t f = 0; f < forward_slots; ++f) {
      const Slot slot = slots[forwarded[f]];
      const BuildNode& node = tree_.nodes[slot.build_node];
      const std::uint32_t child_block = encode({node.left, node.right}, slot.box);
      std::memcpy(blocks_.data() + start + kBlockHeaderBytes + 4 * (node_slots + f), &child_block, 4);
    }
    return checked_uint32(start / 4, "hmq block offset in 4-byte words; build in smaller chunks (build.chunk_triangles)");
  }

 private:
  const BuildTree& tree_;
  const QuantizedMesh& quantized_;
  const GlobalGrid& grid_;
  std::vector<std::byte>& blocks_;
  PartBytes& parts_;
};

// What an hmq world saves besides its arrays, `PREFIX` + "hmq.state" (88 bytes):
//   offset  size  field
//        0    12  grid origin, float x, y, z
//       12    12  grid cell size, float x, y, z
//       24    12  1 / cell size, float x, y, z (as the build computed it: decoding re-snaps with it)
//       36    12  grid bits, uint32 x, y, z
//       48     8  max vertex error, double
//       56     8  hierarchy bytes of the blocks (node slots, forward slots, leaf offsets, padding)
//       64     8  geometry bytes of the leaf records (vertices and connectivity)
//       72     8  other bytes of the leaf records (triangle ids and corners)
//       80     4  BVH nodes, uint32
//       84     4  BVH leaves, uint32
// and the triangle count and build report in the common sections (save_common_state).
// Arrays: "hmq.top" (BvhNode, bvh_node.hpp; a leaf's first is a block's word offset, its
// count 1 or 2 roots) and "hmq.blocks" (bytes, hmq_format.hpp, 8 bytes of read slack at the end).
struct HmqSavedState {
  GlobalGrid grid;
  std::uint64_t hierarchy_bytes, geometry_bytes, other_bytes;
  std::uint32_t nodes, leaves;
};
static_assert(sizeof(GlobalGrid) == 56 && sizeof(HmqSavedState) == 88);
constexpr std::uint32_t kHmqSavedVersion = 2;  // 2: leaf records as one bit string

class HmqAccelerator final : public ProbedAccelerator<HmqAccelerator> {
  friend class ProbedAccelerator<HmqAccelerator>;

 public:
  explicit HmqAccelerator(const SectionLoader& loader) {
    loader.expect_kind("hmq", kHmqSavedVersion);
    SectionLoader in = loader;
    archive(*this, in);
  }

  template <typename Archive>
  static void archive(auto& self, Archive& a) {
    HmqSavedState state{self.grid_, self.parts_.hierarchy, self.parts_.geometry, self.parts_.other,
                        static_cast<std::uint32_t>(self.nodes_), static_cast<std::uint32_t>(self.leaves_)};
    a.value("hmq.state", state);
    a.array("hmq.top", self.top_);
    a.array("hmq.blocks", self.blocks_);
    archive_common_state(a, self.triangles_, self.build_);
    if constexpr (Archive::kLoading) {
      self.grid_ = state.grid;
      self.parts_ = {state.hierarchy_bytes, state.geometry_bytes, state.other_bytes};
      self.nodes_ = state.nodes;
      self.leaves_ = state.leaves;
      if (self.top_.empty() || self.blocks_.size() < 8) a.fail("hmq.top", "is empty: no hmq structure was saved");
      const std::span<const BvhNode> top(self.top_.data(), self.top_.size());
      check_tree(top, a, "hmq.top", [&](const BvhNode& leaf) {
        if (leaf.triangle_count() != 1 && leaf.triangle_count() != 2) a.fail("hmq.top", "has a leaf of other than 1 or 2 roots");
      });
      check_blocks(top, std::span<const std::byte>(self.blocks_.data(), self.blocks_.size()), self.triangles_, a);
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    out.add_value(prefix + "kind", saved_kind("hmq", kHmqSavedVersion));
    SectionSaver saver(out, prefix);
    archive(*this, saver);
  }

  HmqAccelerator(const TriangleMesh& mesh, const HmqOptions& options) {
    const auto start = Clock::now();
    SnappedTree snapped = build_snapped_tree(mesh, options);
    build_.phases = snapped.phases;
    PhaseClock clock;
    grid_ = snapped.grid;
    const BuildTree& tree = snapped.tree;
    const QuantizedMesh& quantized = snapped.quantized;
    const std::size_t tree_peak = snapped.peak_bytes;

    // The uncompressed top: the first inner nodes in breadth-first order, as many as make the
    // top tree (those nodes and the leaves under them, one more) `top_fraction` of all nodes.
    const auto top_inner =
        static_cast<std::size_t>(std::llround(0.5 * options.top_fraction * double(tree.nodes.size())));
    std::vector<bool> in_top(tree.nodes.size(), false);
    std::deque<std::uint32_t> queue = {0};
    for (std::size_t taken = 0; !queue.empty() && taken < top_inner;) {
      const std::uint32_t node = queue.front();
      queue.pop_front();
      if (tree.nodes[node].leaf()) continue;
      in_top[node] = true;
      ++taken;
      queue.push_back(tree.nodes[node].left);
      queue.push_back(tree.nodes[node].right);
    }
    triangles_ = mesh.triangle_count();
    PartBytes parts;
    std::vector<std::byte> blocks;
    std::vector<BvhNode> top;
    BlockEncoder encoder(tree, quantized, grid_, blocks, parts);
    // Depth-first flattening of the top; a node outside it becomes a top leaf over a block.
    struct Pending {
      std::uint32_t build_node, parent_slot;
      bool is_right;
    };
    std::vector<Pending> stack = {{0, 0, false}};
    while (!stack.empty()) {
      const Pending pending = stack.back();
      stack.pop_back();
      const auto slot = static_cast<std::uint32_t>(top.size());
      if (pending.build_node != 0) {
        BvhNode& parent = top[pending.parent_slot];
        (pending.is_right ? parent.count : parent.first) = slot;
      }
      const BuildNode& node = tree.nodes[pending.build_node];
      top.push_back({node.bounds.lower, node.bounds.upper, 0, 0});
      if (in_top[pending.build_node]) {
        stack.push_back({node.right, slot, true});
        stack.push_back({node.left, slot, false});
        continue;
      }
      std::vector<std::uint32_t> roots = node.leaf() ? std::vector<std::uint32_t>{pending.build_node}
                                                     : std::vector<std::uint32_t>{node.left, node.right};
      const std::uint32_t block = encoder.encode(roots, box_of(node.bounds));
      top[slot].first = block;
      top[slot].count = BvhNode::kLeafFlag | static_cast<std::uint32_t>(roots.size());
    }
    clock.lap(build_.phases, "blocks");
    top_ = StoredArray<BvhNode>(LargeArray<BvhNode>(top.begin(), top.end()));
    blocks.resize(blocks.size() + 8, std::byte{0});  // read slack for unaligned 8-byte stream loads
    parts.hierarchy += 8;
    blocks_ = StoredArray<std::byte>(LargeArray<std::byte>(blocks.begin(), blocks.end()));
    parts_ = parts;
    leaves_ = 0;
    for (const BuildNode& node : tree.nodes) leaves_ += node.leaf();
    nodes_ = tree.nodes.size();
    build_.seconds = std::chrono::duration<double>(Clock::now() - start).count();
    build_.peak_bytes = std::max(tree_peak, blocks.capacity() + quantized.lines.size() * sizeof(glm::ivec3)) +
                        tree.nodes.size() * sizeof(BuildNode) + memory().total();
  }

  std::string name() const override { return "hmq"; }

  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = top_.size() * sizeof(BvhNode) + parts_.hierarchy;
    report.geometry = parts_.geometry;
    report.other = parts_.other;
    return report;
  }
  BuildReport build() const override { return build_; }

  std::string build_notes() const override {
    return fmt::format(
        "grid {}x{}x{} bits, cell {:.3g}, vertex error <= {:.3g}; {} nodes ({} top), {} leaves ({:.1f} triangles each); "
        "bytes/tri: nodes+blocks {:.2f}, vertices+connectivity {:.2f}, ids+corners {:.2f}",
        grid_.bits.x, grid_.bits.y, grid_.bits.z, std::max({grid_.cell.x, grid_.cell.y, grid_.cell.z}),
        grid_.max_vertex_error, nodes_, top_.size(), leaves_, double(triangles()) / double(leaves_),
        double(memory().hierarchy) / double(triangles()), double(parts_.geometry) / double(triangles()),
        double(parts_.other) / double(triangles()));
  }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    return {top_.bytes(), blocks_.bytes()};
  }

  std::optional<TriangleMesh> represented_mesh(const TriangleMesh& source) const override {
    return snapped_mesh(grid_, source);
  }
  glm::vec3 represented_point(const glm::vec3& point) const override { return grid_.point(grid_.snap(point)); }

 private:
  std::size_t triangles() const { return std::max<std::size_t>(1, triangles_); }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    DecodedLeafCache decoded;
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      float tmax = ray.tmax;
      LeafHit best;
      walk_bvh(top_.data(), ray.box, ray.tmin, tmax, probe, [&](const BvhNode& leaf) {
        traverse_blocks<kAnyHit>(leaf, ray.box, ray.sheared, ray.tmin, tmax, best, probe, decoded);
        return kAnyHit && best.found;
      });
      write_leaf_hit<!kAnyHit>(best, hits, i);
    });
  }

  // The compressed treelets under one top leaf: nodes decoded from their parents' boxes,
  // the nearer child visited next and the farther one stacked, as in walk_bvh.
  template <bool kAnyHit, typename Probe>
  void traverse_blocks(const BvhNode& top_leaf, const BoxRay& box_ray, const WatertightRay& sheared, float tmin,
                       float& tmax, LeafHit& best, Probe& probe, DecodedLeafCache& decoded) const {
    struct Node {
      const std::byte* block;
      std::uint32_t word;  // its slot
      float distance;      // where the ray enters its box
      Box box;             // decoded
    };
    Node stack[kMaxTreeDepth + 2];
    std::uint32_t top = 0;
    // The node pair at `slot` of `block` (one node when `count` is 1), children of `parent`:
    // the nearer hit one becomes `next`, the other is stacked; false when neither is hit.
    auto visit_pair = [&](const std::byte* block, std::uint32_t slot, std::uint32_t count, const Box& parent,
                          Node& next) {
      Node pair[2];
      std::uint32_t hit = 0;
      if (count == 2) {
        const std::uint32_t words[2] = {slot_word(block, slot, probe), slot_word(block, slot + 1, probe)};
        const ChildPair children =
            decode_and_intersect_children(parent, words[0], words[1], box_ray, tmin, pruning_distance(tmax));
        for (int k = 0; k < 2; ++k) {
          if (children.distance[k] != kInfinity) pair[hit++] = {block, words[k], children.distance[k], children.box[k]};
        }
      } else {  // a top leaf with one root
        const std::uint32_t word = slot_word(block, slot, probe);
        const Box box = decode_child_box(parent, word);
        const float distance = intersect_box(box_ray, box.lower, box.upper, tmin, pruning_distance(tmax));
        if (distance != kInfinity) pair[hit++] = {block, word, distance, box};
      }
      if (hit == 0) return false;
      if (hit == 2 && pair[1].distance < pair[0].distance) std::swap(pair[0], pair[1]);
      if (hit == 2) stack[top++] = pair[1];
      next = pair[0];
      return true;
    };
    Node current{};
    bool have = visit_pair(blocks_.data() + std::size_t(top_leaf.first) * 4, 0, top_leaf.triangle_count(),
                           Box{top_leaf.lower, top_leaf.upper}, current);
    while (true) {
      if (have) {
        if (!is_inner(current.word)) {
          test_leaf<kAnyHit>(current.block, node_index(current.word), current.box, sheared, tmin, tmax, best, probe,
                             decoded);
          if (kAnyHit && best.found) return;
          have = false;
        } else {
          const std::byte* child_block = current.block;
          std::uint32_t child_slot = node_index(current.word);
          if (child_slot >= static_cast<std::uint8_t>(current.block[0])) {  // a forward slot
            std::uint32_t forward;
            probe.read(current.block + kBlockHeaderBytes + 4 * child_slot, 4);
            std::memcpy(&forward, current.block + kBlockHeaderBytes + 4 * child_slot, 4);
            child_block = blocks_.data() + std::size_t(forward) * 4;
            child_slot = 0;
          }
          const Box box = current.box;
          have = visit_pair(child_block, child_slot, 2, box, current);
        }
        if (have) continue;
      }
      while (top > 0 && stack[top - 1].distance > pruning_distance(tmax)) --top;
      if (top == 0) return;
      current = stack[--top];
      have = true;
    }
  }

  template <typename Probe>
  static std::uint32_t slot_word(const std::byte* block, std::uint32_t slot, Probe& probe) {
    std::uint32_t word;
    probe.read(block + kBlockHeaderBytes + 4 * slot, 4);
    std::memcpy(&word, block + kBlockHeaderBytes + 4 * slot, 4);
    return word;
  }

  template <bool kAnyHit, typename Probe>
  void test_leaf(const std::byte* block, std::uint32_t leaf, const Box& box, const WatertightRay& sheared, float tmin,
                 float& tmax, LeafHit& best, Probe& probe, DecodedLeafCache& decoded) const {
    const std::uint32_t node_slots = static_cast<std::uint8_t>(block[0]);
    const std::uint32_t forward_slots = static_cast<std::uint8_t>(block[1]);
    std::uint16_t offset;
    const std::byte* offset_at = block + kBlockHeaderBytes + 4 * (node_slots + forward_slots) + 2 * leaf;
    probe.read(offset_at, 2);
    std::memcpy(&offset, offset_at, 2);
    test_leaf_record<kAnyHit>(block + offset, grid_, box, sheared, tmin, tmax, best, probe, decoded);
  }

  GlobalGrid grid_;
  StoredArray<BvhNode> top_;
  StoredArray<std::byte> blocks_;
  PartBytes parts_;
  std::size_t nodes_ = 0, leaves_ = 0, triangles_ = 0;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_hmq_accelerator(const TriangleMesh& mesh, const HmqOptions& options) {
  if (options.width == 8) return make_wide_hmq_accelerator(mesh, options);
  return std::make_unique<HmqAccelerator>(mesh, options);
}

std::unique_ptr<Accelerator> load_hmq_accelerator(const SectionLoader& loader) {
  return std::make_unique<HmqAccelerator>(loader);
}

}  // namespace wavetrace
