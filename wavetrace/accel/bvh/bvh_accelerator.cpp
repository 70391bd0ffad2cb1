// Build (bounds, optional Morton reorder, SAH tree, flatten in the chosen node order) and
// single-ray ordered traversal with a short stack of (node, entry distance) pairs.
#include "wavetrace/accel/bvh/bvh_accelerator.hpp"

#include <chrono>
#include <stdexcept>

#include "wavetrace/accel/bvh/bvh_build.hpp"
#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/bvh_walk.hpp"
#include "wavetrace/accel/bvh/leaf_query.hpp"
#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/accel/bvh/wide_bvh_accelerator.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {
namespace {

class BvhAccelerator final : public ProbedAccelerator<BvhAccelerator> {
  friend class ProbedAccelerator<BvhAccelerator>;

 public:
  explicit BvhAccelerator(SectionLoader& in) : geometry_(in) {
    load_bvh(in, "bvh.nodes", nodes_, "bvh.leaf_triangles", leaf_triangles_, build_, [&](const BvhNode& leaf) {
      // Without leaf_triangles (triangle_order = leaf) a leaf's slots are the triangles themselves.
      const std::size_t slots = leaf_triangles_.empty() ? geometry_.triangle_count() : leaf_triangles_.size();
      check_leaf_slots(leaf.first, leaf.triangle_count(), slots, in, "bvh.nodes");
    });
    for (const std::uint32_t triangle : leaf_triangles_) {
      if (triangle >= geometry_.triangle_count()) in.fail("bvh.leaf_triangles", "names a triangle that does not exist");
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    save_bvh(out, prefix, geometry_, "bvh.nodes", nodes_, "bvh.leaf_triangles", leaf_triangles_, build_);
  }

  BvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options) : BvhAccelerator(mesh, options, PhaseClock{}) {}

  std::string name() const override { return "bvh"; }

  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = nodes_.size() * sizeof(BvhNode) + leaf_triangles_.size() * sizeof(std::uint32_t);
    report.geometry = geometry_.geometry_bytes();
    report.other = geometry_.id_map_bytes();
    return report;
  }

  BuildReport build() const override { return build_; }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    return bvh_memory_spans(nodes_, leaf_triangles_, geometry_);
  }

 private:
  // The clock starts before the face set is made (a member), so that its copy is timed too.
  BvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options, PhaseClock clock)
      : geometry_(mesh, options.triangle_order) {
    const BuildTree tree = build_bvh_tree_timed(geometry_, options, clock, build_);

    // Leaf triangles are stored in node order too, so a leaf's slots follow its node's position.
    LargeArray<std::uint32_t> leaf_triangles(geometry_.triangle_count());
    LargeArray<BvhNode> nodes;
    std::uint32_t slot = 0;
    flatten_tree(tree, node_order(tree, options.layout), nodes, [&](const BuildNode& leaf) {
      const std::uint32_t first = slot;
      for (std::uint32_t k = 0; k < leaf.count; ++k) leaf_triangles[slot++] = tree.primitive_order[leaf.first + k];
      return first;
    });
    adopt_leaf_order(options, geometry_, leaf_triangles);
    nodes_ = StoredArray<BvhNode>(std::move(nodes));
    leaf_triangles_ = StoredArray<std::uint32_t>(std::move(leaf_triangles));
    clock.lap(build_.phases, "flatten");
    build_.seconds = clock.elapsed();
    build_.peak_bytes = bvh_build_peak_bytes(tree, geometry_, memory().total());
  }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      LeafQuery query(geometry_, leaf_triangles_, ray);
      walk_bvh(nodes_.data(), ray.box, query.tmin, query.tmax, probe, [&](const BvhNode& leaf) {
        query.test_leaf<kAnyHit>(leaf.first, leaf.triangle_count(), probe);
        return kAnyHit && query.found();
      });
      query.write<!kAnyHit>(hits, i, probe);
    });
  }

  IndexedFaceSet geometry_;
  StoredArray<BvhNode> nodes_;
  StoredArray<std::uint32_t> leaf_triangles_;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> load_bvh_accelerator(SectionLoader& in) {
  if (in.file()->has(in.prefix() + "bvh8.nodes")) return load_wide_bvh_accelerator(in);
  return std::make_unique<BvhAccelerator>(in);
}

std::unique_ptr<Accelerator> make_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options) {
  if (options.width == 8) return make_wide_bvh_accelerator(mesh, options);
  if (options.width != 2) throw std::invalid_argument("bvh width must be 2 or 8");
  return std::make_unique<BvhAccelerator>(mesh, options);
}

}  // namespace wavetrace
