// The walk of check_blocks: the traversal's own steps, without a ray.
#include "wavetrace/accel/hmq/block_check.hpp"

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>

#include <fmt/format.h>

#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/accel/hmq/leaf_codec.hpp"
#include "wavetrace/accel/hmq/packed_stream.hpp"
#include "wavetrace/accel/hmq/strip_table.hpp"

namespace wavetrace::hmq {
namespace {

constexpr std::string_view kSection = "hmq.blocks";

// What is wrong with the leaf record at byte `record` of `bytes`, if anything.
std::optional<std::string> leaf_record_problem(std::span<const std::byte> bytes, std::uint64_t record,
                                               std::size_t triangles) {
  if (record + (kLeafHeaderBits + 7) / 8 > bytes.size()) return "has a leaf record past its array";
  // The header's loads read past a short record: from a zero-padded copy, not the array's end.
  std::byte head[kLeafHeaderReadBytes] = {};
  std::memcpy(head, bytes.data() + record, std::min<std::size_t>(sizeof head, bytes.size() - record));
  const LeafHeader header = read_leaf_header(head);
  const StripTable& strips = StripTable::instance();
  if (header.entry >= strips.size()) return fmt::format("has a leaf of strip table entry {}", header.entry);
  const StripLayoutEntry& layout = strips.entry(header.entry);
  // A walk's 8-byte loads of the record's last values reach up to 7 bytes past it, into the
  // slack every array of records keeps.
  if (record + leaf_record_bytes(header, layout) + 7 > bytes.size()) return "has a leaf record running past its array";
  const std::byte* data = bytes.data() + record;
  std::size_t bit = header.stream_bit;
  for (int axis = 0; axis < 3; ++axis) bit += stream_bits(header.axis_bits[axis] + 1, header.vertex_count);
  std::uint32_t values[64];
  if (header.indexed) {
    if (header.vertex_count == 0) return "has an indexed leaf of no vertices";
    read_stream(data, bit, header.index_bits, layout.slots, values);
    for (std::uint32_t s = 0; s < layout.slots; ++s) {
      if (values[s] >= header.vertex_count) return "has a leaf slot naming a vertex it does not hold";
    }
    bit += stream_bits(header.index_bits, layout.slots);
  } else if (header.vertex_count < layout.slots) {
    return fmt::format("has a leaf of {} vertices for {} strip slots", header.vertex_count, layout.slots);
  }
  read_stream(data, bit, header.id_bits, layout.triangles, values);
  for (std::uint32_t k = 0; k < layout.triangles; ++k) {
    if (std::uint64_t(header.id_base) + values[k] >= triangles) return "has a leaf naming a triangle that does not exist";
  }
  bit += stream_bits(header.id_bits, layout.triangles);
  // Corner codes 3 c1 + c2 name the mesh triangle's second and third corner: two different ones.
  read_stream(data, bit, 3, layout.triangles, values);
  for (std::uint32_t k = 0; k < layout.triangles; ++k) {
    if (values[k] / 3 == values[k] % 3) return "has a leaf triangle whose corners repeat";
  }
  return std::nullopt;
}

// Follows every node once, as a walk from the top leaves would: in a tree each node is
// reached once, so more visits than the blocks have slots means nodes are shared (a crafted
// file) and is refused, which also bounds the work. No table of visited nodes is kept: the
// walk costs one visit of every node and one decode of every leaf record.
class BlockChecker {
 public:
  BlockChecker(std::span<const std::byte> blocks, std::size_t triangles, const SectionLoader& in)
      : blocks_(blocks), triangles_(triangles), in_(in), visits_left_(blocks.size() / 4) {}

  // The treelet of a top leaf: its block's first `roots` slots.
  void check_treelet(std::uint64_t block_word, std::uint32_t roots) {
    const Block block = check_block(block_word);
    if (roots > block.node_slots) fail(block_word, fmt::format("has {} node slots under a top leaf of {} roots", block.node_slots, roots));
    for (std::uint32_t slot = 0; slot < roots; ++slot) check_node(block_word, block, slot, 0);
  }

 private:
  struct Block {
    std::uint32_t node_slots, forward_slots, leaves;
  };

  [[noreturn]] void fail(std::uint64_t block_word, const std::string& problem) const {
    in_.fail(kSection, fmt::format("block at word {}: {}", block_word, problem));
  }

  std::uint32_t word_at(std::uint64_t byte) const {
    std::uint32_t word;
    std::memcpy(&word, blocks_.data() + byte, 4);
    return word;
  }

  Block check_block(std::uint64_t block_word) const {
    const std::uint64_t start = block_word * 4;
    if (start + kBlockHeaderBytes > blocks_.size()) fail(block_word, "lies past the blocks");
    const Block block{static_cast<std::uint8_t>(blocks_[start]), static_cast<std::uint8_t>(blocks_[start + 1]),
                      static_cast<std::uint8_t>(blocks_[start + 2])};
    if (block.node_slots == 0 || block.node_slots + block.forward_slots > kMaxBlockSlots) {
      fail(block_word, fmt::format("has {} node and {} forward slots", block.node_slots, block.forward_slots));
    }
    const std::uint64_t tables =
        kBlockHeaderBytes + 4 * std::uint64_t(block.node_slots + block.forward_slots) + 2 * std::uint64_t(block.leaves);
    if (start + tables > blocks_.size()) fail(block_word, "has slots or leaf offsets past the blocks");
    return block;
  }

  // A node `depth` levels below its treelet's roots.
  void check_node(std::uint64_t block_word, const Block& block, std::uint32_t slot, std::uint32_t depth) {
    if (depth >= kMaxTreeDepth) fail(block_word, fmt::format("holds a treelet deeper than {} levels", kMaxTreeDepth));
    if (visits_left_-- == 0) fail(block_word, "shares nodes between treelets (more nodes reached than it holds)");
    if (slot >= block.node_slots) fail(block_word, fmt::format("names node slot {} of its {}", slot, block.node_slots));
    const std::uint64_t start = block_word * 4;
    const std::uint32_t word = word_at(start + kBlockHeaderBytes + 4 * slot);
    const std::uint32_t index = node_index(word);
    if (!is_inner(word)) {
      if (index >= block.leaves) fail(block_word, fmt::format("slot {} names leaf {} of its {}", slot, index, block.leaves));
      std::uint16_t offset;
      std::memcpy(&offset,
                  blocks_.data() + start + kBlockHeaderBytes + 4 * (block.node_slots + block.forward_slots) + 2 * index, 2);
      if (const std::optional<std::string> problem = leaf_record_problem(blocks_, start + offset, triangles_)) {
        fail(block_word, *problem);
      }
      return;
    }
    if (index < block.node_slots) {
      if (index <= slot || index + 1 >= block.node_slots) {
        fail(block_word, fmt::format("slot {} names children at slot {}, not later slots of the block", slot, index));
      }
      check_node(block_word, block, index, depth + 1);
      check_node(block_word, block, index + 1, depth + 1);
      return;
    }
    if (index - block.node_slots >= block.forward_slots) {
      fail(block_word, fmt::format("slot {} names forward slot {} of its {}", slot, index - block.node_slots, block.forward_slots));
    }
    const std::uint32_t forward = word_at(start + kBlockHeaderBytes + 4 * std::uint64_t(index));
    if (forward <= block_word) fail(block_word, fmt::format("forwards to block word {}, not a later block", forward));
    const Block child = check_block(forward);
    if (child.node_slots < 2) fail(forward, "holds fewer than the two children forwarded to it");
    check_node(forward, child, 0, depth + 1);
    check_node(forward, child, 1, depth + 1);
  }

  std::span<const std::byte> blocks_;
  std::size_t triangles_;
  const SectionLoader& in_;
  std::size_t visits_left_;
};

}  // namespace

void check_leaf_record(std::span<const std::byte> records, std::uint64_t offset, std::size_t triangles,
                       const SectionLoader& in, std::string_view section) {
  if (const std::optional<std::string> problem = leaf_record_problem(records, offset, triangles)) {
    in.fail(section, fmt::format("leaf at byte {}: {}", offset, *problem));
  }
}

void check_blocks(std::span<const BvhNode> top, std::span<const std::byte> blocks, std::size_t triangles,
                  const SectionLoader& in) {
  BlockChecker checker(blocks, triangles, in);
  for (const BvhNode& node : top) {
    if (node.leaf()) checker.check_treelet(node.first, node.triangle_count());
  }
}

}  // namespace wavetrace::hmq
