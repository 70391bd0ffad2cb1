// `bvh`: the papers' uncompressed baseline, a binned-SAH binary BVH of 32-byte nodes over
// an indexed face set (32-bit indices, float vertices), with watertight triangle tests.
#pragma once

#include <memory>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/indexed_face_set.hpp"
#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct BvhOptions {
  std::uint32_t max_leaf_size = 4;  // 1..16
  NodeLayout layout = NodeLayout::depth_first;
  // input: leaves index the mesh's own triangles; morton: the BVH keeps a copy of the
  // indexed face set with triangles sorted along a Morton curve and vertices renumbered in
  // first-use order, so a leaf's triangles and vertices sit close together in memory.
  TriangleOrder triangle_order = TriangleOrder::input;
  std::uint32_t bins = 16;
  // 2: the papers' baseline of 32-byte binary nodes. 8: the same tree collapsed into
  // 256-byte 8-wide nodes tested with AVX2 (wide_bvh_node.hpp); node layout is then depth-first.
  std::uint32_t width = 2;
};

// Either width; `mesh` must outlive the accelerator (with input order its buffers are read in place).
std::unique_ptr<Accelerator> make_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options);
// A bvh or bvh8 saved under the loader's prefix (bvh_build.hpp), traced in place.
class SectionLoader;
std::unique_ptr<Accelerator> load_bvh_accelerator(SectionLoader& in);

}  // namespace wavetrace
