// `raystrips`: Lauterbach, Yoon and Manocha's Ray-Strips (2007). The mesh is cut by the
// SAH into sub-meshes, each stripified; the strips carry an implicit spatial kd-tree
// (ray_strip_format.hpp) and sit in the leaves of the baseline's SAH BVH (or, width 8, of
// quantized 8-wide nodes). Triangles are
// tested by Plücker edges shared along the strip (strip_traversal.hpp).
#pragma once

#include <cstdint>
#include <memory>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/raystrips/stripify.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct RayStripsOptions {
  // Sub-mesh threshold (§4.2): the SAH tree is cut at its highest nodes holding at most
  // this many triangles; each such sub-mesh is stripified on its own. 2 .. 65535, or 0: by
  // the top's width (kSubmeshTriangles below).
  std::uint32_t submesh_triangles = 0;
  // OpenMesh's by default: on builtin:sphere:1M its strips are shorter (14.6 triangles
  // against 33.4) but hardly ever turn (2% repeats against 31%), so the kd-tree boxes are
  // tighter and tracing is 1.3x faster at about the same bytes per triangle.
  StripifierKind stripifier = StripifierKind::longest_of_three;
  // Most strips in one leaf of the top BVH; 1 is the paper's partition step (a leaf per
  // strip). The SAH decides below this bound. 1 .. 16, or 0: by the top's width.
  std::uint32_t strips_per_leaf = 0;
  // The strip's kd-tree is descended until a span holds at most this many triangles, which
  // are then tested together by shared edges (the paper: 2, a leaf; 6 fills the 8-lane
  // edge test and measured 1.4x faster than 2). 2 .. 64.
  std::uint32_t run_triangles = 6;
  std::uint32_t bins = 16;  // SAH bins, for the sub-mesh cut and the top BVH
  // The top over the strips: 2, the baseline's 32-byte binary nodes; 8, the quantized 8-wide
  // nodes HMQ's wide layout has (accel/bvh/quantized_wide_node.hpp) and a 4-byte offset per
  // top leaf.
  std::uint32_t width = 2;
  // Camera rays (intersect_coherent) in packets: under the binary top as 2x2 packets (§5.3),
  // which below `packet_min_active` active rays in a strip fall back to single-ray strip
  // traversal; under the 8-wide top eight at a time through its nodes, each ray alone
  // through the strips.
  bool packets = true;
  std::uint32_t packet_min_active = 2;  // 1 .. 4
  bool operator==(const RayStripsOptions&) const = default;

  // What 0 means for submesh_triangles and strips_per_leaf. The binary top keeps the paper's
  // long strips, one a leaf. Under the 8-wide top short strips trace faster (their leaves'
  // boxes are tighter) but each costs a 12-byte header: on room:1M and the scans Loop-subdivided
  // twice, 24 triangles and up to 4 strips a leaf was the fastest within 16 bytes a triangle
  // (1.2-1.6x the rays a second of 256 and 1 at 1.0-1.7 B/tri more; docs/measurements.md,
  // "Ray-Strips under the 8-wide top"), and builds about 1.5x slower.
  static constexpr std::uint32_t kSubmeshTriangles[2] = {256, 24};  // width 2, width 8
  static constexpr std::uint32_t kStripsPerLeaf[2] = {1, 4};
  RayStripsOptions resolved() const {
    RayStripsOptions options = *this;
    const int wide = width == 8 ? 1 : 0;
    if (options.submesh_triangles == 0) options.submesh_triangles = kSubmeshTriangles[wide];
    if (options.strips_per_leaf == 0) options.strips_per_leaf = kStripsPerLeaf[wide];
    return options;
  }
};

// Throws std::invalid_argument for options outside their ranges. `mesh` must outlive
// the accelerator only while it builds; the strips keep their own vertex copy.
std::unique_ptr<Accelerator> make_raystrips_accelerator(const TriangleMesh& mesh, const RayStripsOptions& options);

// The raystrips structure saved under the loader's prefix, traced in place (format in
// raystrips_accelerator.cpp).
class SectionLoader;
std::unique_ptr<Accelerator> load_raystrips_accelerator(const SectionLoader& loader);

}  // namespace wavetrace
