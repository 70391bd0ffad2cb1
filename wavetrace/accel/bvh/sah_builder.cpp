// Top-down binned SAH (Wald 2007): centroids are binned along each axis, the cheapest
// plane by surface area heuristic splits the range in place. Large ranges bin in parallel
// and subtrees build as parallel tasks; node slots come from an atomic counter, so the
// tree's shape does not depend on the thread count (only node numbering does).
#include "wavetrace/accel/bvh/sah_builder.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include "wavetrace/kernels/checked_narrowing.hpp"

namespace wavetrace {
namespace {

constexpr std::uint32_t kMaxBins = 64;
constexpr std::size_t kParallelBinningThreshold = 1 << 16;
constexpr std::size_t kParallelSubtreeThreshold = 1 << 12;
// Below this depth the SAH chooses freely; deeper, ranges are halved, which bounds the
// tree's depth by kFreeDepth + log2(primitives) whatever the geometry (traversal stacks
// are sized from it: kMaxTreeDepth).
constexpr std::uint32_t kFreeDepth = 64;

float half_area(const Bounds3& bounds) {
  if (bounds.empty()) return 0.0f;
  const glm::vec3 e = bounds.extent();
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

struct Bin {
  Bounds3 bounds;
  std::uint32_t count;
};

// Bins of the three axes. Only the first `used` bins per axis are initialized: a node
// is binned once, and clearing all kMaxBins bins would cost more than binning a small node.
struct Binning {
  explicit Binning(std::uint32_t used) : used(used) {
    for (auto& axis : bins) {
      for (std::uint32_t i = 0; i < used; ++i) axis[i] = {Bounds3{}, 0};
    }
  }
  std::uint32_t used;
  std::array<std::array<Bin, kMaxBins>, 3> bins;
};

struct Split {
  int axis = -1;
  std::uint32_t bin = 0;  // primitives in bins [0, bin] go left
  float cost = std::numeric_limits<float>::infinity();
  Bounds3 left_bounds, right_bounds;
};

// A primitive as the builder moves it: its box and its id, 32 bytes, partitioned in
// place so that binning streams through memory instead of gathering through an index.
struct PrimitiveReference {
  Bounds3 bounds;
  std::uint32_t id;
  std::uint32_t unused;
  glm::vec3 centroid() const { return (bounds.lower + bounds.upper) * 0.5f; }
};

class Builder {
 public:
  Builder(std::span<const Bounds3> primitive_bounds, const SahOptions& options, BuildTree& tree)
      : options_(options), tree_(tree), references_(primitive_bounds.size()) {
    const std::size_t count = primitive_bounds.size();
    // Node and primitive ids are 32-bit, and a tree of n leaves has 2n - 1 nodes.
    checked_uint32(2 * std::uint64_t(count), "SAH build: twice the primitive count; build in chunks (build.chunk_triangles)");
    tbb::parallel_for(std::size_t{0}, count, [&](std::size_t i) {
      references_[i] = {primitive_bounds[i], static_cast<std::uint32_t>(i), 0};
    });
    tree_.nodes.resize(2 * count - 1);
    tree_.peak_bytes = references_.size() * sizeof(PrimitiveReference) + count * sizeof(std::uint32_t) +
                       tree_.nodes.size() * sizeof(BuildNode);
  }

  void build() {
    const auto count = static_cast<std::uint32_t>(references_.size());
    const Bounds3 root_bounds = bounds_of_range(0, count);
    next_node_.store(1);
    build_node(0, 0, count, root_bounds, 1);
    tree_.nodes.resize(next_node_.load());
    tree_.primitive_order.resize(count);
    tbb::parallel_for(std::uint32_t{0}, count, [&](std::uint32_t i) { tree_.primitive_order[i] = references_[i].id; });
  }

 private:
  Bounds3 bounds_of_range(std::uint32_t first, std::uint32_t count) const {
    return tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(first, first + count, 1 << 14), Bounds3{},
        [&](const tbb::blocked_range<std::uint32_t>& range, Bounds3 b) {
          for (std::uint32_t i = range.begin(); i != range.end(); ++i) b.extend(references_[i].bounds);
          return b;
        },
        [](Bounds3 a, const Bounds3& b) {
          a.extend(b);
          return a;
        });
  }

  Bounds3 centroid_bounds(std::uint32_t first, std::uint32_t count) const {
    const auto reduce = [&](std::uint32_t begin, std::uint32_t end, Bounds3 b) {
      for (std::uint32_t i = begin; i != end; ++i) b.extend(references_[i].centroid());
      return b;
    };
    if (count < kParallelBinningThreshold) return reduce(first, first + count, Bounds3{});
    return tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(first, first + count, 1 << 14), Bounds3{},
        [&](const tbb::blocked_range<std::uint32_t>& range, Bounds3 b) { return reduce(range.begin(), range.end(), b); },
        [](Bounds3 a, const Bounds3& b) {
          a.extend(b);
          return a;
        });
  }

  // The bin of a centroid along an axis; the same formula is used to partition.
  std::uint32_t bin_of(float centroid, float lower, float scale) const {
    const auto bin = static_cast<std::int64_t>((centroid - lower) * scale);
    return static_cast<std::uint32_t>(std::clamp<std::int64_t>(bin, 0, options_.bins - 1));
  }

  Binning bin_range(std::uint32_t first, std::uint32_t count, const Bounds3& centroids, const glm::vec3& scale) const {
    const auto fill = [&](std::uint32_t begin, std::uint32_t end, Binning binning) {
      for (std::uint32_t i = begin; i != end; ++i) {
        const PrimitiveReference& reference = references_[i];
        const glm::vec3 c = reference.centroid();
        for (int axis = 0; axis < 3; ++axis) {
          Bin& bin = binning.bins[axis][bin_of(c[axis], centroids.lower[axis], scale[axis])];
          bin.bounds.extend(reference.bounds);
          ++bin.count;
        }
      }
      return binning;
    };
    if (count < kParallelBinningThreshold) return fill(first, first + count, Binning(options_.bins));
    return tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(first, first + count, 1 << 14), Binning(options_.bins),
        [&](const tbb::blocked_range<std::uint32_t>& range, Binning b) { return fill(range.begin(), range.end(), b); },
        [&](Binning a, const Binning& b) {
          for (int axis = 0; axis < 3; ++axis) {
            for (std::uint32_t i = 0; i < options_.bins; ++i) {
              a.bins[axis][i].bounds.extend(b.bins[axis][i].bounds);
              a.bins[axis][i].count += b.bins[axis][i].count;
            }
          }
          return a;
        });
  }

  // The cheapest plane over all axes; only areas and counts are kept during the sweep
  // (no per-bin boxes to initialize), the chosen split's two boxes are merged afterwards.
  Split best_split(const Binning& binning, const Bounds3& centroids) const {
    Split best;
    const std::uint32_t bins = options_.bins;
    float right_area[kMaxBins];
    std::uint32_t right_count[kMaxBins];
    for (int axis = 0; axis < 3; ++axis) {
      if (!(centroids.upper[axis] > centroids.lower[axis])) continue;
      const auto& row = binning.bins[axis];
      Bounds3 accumulated;
      std::uint32_t count = 0;
      for (std::uint32_t i = bins - 1; i > 0; --i) {
        accumulated.extend(row[i].bounds);
        count += row[i].count;
        right_area[i - 1] = half_area(accumulated);
        right_count[i - 1] = count;
      }
      accumulated = Bounds3{};
      count = 0;
      for (std::uint32_t i = 0; i + 1 < bins; ++i) {
        accumulated.extend(row[i].bounds);
        count += row[i].count;
        if (count == 0 || right_count[i] == 0) continue;
        const float cost = half_area(accumulated) * blocks(count) + right_area[i] * blocks(right_count[i]);
        if (cost < best.cost) {
          best.axis = axis;
          best.bin = i;
          best.cost = cost;
        }
      }
    }
    if (best.axis >= 0) {
      const auto& row = binning.bins[best.axis];
      for (std::uint32_t i = 0; i < bins; ++i) (i <= best.bin ? best.left_bounds : best.right_bounds).extend(row[i].bounds);
    }
    return best;
  }

  float blocks(std::uint32_t count) const {
    return float((count + options_.block_size - 1) / options_.block_size);
  }

  void make_leaf(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Bounds3& bounds) {
    BuildNode& leaf = tree_.nodes[node];
    leaf.bounds = bounds;
    leaf.first = first;
    leaf.count = count;
  }

  void build_node(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Bounds3& bounds,
                  std::uint32_t depth) {
    if (count == 1) return make_leaf(node, first, count, bounds);
    const Bounds3 centroids = centroid_bounds(first, count);
    glm::vec3 scale;
    for (int axis = 0; axis < 3; ++axis) {
      const float extent = centroids.upper[axis] - centroids.lower[axis];
      scale[axis] = extent > 0.0f ? float(options_.bins) * (1.0f - 1e-6f) / extent : 0.0f;
    }
    const Split split = depth < kFreeDepth ? best_split(bin_range(first, count, centroids, scale), centroids) : Split{};
    const float leaf_cost = options_.intersection_cost * blocks(count);
    const float split_cost = options_.traversal_cost + options_.intersection_cost * split.cost / half_area(bounds);
    if (count <= options_.max_leaf_size && (split.axis < 0 || leaf_cost <= split_cost)) {
      // split.axis < 0 with few primitives: coincident centroids, a leaf is best.
      return make_leaf(node, first, count, bounds);
    }

    std::uint32_t middle;
    Bounds3 left_bounds, right_bounds;
    PrimitiveReference* references = references_.data();
    if (split.axis >= 0) {
      const int axis = split.axis;
      middle = static_cast<std::uint32_t>(
          std::partition(references + first, references + first + count,
                         [&](const PrimitiveReference& r) {
                           return bin_of(r.centroid()[axis], centroids.lower[axis], scale[axis]) <= split.bin;
                         }) -
          references);
      left_bounds = split.left_bounds;
      right_bounds = split.right_bounds;
    } else {
      // No plane separates the centroids (or the tree is too deep): halve the list.
      middle = first + count / 2;
      left_bounds = bounds_of_range(first, middle - first);
      right_bounds = bounds_of_range(middle, first + count - middle);
    }

    const std::uint32_t left = next_node_.fetch_add(2);
    BuildNode& inner = tree_.nodes[node];
    inner.bounds = bounds;
    inner.left = left;
    inner.right = left + 1;
    const std::uint32_t left_count = middle - first, right_count = first + count - middle;
    if (count >= kParallelSubtreeThreshold) {
      tbb::task_group group;
      group.run([&] { build_node(left, first, left_count, left_bounds, depth + 1); });
      build_node(left + 1, middle, right_count, right_bounds, depth + 1);
      group.wait();
    } else {
      build_node(left, first, left_count, left_bounds, depth + 1);
      build_node(left + 1, middle, right_count, right_bounds, depth + 1);
    }
  }

  SahOptions options_;
  BuildTree& tree_;
  LargeArray<PrimitiveReference> references_;
  std::atomic<std::uint32_t> next_node_{0};
};

std::uint32_t subtree_depth(const BuildTree& tree, std::uint32_t node) {
  const BuildNode& n = tree.nodes[node];
  if (n.leaf()) return 1;
  return 1 + std::max(subtree_depth(tree, n.left), subtree_depth(tree, n.right));
}

}  // namespace

std::uint32_t BuildTree::depth() const { return nodes.empty() ? 0 : subtree_depth(*this, 0); }

BuildTree build_sah_tree(std::span<const Bounds3> primitive_bounds, const SahOptions& options) {
  if (primitive_bounds.empty()) throw std::invalid_argument("SAH builder: no primitives");
  if (options.block_size < 1) throw std::invalid_argument("SAH builder: block size 0");
  if (options.max_leaf_size < 1 || options.max_leaf_size > 16) {
    throw std::invalid_argument(fmt::format("SAH builder: max leaf size {} is outside 1..16", options.max_leaf_size));
  }
  if (options.bins < 2 || options.bins > kMaxBins) {
    throw std::invalid_argument(fmt::format("SAH builder: {} bins is outside 2..{}", options.bins, kMaxBins));
  }
  BuildTree tree;
  Builder builder(primitive_bounds, options, tree);
  builder.build();
  return tree;
}

}  // namespace wavetrace
