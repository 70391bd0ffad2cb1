// The build steps the binary and the 8-wide BVH share: the SAH tree over an indexed face
// set, the optional switch to leaf triangle order, and the peak-memory account.
#pragma once

#include <algorithm>
#include <cstdint>

#include "accel/bvh/bvh_accelerator.hpp"
#include "accel/bvh/indexed_face_set.hpp"
#include "accel/bvh/sah_builder.hpp"

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

// Peak build memory: the larger of the tree build's and the face-set copy's working sets,
// held while the finished structure (`result_bytes`) already exists.
inline std::size_t bvh_build_peak_bytes(const BuildTree& tree, const IndexedFaceSet& geometry, std::size_t result_bytes) {
  return std::max(tree.peak_bytes, geometry.build_scratch_bytes()) + result_bytes;
}

}  // namespace wavetrace
