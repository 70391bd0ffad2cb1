// Build (bounds, optional Morton reorder, SAH tree, flatten in the chosen node order) and
// single-ray ordered traversal with a short stack of (node, entry distance) pairs.
#include "accel/bvh/bvh_accelerator.hpp"

#include <chrono>
#include <limits>
#include <numeric>
#include <stdexcept>

#include <tbb/parallel_for.h>
#include <tbb/parallel_sort.h>

#include "accel/bvh/bvh_node.hpp"
#include "kernels/morton.hpp"
#include "kernels/ray_box.hpp"
#include "kernels/triangle_intersect.hpp"
#include "memory/cache_aligned_allocator.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

// The indexed face set in Morton order of triangle centroids, vertices renumbered by first use.
struct ReorderedMesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::uvec3> triangles;
  std::vector<std::uint32_t> input_id;  // storage slot -> the mesh's triangle index
};

ReorderedMesh reorder_by_morton(const TriangleMesh& mesh) {
  const Bounds3 bounds = mesh.bounds();
  const glm::vec3 extent = glm::max(bounds.extent(), glm::vec3(1e-30f));
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(mesh.triangle_count());
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::vec3 centroid = (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0f;
    const glm::vec3 unit = glm::clamp((centroid - bounds.lower) / extent, 0.0f, 1.0f);
    const auto quantize = [](float x) { return static_cast<std::uint64_t>(x * 1048575.0f); };  // 20 bits per axis
    keys[t] = {morton3d_encode(quantize(unit.x), quantize(unit.y), quantize(unit.z)), static_cast<std::uint32_t>(t)};
  });
  tbb::parallel_sort(keys.begin(), keys.end());

  ReorderedMesh out;
  out.triangles.resize(keys.size());
  out.input_id.resize(keys.size());
  std::vector<std::uint32_t> new_vertex(mesh.vertex_count(), std::numeric_limits<std::uint32_t>::max());
  out.positions.reserve(mesh.vertex_count() + 1);
  for (std::size_t slot = 0; slot < keys.size(); ++slot) {
    const std::uint32_t t = keys[slot].second;
    out.input_id[slot] = t;
    glm::uvec3 tri = mesh.triangles[t];
    for (int k = 0; k < 3; ++k) {
      std::uint32_t& mapped = new_vertex[tri[k]];
      if (mapped == std::numeric_limits<std::uint32_t>::max()) {
        mapped = static_cast<std::uint32_t>(out.positions.size());
        out.positions.push_back(mesh.positions[tri[k]]);
      }
      tri[k] = mapped;
    }
    out.triangles[slot] = tri;
  }
  return out;
}

class BvhAccelerator final : public Accelerator {
 public:
  BvhAccelerator(const TriangleMesh& mesh, const BvhOptions& options) : options_(options) {
    const auto start = std::chrono::steady_clock::now();
    std::size_t working_bytes = 0;
    if (options.triangle_order == TriangleOrder::morton) {
      reordered_ = reorder_by_morton(mesh);
      positions_ = reordered_.positions.data();
      triangles_ = reordered_.triangles.data();
      vertex_count_ = reordered_.positions.size();
      working_bytes += mesh.triangle_count() * (sizeof(std::pair<std::uint64_t, std::uint32_t>) + 4);
    } else {
      positions_ = mesh.positions.data();
      triangles_ = mesh.triangles.data();
      vertex_count_ = mesh.vertex_count();
    }
    triangle_count_ = mesh.triangle_count();

    std::vector<Bounds3> bounds(triangle_count_);
    tbb::parallel_for(std::size_t{0}, triangle_count_, [&](std::size_t t) {
      const glm::uvec3& tri = triangles_[t];
      Bounds3 b;
      b.extend(positions_[tri.x]);
      b.extend(positions_[tri.y]);
      b.extend(positions_[tri.z]);
      bounds[t] = b;
    });
    SahOptions sah;
    sah.max_leaf_size = options.max_leaf_size;
    sah.bins = options.bins;
    const BuildTree tree = build_sah_tree(bounds, sah);
    working_bytes = std::max(working_bytes, bounds.size() * sizeof(Bounds3) + tree.peak_bytes);

    // Flatten in the chosen order: node i of the array is build node order[i].
    const std::vector<std::uint32_t> order = node_order(tree, options.layout);
    std::vector<std::uint32_t> position_of(tree.nodes.size());
    for (std::uint32_t i = 0; i < order.size(); ++i) position_of[order[i]] = i;
    nodes_.resize(order.size());
    leaf_triangles_.resize(triangle_count_);
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
    depth_ = tree.depth();
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = working_bytes + tree.nodes.size() * sizeof(BuildNode) + memory().total();
  }

  std::string name() const override { return "bvh"; }

  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    traverse<false>(rays, hits, range);
  }
  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    traverse<true>(rays, hits, range);
  }

  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = nodes_.size() * sizeof(BvhNode) + leaf_triangles_.size() * sizeof(std::uint32_t);
    report.geometry = vertex_count_ * sizeof(glm::vec3) + triangle_count_ * sizeof(glm::uvec3);
    report.other = reordered_.input_id.size() * sizeof(std::uint32_t);
    return report;
  }

  BuildReport build() const override { return build_; }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    return {std::as_bytes(std::span(nodes_)), std::as_bytes(std::span(leaf_triangles_)),
            std::as_bytes(std::span(triangles_, triangle_count_)), std::as_bytes(std::span(positions_, vertex_count_))};
  }

 private:
  template <bool kAnyHit>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    struct StackEntry {
      std::uint32_t node;
      float distance;
    };
    StackEntry stack[kMaxTreeDepth];
    const BvhNode* nodes = nodes_.data();
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      hits.t[i] = kInfinity;
      hits.primitive[i] = kInvalidPrimitive;
      hits.u[i] = hits.v[i] = 0.0f;
      if (!(rays.flags[i] & ray_flags::alive)) continue;
      const glm::vec3 origin(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]);
      const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
      const BoxRay box_ray = make_box_ray(origin, direction);
      const WatertightRay triangle_ray = make_watertight_ray(origin, direction);
      const float tmin = rays.tmin[i];
      float tmax = rays.tmax[i];
      std::uint32_t found = kInvalidPrimitive;
      TriangleHit best{kInfinity, 0.0f, 0.0f};

      std::uint32_t top = 0;
      std::uint32_t node = 0;
      if (intersect_box(box_ray, nodes[0].lower, nodes[0].upper, tmin, tmax) == kInfinity) continue;
      while (true) {
        const BvhNode& current = nodes[node];
        if (current.leaf()) {
          const std::uint32_t end = current.first + current.triangle_count();
          for (std::uint32_t slot = current.first; slot < end; ++slot) {
            const std::uint32_t triangle = leaf_triangles_[slot];
            const glm::uvec3& tri = triangles_[triangle];
            TriangleHit hit;
            if (intersect_watertight(triangle_ray, positions_[tri.x], positions_[tri.y], positions_[tri.z], tmin, tmax,
                                     hit)) {
              tmax = hit.t;
              best = hit;
              found = triangle;
              if constexpr (kAnyHit) break;
            }
          }
          if (kAnyHit && found != kInvalidPrimitive) break;
        } else {
          std::uint32_t near = current.left(), far = current.right();
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
      if (found != kInvalidPrimitive) {
        hits.t[i] = best.t;
        hits.primitive[i] = reordered_.input_id.empty() ? found : reordered_.input_id[found];
        hits.u[i] = best.u;
        hits.v[i] = best.v;
      }
    }
  }

  BvhOptions options_;
  ReorderedMesh reordered_;
  const glm::vec3* positions_ = nullptr;
  const glm::uvec3* triangles_ = nullptr;
  std::size_t vertex_count_ = 0;
  std::size_t triangle_count_ = 0;
  std::vector<BvhNode, CacheAlignedAllocator<BvhNode>> nodes_;
  std::vector<std::uint32_t> leaf_triangles_;
  std::uint32_t depth_ = 0;
  BuildReport build_;
};

}  // namespace

TriangleOrder parse_triangle_order(const std::string& text) {
  if (text == "input") return TriangleOrder::input;
  if (text == "morton") return TriangleOrder::morton;
  throw std::invalid_argument("unknown triangle order '" + text + "' (input, morton)");
}

std::string to_string(TriangleOrder order) { return order == TriangleOrder::morton ? "morton" : "input"; }

std::unique_ptr<Accelerator> make_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options) {
  return std::make_unique<BvhAccelerator>(mesh, options);
}

}  // namespace wavetrace
