// Binned SAH builder (parallel, TBB): a binary tree over primitive bounding boxes. It is
// a component: the BVH baseline flattens its tree into 32-byte nodes, and the compact
// accelerators build their top levels with it.
#pragma once

#include <cstdint>
#include <cstdlib>
#include <memory>
#include <span>
#include <vector>

#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// No tree is deeper than this (64 free SAH levels, then halving: 64 + 32 for 2^32 primitives).
inline constexpr std::uint32_t kMaxTreeDepth = 96;

struct SahOptions {
  std::uint32_t max_leaf_size = 4;  // 1..16; a node above this is always split
  std::uint32_t bins = 16;          // candidate split planes per axis, minus one
  float traversal_cost = 1.0f;      // cost of visiting a node, relative to ...
  float intersection_cost = 1.0f;   // ... testing one primitive (one block of them)
  // Primitives a leaf tests in one SIMD pass: leaf and split costs count ceil(n / block_size)
  // tests, as Embree's builders do for their triangle4 leaves, so a leaf of three costs what
  // one of four does and the SAH fills blocks instead of making leaves of one or two.
  std::uint32_t block_size = 1;
  // > 0: a range of at most this many primitives is made a leaf without being split, whatever
  // max_leaf_size says: for a caller that only cuts the tree into pieces of this size (the
  // sub-meshes of Ray-Strips), the levels below them were half its build.
  std::uint32_t cut_size = 0;
};

// A node of the built tree. Inner nodes have two children; leaves own the primitive
// range [first, first + count) of BuildTree::primitive_order.
struct BuildNode {
  Bounds3 bounds;
  std::uint32_t left = 0, right = 0;  // inner
  std::uint32_t first = 0, count = 0;  // leaf: count > 0
  bool leaf() const { return count > 0; }
};

// The builder's node slots, handed to the tree as they are: a build reserves the worst case,
// 2n - 1 nodes, as raw memory and writes about a quarter of them, so the pages past `size()`
// are never touched (never resident). Copying the nodes made into an array of their own had
// both copies resident at once, at the top of an hmq chunk's build (measurements.md,
// "A build's peak").
class BuildNodes {
 public:
  BuildNodes() = default;
  BuildNodes(BuildNode* slots, std::size_t size) : slots_(slots), size_(size) {}
  std::size_t size() const { return size_; }
  bool empty() const { return size_ == 0; }
  const BuildNode& operator[](std::size_t i) const { return slots_[i]; }
  BuildNode& operator[](std::size_t i) { return slots_[i]; }
  const BuildNode* begin() const { return slots_.get(); }
  const BuildNode* end() const { return slots_.get() + size_; }

 private:
  struct Free {
    void operator()(BuildNode* slots) const { std::free(slots); }
  };
  std::unique_ptr<BuildNode[], Free> slots_;
  std::size_t size_ = 0;
};

struct BuildTree {
  BuildNodes nodes;                            // root at index 0
  LargeArray<std::uint32_t> primitive_order;   // input primitive ids in leaf order
  std::size_t peak_bytes = 0;                  // the builder's own working memory at its peak
  std::uint32_t depth() const;                 // levels from the root to the deepest leaf, root = 1
};

// A primitive as the builder moves it: its box and its id, 32 bytes, partitioned in place so
// that binning streams through memory instead of gathering through an index.
//   offset  size  field
//        0    24  box: float lower x, y, z, upper x, y, z
//       24     4  id: the primitive's index in the input, uint32
//       28     4  unused (zero)
struct SahReference {
  Bounds3 bounds;
  std::uint32_t id;
  std::uint32_t unused;
};
static_assert(sizeof(SahReference) == 32);

// Throws std::invalid_argument for an empty input or max_leaf_size outside 1..16.
BuildTree build_sah_tree(std::span<const Bounds3> primitive_bounds, const SahOptions& options);
// The same build over references the caller filled (reference i: primitive i's box, id i):
// no array of boxes is held beside the builder's own (24 bytes a primitive less, and pages a
// build need not touch).
BuildTree build_sah_tree(LargeArray<SahReference> references, const SahOptions& options);

}  // namespace wavetrace
