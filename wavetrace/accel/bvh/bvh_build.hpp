// The build steps the binary and the 8-wide BVH share: the SAH tree over an indexed face
// set, the optional switch to leaf triangle order, and the peak-memory account.
#pragma once

#include <algorithm>
#include <cstdint>
#include <span>
#include <type_traits>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_options.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"
#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/section_archive.hpp"

namespace wavetrace {

// The SAH tree over the face set's triangles; its peak_bytes include the bounds array.
inline BuildTree build_bvh_tree(const IndexedFaceSet& geometry, const BvhOptions& options) {
  const LargeArray<Bounds3> bounds = geometry.triangle_bounds();
  SahOptions sah;
  sah.max_leaf_size = options.max_leaf_size;
  sah.bins = options.bins;
  BuildTree tree = build_sah_tree(bounds, sah);
  tree.peak_bytes += bounds.size() * sizeof(Bounds3);
  return tree;
}

// With leaf order, re-stores the face set as the leaves list it and drops the leaf index.
inline void adopt_leaf_order(const BvhOptions& options, IndexedFaceSet& geometry, LargeArray<std::uint32_t>& leaf_index) {
  if (options.triangle_order != TriangleOrder::leaf) return;
  geometry.adopt_order(leaf_index);  // slots now equal leaf positions
  leaf_index = {};
}

// What a saved bvh or bvh8 keeps besides its arrays: its indexed face set (faces.*,
// indexed_face_set.hpp), and "common" (section_archive.hpp). Arrays: "bvh.nodes" (BvhNode,
// bvh_node.hpp) or "bvh8.nodes" (WideBvhNode, wide_bvh_node.hpp), and "bvh.leaf_triangles"
// (uint32 per leaf slot: a face-set slot; empty in leaf order, where slot = leaf position).
inline constexpr std::uint32_t kBvhSavedVersion = 1;

template <typename Node>
void save_bvh(SectionWriter& out, const std::string& prefix, const IndexedFaceSet& geometry, std::string_view nodes_section,
              const StoredArray<Node>& nodes, const StoredArray<std::uint32_t>& leaf_triangles, const BuildReport& build) {
  out.add_value(prefix + "kind", saved_kind("bvh", kBvhSavedVersion));
  SectionSaver saver(out, prefix);
  geometry.save(saver);
  saver.array(nodes_section, nodes);
  saver.array("bvh.leaf_triangles", leaf_triangles);
  std::size_t triangles = geometry.triangle_count();
  BuildReport report = build;
  archive_common_state(saver, triangles, report);
}

// The face set is loaded by the accelerator's constructor (a member); this reads the rest
// and checks every index a walk follows (tree_check.hpp).
template <typename Node>
void load_bvh(SectionLoader& in, const IndexedFaceSet& geometry, std::string_view nodes_section,
              StoredArray<Node>& nodes, StoredArray<std::uint32_t>& leaf_triangles, BuildReport& build) {
  in.expect_kind("bvh", kBvhSavedVersion);
  in.array(nodes_section, nodes);
  in.array("bvh.leaf_triangles", leaf_triangles);
  std::size_t triangles = 0;
  archive_common_state(in, triangles, build);
  if (nodes.empty()) in.fail(nodes_section, "is empty: no bvh was saved");
  for (const std::uint32_t triangle : leaf_triangles) {
    if (triangle >= geometry.triangle_count()) in.fail("bvh.leaf_triangles", "names a triangle that does not exist");
  }
  // Without leaf_triangles (triangle_order = leaf) a leaf's slots are the triangles themselves.
  const std::size_t slots = leaf_triangles.empty() ? geometry.triangle_count() : leaf_triangles.size();
  const auto check_slots = [&](std::uint64_t first, std::uint64_t count) {
    check_leaf_slots(first, count, slots, in, nodes_section);
  };
  if constexpr (std::is_same_v<Node, BvhNode>) {
    check_tree(std::span<const BvhNode>(nodes.data(), nodes.size()), in, nodes_section,
               [&](const BvhNode& leaf) { check_slots(leaf.first, leaf.triangle_count()); });
  } else {
    check_tree(std::span<const Node>(nodes.data(), nodes.size()), in, nodes_section, check_slots);
  }
}

// Peak build memory: the larger of the tree build's and the face-set copy's working sets,
// held while the finished structure (`result_bytes`) already exists.
inline std::size_t bvh_build_peak_bytes(const BuildTree& tree, const IndexedFaceSet& geometry, std::size_t result_bytes) {
  return std::max(tree.peak_bytes, geometry.build_scratch_bytes()) + result_bytes;
}

}  // namespace wavetrace
