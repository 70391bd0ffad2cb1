// The quantized 8-wide tree: the binary tree cut into wide nodes (collapse_plan.hpp) and the
// outward-rounded quantization of every child box against its frame.
#include "wavetrace/accel/bvh/quantized_wide_tree.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <deque>
#include <limits>
#include <stdexcept>
#include <vector>

#include "wavetrace/accel/bvh/collapse_plan.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"

namespace wavetrace {
namespace {

constexpr int kWidth = QuantizedWideNode::kWidth;

// q for one plane: the largest step count whose decoded plane stays at or below the
// child's lower bound (lower) or at or above its upper bound (upper).
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

class Encoder {
 public:
  Encoder(const BuildTree& tree, const EncodeWideLeaf& encode_leaf, QuantizedWideTree& out)
      : tree_(tree), plan_(tree), encode_leaf_(encode_leaf), out_(out) {}

  // Fills node `index` with the children of binary node `root`, allocates its inner children
  // next to each other, and fills them depth first.
  void encode(std::uint32_t root, std::uint32_t index, const Bounds3& frame) {
    const std::vector<std::uint32_t> children = plan_.children(tree_, root);
    out_.children += children.size();
    QuantizedWideNode node{};
    Bounds3 child_box[kWidth];
    for (int slot = 0; slot < int(children.size()); ++slot) {
      const Bounds3& bounds = tree_.nodes[children[slot]].bounds;
      for (int axis = 0; axis < 3; ++axis) {
        const float step = frame_step(frame, axis);
        node.lower(axis)[slot] = quantize_lower(frame.lower[axis], step, bounds.lower[axis]);
        node.upper(axis)[slot] = quantize_upper(frame.upper[axis], step, bounds.upper[axis]);
      }
      child_box[slot] = decode_wide_child(node, slot, frame);
    }
    node.leaf_base = static_cast<std::uint32_t>(weights_);
    std::uint32_t inner_count = 0;
    for (int slot = 0; slot < int(children.size()); ++slot) {
      const BuildNode& child = tree_.nodes[children[slot]];
      if (!child.leaf()) {
        node.meta[slot] = QuantizedWideNode::kInnerMeta;
        ++inner_count;
        continue;
      }
      const std::uint32_t weight = encode_leaf_(child, child_box[slot]);
      if (weight < 1 || weight > QuantizedWideNode::kMaxLeafWeight) {
        throw std::logic_error("quantized wide tree: a leaf weight outside 1 .. 254");
      }
      node.meta[slot] = static_cast<std::uint8_t>(weight);
      weights_ += weight;
    }
    if (weights_ >= (std::uint64_t{1} << 31)) {
      throw std::length_error("quantized wide tree: the leaf references pass 2^31; build in smaller chunks (build.chunk_triangles)");
    }
    node.child_base = checked_uint32(out_.nodes.size(), "quantized wide nodes");
    out_.nodes.resize(out_.nodes.size() + inner_count);
    out_.nodes[index] = node;
    std::uint32_t next = node.child_base;
    for (int slot = 0; slot < int(children.size()); ++slot) {
      if (node.meta[slot] == QuantizedWideNode::kInnerMeta) encode(children[slot], next++, child_box[slot]);
    }
  }

 private:
  const BuildTree& tree_;
  const CollapsePlan plan_;
  const EncodeWideLeaf& encode_leaf_;
  QuantizedWideTree& out_;
  std::uint64_t weights_ = 0;
};

// A node's inner children, nodes first .. first + count - 1: the unit every layout moves.
struct SiblingGroup {
  std::uint32_t first, count;
};

std::uint32_t inner_children(const QuantizedWideNode& node) {
  std::uint32_t count = 0;
  for (const std::uint8_t meta : node.meta) count += meta == QuantizedWideNode::kInnerMeta;
  return count;
}

class GroupOrder {
 public:
  explicit GroupOrder(const LargeArray<QuantizedWideNode>& nodes) : nodes_(nodes), height_(nodes.size(), 1) {
    // Children come after their parent in the encoder's order: one pass backwards gives heights.
    for (std::size_t n = nodes.size(); n-- > 0;) {
      for (std::uint32_t c = 0, inner = inner_children(nodes[n]); c < inner; ++c) {
        height_[n] = std::max(height_[n], height_[nodes[n].child_base + c] + 1);
      }
    }
    order_.reserve(nodes.size());
  }

  std::vector<std::uint32_t> breadth_first() {
    std::deque<SiblingGroup> queue = {{0, 1}};
    while (!queue.empty()) {
      const SiblingGroup group = queue.front();
      queue.pop_front();
      emit(group, [&](SiblingGroup child) { queue.push_back(child); });
    }
    return std::move(order_);
  }

  std::vector<std::uint32_t> van_emde_boas() {
    std::vector<SiblingGroup> below;
    van_emde_boas({0, 1}, height_[0], below);
    return std::move(order_);
  }

 private:
  template <typename Child>
  void emit(SiblingGroup group, Child&& child) {
    for (std::uint32_t n = group.first; n < group.first + group.count; ++n) {
      order_.push_back(n);
      if (const std::uint32_t inner = inner_children(nodes_[n]); inner != 0) child({nodes_[n].child_base, inner});
    }
  }

  // Lays out the `levels` top levels of the subtree at `group`; the groups just below them go
  // to `frontier` for the caller to lay out next. Recursion depth is O(log levels).
  void van_emde_boas(SiblingGroup group, std::uint32_t levels, std::vector<SiblingGroup>& frontier) {
    if (levels == 1) return emit(group, [&](SiblingGroup child) { frontier.push_back(child); });
    const std::uint32_t top = levels / 2;
    std::vector<SiblingGroup> middle;
    van_emde_boas(group, top, middle);
    for (const SiblingGroup subtree : middle) van_emde_boas(subtree, levels - top, frontier);
  }

  const LargeArray<QuantizedWideNode>& nodes_;
  std::vector<std::uint32_t> height_;
  std::vector<std::uint32_t> order_;
};

}  // namespace

void reorder_wide_nodes(LargeArray<QuantizedWideNode>& nodes, NodeLayout layout) {
  if (layout == NodeLayout::depth_first || nodes.empty()) return;
  GroupOrder groups(nodes);
  const std::vector<std::uint32_t> order =
      layout == NodeLayout::breadth_first ? groups.breadth_first() : groups.van_emde_boas();
  if (order.size() != nodes.size()) throw std::logic_error("reorder_wide_nodes: a node is not reached from the root");
  std::vector<std::uint32_t> position_of(nodes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) position_of[order[i]] = i;
  LargeArray<QuantizedWideNode> reordered(nodes.size());
  for (std::uint32_t i = 0; i < order.size(); ++i) {
    reordered[i] = nodes[order[i]];
    if (inner_children(reordered[i]) != 0) reordered[i].child_base = position_of[reordered[i].child_base];
  }
  nodes = std::move(reordered);
}

InterleavedWideTree interleave_leaf_records(std::span<const QuantizedWideNode> nodes, std::span<const std::byte> records,
                                            std::size_t unit_bytes, std::size_t slack_bytes) {
  constexpr std::size_t kUnitBytes = sizeof(QuantizedWideNode);
  std::vector<bool> group_start(nodes.size() + 1, false);
  group_start[0] = group_start[nodes.size()] = true;
  for (const QuantizedWideNode& node : nodes) {
    if (inner_children(node) != 0) group_start[node.child_base] = true;
  }
  const auto leaf_weight = [](const QuantizedWideNode& node) {
    std::size_t weight = 0;
    for (const std::uint8_t meta : node.meta) weight += meta != QuantizedWideNode::kInnerMeta ? meta : 0;
    return weight;
  };
  // Where each node and each node's records go, then the bytes.
  std::vector<std::uint32_t> unit_of(nodes.size());
  std::vector<std::size_t> records_at(nodes.size());
  std::size_t cursor = 0, used = 0;
  for (std::size_t first = 0; first < nodes.size();) {
    std::size_t end = first + 1;
    while (!group_start[end]) ++end;
    cursor = (cursor + kUnitBytes - 1) / kUnitBytes * kUnitBytes;
    for (std::size_t n = first; n < end; ++n, cursor += kUnitBytes) unit_of[n] = checked_uint32(cursor / kUnitBytes, "interleaved wide tree units");
    for (std::size_t n = first; n < end; ++n) {
      records_at[n] = cursor;
      cursor += leaf_weight(nodes[n]) * unit_bytes;
    }
    used += (end - first) * kUnitBytes;
    first = end;
  }
  if (cursor / unit_bytes >= (std::uint64_t{1} << 31)) {
    throw std::length_error("interleaved wide tree: the leaf references pass 2^31; build in smaller chunks (build.chunk_triangles)");
  }
  InterleavedWideTree out;
  out.units.resize((cursor + slack_bytes + kUnitBytes - 1) / kUnitBytes);
  std::byte* bytes = reinterpret_cast<std::byte*>(out.units.data());
  std::memset(bytes, 0, out.units.size() * kUnitBytes);
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    QuantizedWideNode node = nodes[n];
    const std::size_t record_bytes = leaf_weight(node) * unit_bytes;
    if (record_bytes != 0) std::memcpy(bytes + records_at[n], records.data() + std::size_t(node.leaf_base) * unit_bytes, record_bytes);
    used += record_bytes;
    node.leaf_base = static_cast<std::uint32_t>(records_at[n] / unit_bytes);
    if (inner_children(node) != 0) node.child_base = unit_of[node.child_base];
    std::memcpy(bytes + std::size_t(unit_of[n]) * kUnitBytes, &node, kUnitBytes);
  }
  out.padding_bytes = out.units.size() * kUnitBytes - used;
  return out;
}

QuantizedWideTree build_quantized_wide_tree(const BuildTree& tree, const EncodeWideLeaf& encode_leaf,
                                            NodeLayout layout) {
  QuantizedWideTree out;
  out.root_frame = tree.nodes[0].bounds;
  out.nodes.resize(1);
  Encoder(tree, encode_leaf, out).encode(0, 0, out.root_frame);
  reorder_wide_nodes(out.nodes, layout);
  return out;
}

}  // namespace wavetrace
