// Build (bounds, optional Morton reorder, SAH tree, flatten in the chosen node order) and
// single-ray ordered traversal with a short stack of (node, entry distance) pairs.
#include "accel/bvh/bvh_accelerator.hpp"

#include <chrono>
#include <limits>
#include <numeric>
#include <stdexcept>


#include "accel/bvh/bvh_build.hpp"
#include "accel/bvh/bvh_node.hpp"
#include "accel/bvh/wide_bvh_accelerator.hpp"
#include "kernels/ray_box.hpp"
#include "accel/bvh/leaf_query.hpp"
#include "memory/cache_aligned_allocator.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

class BvhAccelerator final : public Accelerator {
 public:
  BvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options)
      : geometry_(mesh, options.triangle_order) {
    const auto start = std::chrono::steady_clock::now();
    const BuildTree tree = build_bvh_tree(geometry_, options);

    // Flatten in the chosen order: node i of the array is build node order[i].
    const std::vector<std::uint32_t> order = node_order(tree, options.layout);
    std::vector<std::uint32_t> position_of(tree.nodes.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) position_of[order[i]] = i;
    nodes_.resize(order.size());
    leaf_triangles_.resize(geometry_.triangle_count());
    std::uint32_t slot = 0;
    for (std::uint32_t i = 0; i < order.size(); ++i) {
      const BuildNode& built = tree.nodes[order[i]];
      BvhNode& node = nodes_[i];
      node.lower = built.bounds.lower;
      node.upper = built.bounds.upper;
      if (built.leaf()) {
        // Leaf triangles are stored in node order too, so a leaf's slots follow its node's position.
        node.first = slot;
        node.count = BvhNode::kLeafFlag | built.count;
        for (std::uint32_t k = 0; k < built.count; ++k) {
          leaf_triangles_[slot++] = tree.primitive_order[built.first + k];
        }
      } else {
        node.first = position_of[built.left];
        node.count = position_of[built.right];
      }
    }
    adopt_leaf_order(options, geometry_, leaf_triangles_);
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = bvh_build_peak_bytes(tree, geometry_, memory().total());
  }

  std::string name() const override { return "bvh"; }

  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    traverse<false>(rays, hits, range, probe);
  }
  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    traverse<true>(rays, hits, range, probe);
  }
  bool probed() const override { return true; }
  void intersect_closest_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                RecordingProbe& probe) const override {
    traverse<false>(rays, hits, range, probe);
  }
  void intersect_any_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                            RecordingProbe& probe) const override {
    traverse<true>(rays, hits, range, probe);
  }

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
  template <bool kAnyHit, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    struct StackEntry {
      std::uint32_t node;
      float distance;
    };
    StackEntry stack[kMaxTreeDepth];
    const BvhNode* nodes = nodes_.data();
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      if (!(rays.flags[i] & ray_flags::alive)) {
        write_miss(hits, i);
        continue;
      }
      const glm::vec3 origin(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]);
      const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
      const BoxRay box_ray = make_box_ray(origin, direction);
      LeafQuery query(geometry_, leaf_triangles_, origin, direction, rays.tmin[i], rays.tmax[i]);
      const float tmin = query.tmin;
      float& tmax = query.tmax;

      std::uint32_t top = 0;
      std::uint32_t node = 0;
      probe.read(nodes, sizeof(BvhNode));
      if (intersect_box(box_ray, nodes[0].lower, nodes[0].upper, tmin, tmax) == kInfinity) {
        write_miss(hits, i);
        continue;
      }
      while (true) {
        const BvhNode& current = nodes[node];
        if (current.leaf()) {
          query.test_leaf<kAnyHit>(current.first, current.triangle_count(), probe);
          if (kAnyHit && query.found()) break;
        } else {
          std::uint32_t near = current.left(), far = current.right();
          probe.read(nodes + near, sizeof(BvhNode));
          probe.read(nodes + far, sizeof(BvhNode));
          float near_distance = intersect_box(box_ray, nodes[near].lower, nodes[near].upper, tmin, tmax);
          float far_distance = intersect_box(box_ray, nodes[far].lower, nodes[far].upper, tmin, tmax);
          if (far_distance < near_distance) {
            std::swap(near, far);
            std::swap(near_distance, far_distance);
          }
          if (near_distance != kInfinity) {
            if (far_distance != kInfinity) stack[top++] = {far, far_distance};
            node = near;
            continue;
          }
        }
        // Pop the nearest pending subtree that can still hold a closer hit.
        while (top > 0 && stack[top - 1].distance > tmax) --top;
        if (top == 0) break;
        node = stack[--top].node;
      }
      query.write(hits, i, probe);
    }
  }

  IndexedFaceSet geometry_;
  LargeArray<BvhNode> nodes_;
  LargeArray<std::uint32_t> leaf_triangles_;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options) {
  if (options.width == 8) return make_wide_bvh_accelerator(mesh, options);
  if (options.width != 2) throw std::invalid_argument("bvh width must be 2 or 8");
  return std::make_unique<BvhAccelerator>(mesh, options);
}

}  // namespace wavetrace
