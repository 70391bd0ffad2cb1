// The build steps the binary and the 8-wide BVH share: the SAH tree over an indexed face
// set, the optional switch to leaf triangle order, and the peak-memory account.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <utility>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_options.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/bvh/triangle_block.hpp"
#include "wavetrace/accel/bvh/wide_bvh_node.hpp"
#include "wavetrace/accel/section_archive.hpp"

namespace wavetrace {

// The SAH tree over the face set's triangles; its peak_bytes include the references. Adds
// the phases "bounds" and "sah".
inline BuildTree build_bvh_tree(const IndexedFaceSet& geometry, const BvhOptions& options, BuildPhases& phases) {
  PhaseClock clock;
  LargeArray<SahReference> references = geometry.triangle_references();
  clock.lap(phases, "bounds");
  SahOptions sah;
  sah.max_leaf_size = options.leaf_triangles();
  sah.bins = options.bins;
  // The 8-wide tree's leaves are blocks of four (triangle_block.hpp).
  sah.block_size = options.width == 8 ? TriangleBlock::kLanes : 1;
  BuildTree tree = build_sah_tree(std::move(references), sah);
  clock.lap(phases, "sah");
  return tree;
}

// A BVH build's first phases: `clock` started before the face set (a member of the
// accelerator) was made, so its copy is "face_set"; then build_bvh_tree's.
inline BuildTree build_bvh_tree_timed(const IndexedFaceSet& geometry, const BvhOptions& options, PhaseClock& clock,
                                      BuildReport& build) {
  build.phases.add("face_set", clock.lap());
  BuildTree tree = build_bvh_tree(geometry, options, build.phases);
  clock.lap();
  return tree;
}

// With leaf order, re-stores the face set as the leaves list it and drops the leaf index.
inline void adopt_leaf_order(const BvhOptions& options, IndexedFaceSet& geometry, LargeArray<std::uint32_t>& leaf_index) {
  if (options.triangle_order != TriangleOrder::leaf) return;
  geometry.adopt_order(leaf_index);  // slots now equal leaf positions
  leaf_index = {};
}

// What a saved bvh or bvh8 keeps besides its arrays: its indexed face set (faces.*,
// indexed_face_set.hpp), and "common" (section_archive.hpp). The binary tree (kind "bvh",
// version 1): "bvh.nodes" (BvhNode, bvh_node.hpp) and "bvh.leaf_triangles" (uint32 per leaf
// slot: a face-set slot; empty in leaf order, where slot = leaf position). The 8-wide tree
// (kind "bvh", version 2, told apart by its "bvh8.nodes"): "bvh8.nodes" (WideBvhNode,
// wide_bvh_node.hpp; a leaf lane names its first triangle block) and "bvh8.triangle_blocks"
// (TriangleBlock, triangle_block.hpp). Version 1 of the 8-wide tree kept leaf slots as the
// binary tree does; such a world is refused with the advice to rebuild it.
template <typename Node>
inline constexpr std::uint32_t kBvhSavedVersion = 1;
template <>
inline constexpr std::uint32_t kBvhSavedVersion<WideBvhNode> = 2;

template <typename Node, typename Leaf>
void save_bvh(SectionWriter& out, const std::string& prefix, const IndexedFaceSet& geometry, std::string_view nodes_section,
              const StoredArray<Node>& nodes, std::string_view leaves_section, const StoredArray<Leaf>& leaves,
              const BuildReport& build) {
  out.add_value(prefix + "kind", saved_kind("bvh", kBvhSavedVersion<Node>));
  SectionSaver saver(out, prefix);
  geometry.save(saver);
  saver.array(nodes_section, nodes);
  saver.array(leaves_section, leaves);
  std::size_t triangles = geometry.triangle_count();
  BuildReport report = build;
  archive_common_state(saver, triangles, report);
}

// The face set is loaded by the accelerator's constructor (a member); this reads the rest
// and checks the tree (tree_check.hpp), each leaf by `check_leaf` (a BvhNode for the binary
// tree, (first, count) for the 8-wide one). The caller checks the leaf array's own contents.
template <typename Node, typename Leaf, typename CheckLeaf>
void load_bvh(SectionLoader& in, std::string_view nodes_section, StoredArray<Node>& nodes, std::string_view leaves_section,
              StoredArray<Leaf>& leaves, BuildReport& build, CheckLeaf&& check_leaf) {
  in.expect_kind("bvh", kBvhSavedVersion<Node>);
  in.array(nodes_section, nodes);
  in.array(leaves_section, leaves);
  std::size_t triangles = 0;
  archive_common_state(in, triangles, build);
  if (nodes.empty()) in.fail(nodes_section, "is empty: no bvh was saved");
  check_tree(std::span<const Node>(nodes.data(), nodes.size()), in, nodes_section, check_leaf);
}

// Peak build memory: the larger of the tree build's and the face-set copy's working sets,
// held while the finished structure (`result_bytes`) already exists.
inline std::size_t bvh_build_peak_bytes(const BuildTree& tree, const IndexedFaceSet& geometry, std::size_t result_bytes) {
  return std::max(tree.peak_bytes, geometry.build_scratch_bytes()) + result_bytes;
}

}  // namespace wavetrace
