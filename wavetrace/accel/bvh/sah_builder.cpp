// Top-down binned SAH (Wald 2007): centroids are binned along each axis, the cheapest
// plane by surface area heuristic splits the range in place. Large ranges bin in parallel
// and subtrees build as parallel tasks; node slots come from an atomic counter, so the
// tree's shape does not depend on the thread count (only node numbering does). Boxes are
// binned a register a box, as Wald's SIMD binning does, into several sets of bins in turn;
// the three axes' planes are costed in lanes; the partition finds the children's centroid
// bounds as it moves them, so a node costs two passes over its range.
#include "wavetrace/accel/bvh/sah_builder.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <bit>
#include <cstddef>
#include <limits>
#include <memory>
#include <new>
#include <utility>

#include <immintrin.h>
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
// Ranges of at least this many references bin into four sets of bins in turn, or two.
constexpr std::uint32_t kFourBinSetsFrom = 256;
constexpr std::uint32_t kTwoBinSetsFrom = 64;
// Below this depth the SAH chooses freely; deeper, ranges are halved, which bounds the
// tree's depth by kFreeDepth + log2(primitives) whatever the geometry (traversal stacks
// are sized from it: kMaxTreeDepth).
constexpr std::uint32_t kFreeDepth = 64;

float half_area(const Bounds3& bounds) {
  if (bounds.empty()) return 0.0f;
  const glm::vec3 e = bounds.extent();
  return e.x * e.y + e.y * e.z + e.z * e.x;
}

// A box as two SSE registers: lower (x, y, z, -) and upper (x, y, z, -); lane 3 is not read.
struct BinBox {
  __m128 lower, upper;
  // Bounds3::extend's own comparisons: glm::min(a, b) is b < a ? b : a, which is
  // _mm_min_ps(b, a), and glm::max(a, b) is _mm_max_ps(b, a), so that boxes, even to the sign
  // of a zero, come out as the scalar build's did.
  void extend(__m128 other_lower, __m128 other_upper) {
    lower = _mm_min_ps(other_lower, lower);
    upper = _mm_max_ps(other_upper, upper);
  }
  Bounds3 bounds() const {
    alignas(16) float l[4], u[4];
    _mm_store_ps(l, lower);
    _mm_store_ps(u, upper);
    return Bounds3{glm::vec3(l[0], l[1], l[2]), glm::vec3(u[0], u[1], u[2])};
  }
};

inline BinBox empty_bin_box() {
  return {_mm_set1_ps(std::numeric_limits<float>::infinity()), _mm_set1_ps(-std::numeric_limits<float>::infinity())};
}

// A bin's box in one AVX register: lower (x, y, z, -) in the low half and the negated upper
// (-x, -y, -z, -) in the high one, so that one min extends both ends (binning stores one
// register a reference and axis instead of two). min(-a, -b) picks -a exactly where max(a, b)
// picks a, and negation is exact, so the boxes are BinBox's to the bit. Lanes 3 and 7 are not
// read.
struct BinBounds {
  __m256 lower_and_negated_upper;
  void extend(__m256 other) { lower_and_negated_upper = _mm256_min_ps(other, lower_and_negated_upper); }
  __m128 lower() const { return _mm256_castps256_ps128(lower_and_negated_upper); }
  __m128 upper() const {
    return _mm_xor_ps(_mm256_extractf128_ps(lower_and_negated_upper, 1), _mm_set1_ps(-0.0f));
  }
  Bounds3 bounds() const { return BinBox{lower(), upper()}.bounds(); }
};

// A reference's box as BinBounds holds it.
inline __m256 bin_bounds_of(__m128 lower, __m128 upper) {
  return _mm256_set_m128(_mm_xor_ps(upper, _mm_set1_ps(-0.0f)), lower);
}

// Bins of the three axes. Only the first `used` bins per axis are initialized: a node
// is binned once, and clearing all kMaxBins bins would cost more than binning a small node.
struct Binning {
  Binning() = default;  // no bin initialized: clear() before use
  explicit Binning(std::uint32_t used) { clear(used); }
  void clear(std::uint32_t bins) {
    used = bins;
    const __m256 empty = _mm256_set1_ps(std::numeric_limits<float>::infinity());
    for (int axis = 0; axis < 3; ++axis) {
      for (std::uint32_t i = 0; i < used; ++i) {
        boxes[axis][i].lower_and_negated_upper = empty;
        counts[axis][i] = 0;
      }
    }
  }
  void merge(const Binning& other) {
    for (int axis = 0; axis < 3; ++axis) {
      for (std::uint32_t i = 0; i < used; ++i) {
        boxes[axis][i].extend(other.boxes[axis][i].lower_and_negated_upper);
        counts[axis][i] += other.counts[axis][i];
      }
    }
  }
  std::uint32_t used = 0;
  std::array<std::array<BinBounds, kMaxBins>, 3> boxes;
  std::array<std::array<std::uint32_t, kMaxBins>, 3> counts;
};

struct Split {
  int axis = -1;
  std::uint32_t bin = 0;  // primitives in bins [0, bin] go left
  float cost = std::numeric_limits<float>::infinity();
  Bounds3 left_bounds, right_bounds;
};

// The builder's references as SSE registers: 16-byte loads at bytes 0 and 12 of the box
// (lane 3 is upper.x and the id, never read); the centroid as (lower + upper) * 0.5, lane
// by lane.
inline __m128 lower4(const SahReference& reference) { return _mm_loadu_ps(&reference.bounds.lower.x); }
inline __m128 upper4(const SahReference& reference) { return _mm_loadu_ps(&reference.bounds.upper.x); }
inline glm::vec3 centroid_of(const SahReference& reference) {
  return (reference.bounds.lower + reference.bounds.upper) * 0.5f;
}

inline __m128 centroid4(__m128 lower, __m128 upper) { return _mm_mul_ps(_mm_add_ps(lower, upper), _mm_set1_ps(0.5f)); }

// The bins of a centroid along the three axes: (centroid - lower) * scale truncated toward
// zero, clamped to [0, bins - 1]; binning and partitioning both use it. Lane 3 is garbage.
inline __m128i bins_of(__m128 centroid, __m128 lower, __m128 scale, __m128i last_bin) {
  const __m128i bin = _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(centroid, lower), scale));
  return _mm_min_epi32(_mm_max_epi32(bin, _mm_setzero_si128()), last_bin);
}

inline __m128 load3(const glm::vec3& v) { return _mm_setr_ps(v.x, v.y, v.z, 0.0f); }

class Builder {
 public:
  Builder(LargeArray<SahReference> references, const SahOptions& options, BuildTree& tree)
      : options_(options), tree_(tree), references_(std::move(references)) {
    const std::size_t count = references_.size();
    slots_.reset(static_cast<BuildNode*>(allocate_large_array((2 * count - 1) * sizeof(BuildNode))));
  }

  void build() {
    const auto count = static_cast<std::uint32_t>(references_.size());
    const Bounds3 root_bounds = bounds_of_range(0, count);
    next_node_.store(1);
    build_node(0, 0, count, root_bounds, centroid_bounds(0, count), 1);
    const std::uint32_t used = next_node_.load();
    tree_.nodes = BuildNodes(slots_.release(), used);
    tree_.peak_bytes = references_.size() * sizeof(SahReference) + count * sizeof(std::uint32_t) +
                       std::size_t{used} * sizeof(BuildNode);
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
      for (std::uint32_t i = begin; i != end; ++i) b.extend(centroid_of(references_[i]));
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

  // What places a centroid in its bins on the three axes (bins_of's operands).
  struct BinFrame {
    __m128 lower, scales;
    __m128i last_bin;
  };

  BinFrame bin_frame(const Bounds3& centroids, const glm::vec3& scale) const {
    return {load3(centroids.lower), load3(scale), _mm_set1_epi32(static_cast<int>(options_.bins - 1))};
  }

  static void bin_reference(const SahReference& reference, const BinFrame& frame, Binning& binning) {
    const __m128 box_lower = lower4(reference), box_upper = upper4(reference);
    const __m128i bins = bins_of(centroid4(box_lower, box_upper), frame.lower, frame.scales, frame.last_bin);
    const int bin[3] = {_mm_cvtsi128_si32(bins), _mm_extract_epi32(bins, 1), _mm_extract_epi32(bins, 2)};
    const __m256 box = bin_bounds_of(box_lower, box_upper);
    for (int axis = 0; axis < 3; ++axis) {
      binning.boxes[axis][bin[axis]].extend(box);
      ++binning.counts[axis][bin[axis]];
    }
  }

  // Neighbours in a range mostly fall in the same bins (the splits above sorted the range by
  // place), so with one set of bins each reference waits for the previous one's store to its
  // bin to extend it again. A range deals its references to kSets sets in turn, merged at the
  // end; returns where the dealing stopped (fewer than kSets references are left). The boxes
  // are the one set's but for the sign of a zero where +0 and -0 meet in a bin, which no
  // comparison or area tells apart (test SahBuilder.BuildsTheTreeAPlainBinnedSahBuilds).
  template <std::uint32_t kSets>
  std::uint32_t fill_bins_in_turn(std::uint32_t begin, std::uint32_t end, const BinFrame& frame,
                                  Binning& binning) const {
    std::array<Binning, kSets - 1> others;
    for (Binning& other : others) other.clear(binning.used);
    std::uint32_t i = begin;
    for (; end - i >= kSets; i += kSets) {
      bin_reference(references_[i], frame, binning);
      for (std::uint32_t k = 1; k < kSets; ++k) bin_reference(references_[i + k], frame, others[k - 1]);
    }
    for (const Binning& other : others) binning.merge(other);
    return i;
  }

  void fill_bins(std::uint32_t begin, std::uint32_t end, const BinFrame& frame, Binning& binning) const {
    std::uint32_t i = begin;
    if (end - begin >= kFourBinSetsFrom) {
      i = fill_bins_in_turn<4>(begin, end, frame, binning);
    } else if (end - begin >= kTwoBinSetsFrom) {
      i = fill_bins_in_turn<2>(begin, end, frame, binning);
    }
    for (; i != end; ++i) bin_reference(references_[i], frame, binning);
  }

  // Into `binning`, fresh: a small node's bins are filled in place, never copied (7 KB).
  void bin_range(std::uint32_t first, std::uint32_t count, const Bounds3& centroids, const glm::vec3& scale,
                 Binning& binning) const {
    const BinFrame frame = bin_frame(centroids, scale);
    if (count < kParallelBinningThreshold) return fill_bins(first, first + count, frame, binning);
    binning = tbb::parallel_reduce(
        tbb::blocked_range<std::uint32_t>(first, first + count, 1 << 14), binning,
        [&](const tbb::blocked_range<std::uint32_t>& range, Binning b) {
          fill_bins(range.begin(), range.end(), frame, b);
          return b;
        },
        [](Binning a, const Binning& b) {
          a.merge(b);
          return a;
        });
  }

  // The cheapest plane over all axes. The three axes' sweeps run side by side, an axis a lane
  // (most nodes are small, and this sweep, done one axis and one float at a time, was a
  // quarter of a build); each lane computes what the scalar sweep did, operation for
  // operation, so the same plane wins: the first cheapest in axis, then bin, order.
  Split best_split(const Binning& binning, const Bounds3& centroids) const {
    const std::uint32_t bins = options_.bins;
    struct Lanes {  // a box per axis: lane a holds the box of axis a's bin
      __m128 lx, ly, lz, ux, uy, uz;
      void extend(const Lanes& o) {
        lx = _mm_min_ps(o.lx, lx), ly = _mm_min_ps(o.ly, ly), lz = _mm_min_ps(o.lz, lz);
        ux = _mm_max_ps(o.ux, ux), uy = _mm_max_ps(o.uy, uy), uz = _mm_max_ps(o.uz, uz);
      }
      __m128 half_area() const {  // as half_area(): 0 for an empty box
        const __m128 ex = _mm_sub_ps(ux, lx), ey = _mm_sub_ps(uy, ly), ez = _mm_sub_ps(uz, lz);
        const __m128 area = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ey), _mm_mul_ps(ey, ez)), _mm_mul_ps(ez, ex));
        return _mm_andnot_ps(_mm_cmpgt_ps(lx, ux), area);
      }
    };
    Lanes lanes[kMaxBins];  // transposed once for both sweeps
    const __m128 sign = _mm_set1_ps(-0.0f);
    for (std::uint32_t i = 0; i < bins; ++i) {
      // The three axes' boxes as rows, lower and negated upper transposed at once, a half each.
      const __m256 r0 = binning.boxes[0][i].lower_and_negated_upper, r1 = binning.boxes[1][i].lower_and_negated_upper;
      const __m256 r2 = binning.boxes[2][i].lower_and_negated_upper, r3 = _mm256_setzero_ps();
      const __m256 t0 = _mm256_unpacklo_ps(r0, r1), t1 = _mm256_unpackhi_ps(r0, r1);
      const __m256 t2 = _mm256_unpacklo_ps(r2, r3), t3 = _mm256_unpackhi_ps(r2, r3);
      const __m256 x = _mm256_shuffle_ps(t0, t2, 0x44), y = _mm256_shuffle_ps(t0, t2, 0xEE);
      const __m256 z = _mm256_shuffle_ps(t1, t3, 0x44);
      lanes[i] = Lanes{_mm256_castps256_ps128(x),
                       _mm256_castps256_ps128(y),
                       _mm256_castps256_ps128(z),
                       _mm_xor_ps(_mm256_extractf128_ps(x, 1), sign),
                       _mm_xor_ps(_mm256_extractf128_ps(y, 1), sign),
                       _mm_xor_ps(_mm256_extractf128_ps(z, 1), sign)};
    }
    const auto bin_counts = [&](std::uint32_t i) {
      return _mm_setr_epi32(static_cast<int>(binning.counts[0][i]), static_cast<int>(binning.counts[1][i]),
                            static_cast<int>(binning.counts[2][i]), 0);
    };
    const __m128 infinity = _mm_set1_ps(std::numeric_limits<float>::infinity());
    const __m128 minus_infinity = _mm_set1_ps(-std::numeric_limits<float>::infinity());
    const Lanes empty{infinity, infinity, infinity, minus_infinity, minus_infinity, minus_infinity};
    __m128 right_area[kMaxBins];
    __m128i right_count[kMaxBins];
    Lanes accumulated = empty;
    __m128i count = _mm_setzero_si128();
    for (std::uint32_t i = bins - 1; i > 0; --i) {
      accumulated.extend(lanes[i]);
      count = _mm_add_epi32(count, bin_counts(i));
      right_area[i - 1] = accumulated.half_area();
      right_count[i - 1] = count;
    }
    alignas(16) float cost[kMaxBins][4];
    alignas(16) std::uint32_t left_count[kMaxBins][4], right_counts[kMaxBins][4];
    accumulated = empty;
    count = _mm_setzero_si128();
    for (std::uint32_t i = 0; i + 1 < bins; ++i) {
      accumulated.extend(lanes[i]);
      count = _mm_add_epi32(count, bin_counts(i));
      _mm_store_ps(cost[i], _mm_add_ps(_mm_mul_ps(accumulated.half_area(), blocks(count)),
                                       _mm_mul_ps(right_area[i], blocks(right_count[i]))));
      _mm_store_si128(reinterpret_cast<__m128i*>(left_count[i]), count);
      _mm_store_si128(reinterpret_cast<__m128i*>(right_counts[i]), right_count[i]);
    }
    // The first cheapest plane in axis, then bin, order: the least cost over the planes with
    // primitives on both sides, then the first plane that costs it (no branch a plane).
    const __m128 open_axes = _mm_cmpgt_ps(load3(centroids.upper), load3(centroids.lower));
    __m128 least = infinity;
    for (std::uint32_t i = 0; i + 1 < bins; ++i) {
      least = _mm_min_ps(least, plane_cost(cost[i], left_count[i], right_counts[i], open_axes, infinity));
    }
    least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(2, 3, 0, 1)));
    least = _mm_min_ps(least, _mm_shuffle_ps(least, least, _MM_SHUFFLE(1, 0, 3, 2)));
    Split best;
    if (!(_mm_cvtss_f32(least) < std::numeric_limits<float>::infinity())) return best;
    best.cost = _mm_cvtss_f32(least);
    std::uint32_t first_plane = ~0u;  // axis * kMaxBins + bin of the first plane at the least cost
    for (std::uint32_t i = 0; i + 1 < bins; ++i) {
      const int at_least =
          _mm_movemask_ps(_mm_cmpeq_ps(plane_cost(cost[i], left_count[i], right_counts[i], open_axes, infinity), least)) & 7;
      if (at_least != 0) first_plane = std::min(first_plane, std::uint32_t(std::countr_zero(unsigned(at_least))) * kMaxBins + i);
    }
    best.axis = static_cast<int>(first_plane / kMaxBins);
    best.bin = first_plane % kMaxBins;
    const auto& row = binning.boxes[best.axis];
    BinBounds left = row[0], right = row[best.bin + 1];
    for (std::uint32_t i = 1; i <= best.bin; ++i) left.extend(row[i].lower_and_negated_upper);
    for (std::uint32_t i = best.bin + 2; i < bins; ++i) right.extend(row[i].lower_and_negated_upper);
    best.left_bounds = left.bounds();
    best.right_bounds = right.bounds();
    return best;
  }

  // A plane's cost on each axis, infinite where it leaves a side empty or the axis is closed.
  static __m128 plane_cost(const float* cost, const std::uint32_t* left_count, const std::uint32_t* right_count,
                           __m128 open_axes, __m128 infinity) {
    const __m128i zero = _mm_setzero_si128();
    const __m128i left = _mm_load_si128(reinterpret_cast<const __m128i*>(left_count));
    const __m128i right = _mm_load_si128(reinterpret_cast<const __m128i*>(right_count));
    const __m128 empty_side = _mm_castsi128_ps(_mm_or_si128(_mm_cmpeq_epi32(left, zero), _mm_cmpeq_epi32(right, zero)));
    const __m128 open = _mm_andnot_ps(empty_side, open_axes);
    return _mm_blendv_ps(infinity, _mm_load_ps(cost), open);
  }

  // blocks() of each lane's count (counts stay below 2^31: twice them fits 32 bits).
  __m128 blocks(__m128i count) const {
    if (block_shift_ >= 0) {
      const __m128i rounded = _mm_add_epi32(count, _mm_set1_epi32(static_cast<int>(options_.block_size - 1)));
      return _mm_cvtepi32_ps(_mm_srl_epi32(rounded, _mm_cvtsi32_si128(block_shift_)));
    }
    alignas(16) std::uint32_t lanes[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(lanes), count);
    return _mm_setr_ps(blocks(lanes[0]), blocks(lanes[1]), blocks(lanes[2]), blocks(lanes[3]));
  }

  // The SAH sweep asks this for every bin: a shift where the block size is a power of two.
  float blocks(std::uint32_t count) const {
    if (block_shift_ >= 0) return float((count + options_.block_size - 1) >> block_shift_);
    return float((count + options_.block_size - 1) / options_.block_size);
  }

  void make_leaf(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Bounds3& bounds) {
    new (&slots_[node]) BuildNode{bounds, 0, 0, first, count};
  }

  // std::partition's own moves (libstdc++'s bidirectional __partition, so the tree is the one
  // it built), gathering each side's centroid bounds on the way: every reference is tested
  // once, and a side's bounds are those of the references that end on it.
  std::uint32_t partition_range(std::uint32_t first, std::uint32_t count, int axis, std::uint32_t split_bin,
                                const Bounds3& centroids, const glm::vec3& scale, Bounds3& left_centroids,
                                Bounds3& right_centroids) {
    const __m128 lower = load3(centroids.lower), scales = load3(scale);
    const __m128i last_bin = _mm_set1_epi32(static_cast<int>(options_.bins - 1));
    const __m128i split = _mm_set1_epi32(static_cast<int>(split_bin));
    BinBox left = empty_bin_box(), right = empty_bin_box();
    // Tests a reference, and adds its centroid to the side it goes to.
    const auto goes_left = [&](const SahReference& reference) {
      const __m128 c = centroid4(lower4(reference), upper4(reference));
      const __m128i bin = bins_of(c, lower, scales, last_bin);
      const bool is_left = ((_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(bin, split))) >> axis) & 1) == 0;
      (is_left ? left : right).extend(c, c);
      return is_left;
    };
    SahReference* begin = references_.data() + first;
    SahReference* end = begin + count;
    const auto finish = [&] {
      left_centroids = left.bounds();
      right_centroids = right.bounds();
      return static_cast<std::uint32_t>(begin - references_.data());
    };
    while (true) {
      while (true) {
        if (begin == end) return finish();
        if (!goes_left(*begin)) break;
        ++begin;
      }
      --end;
      while (true) {
        if (begin == end) return finish();
        if (goes_left(*end)) break;
        --end;
      }
      std::swap(*begin, *end);
      ++begin;
    }
  }

  void build_node(std::uint32_t node, std::uint32_t first, std::uint32_t count, const Bounds3& bounds,
                  const Bounds3& centroids, std::uint32_t depth) {
    if (count == 1 || count <= options_.cut_size) return make_leaf(node, first, count, bounds);
    // A range whose leaf costs no more than a node's visit is a leaf whatever plane the bins
    // would offer: a split costs the visit plus a share of its children's tests, never less
    // (where the box has an area). bvh:width=8's ranges of one block (four) and HMQ's of
    // seven triangles or fewer end here without being binned.
    const float leaf_cost = options_.intersection_cost * blocks(count);
    if (count <= options_.max_leaf_size && leaf_cost <= options_.traversal_cost && options_.intersection_cost >= 0.0f &&
        half_area(bounds) > 0.0f) {
      return make_leaf(node, first, count, bounds);
    }
    glm::vec3 scale;
    for (int axis = 0; axis < 3; ++axis) {
      const float extent = centroids.upper[axis] - centroids.lower[axis];
      scale[axis] = extent > 0.0f ? float(options_.bins) * (1.0f - 1e-6f) / extent : 0.0f;
    }
    Split split;
    if (depth < kFreeDepth) {
      Binning binning(options_.bins);
      bin_range(first, count, centroids, scale, binning);
      split = best_split(binning, centroids);
    }
    const float split_cost = options_.traversal_cost + options_.intersection_cost * split.cost / half_area(bounds);
    if (count <= options_.max_leaf_size && (split.axis < 0 || leaf_cost <= split_cost)) {
      // split.axis < 0 with few primitives: coincident centroids, a leaf is best.
      return make_leaf(node, first, count, bounds);
    }

    std::uint32_t middle;
    Bounds3 left_bounds, right_bounds, left_centroids, right_centroids;
    if (split.axis >= 0) {
      middle = partition_range(first, count, split.axis, split.bin, centroids, scale, left_centroids, right_centroids);
      left_bounds = split.left_bounds;
      right_bounds = split.right_bounds;
    } else {
      // No plane separates the centroids (or the tree is too deep): halve the list.
      middle = first + count / 2;
      left_bounds = bounds_of_range(first, middle - first);
      right_bounds = bounds_of_range(middle, first + count - middle);
      left_centroids = centroid_bounds(first, middle - first);
      right_centroids = centroid_bounds(middle, first + count - middle);
    }

    const std::uint32_t left = next_node_.fetch_add(2);
    new (&slots_[node]) BuildNode{bounds, left, left + 1, 0, 0};
    const std::uint32_t left_count = middle - first, right_count = first + count - middle;
    if (count >= kParallelSubtreeThreshold) {
      tbb::task_group group;
      group.run([&] { build_node(left, first, left_count, left_bounds, left_centroids, depth + 1); });
      build_node(left + 1, middle, right_count, right_bounds, right_centroids, depth + 1);
      group.wait();
    } else {
      build_node(left, first, left_count, left_bounds, left_centroids, depth + 1);
      build_node(left + 1, middle, right_count, right_bounds, right_centroids, depth + 1);
    }
  }

  SahOptions options_;
  int block_shift_ = std::has_single_bit(options_.block_size) ? std::countr_zero(options_.block_size) : -1;
  BuildTree& tree_;
  LargeArray<SahReference> references_;
  // Slots for the worst case, 2n - 1 nodes, as raw memory: a tree takes about one node per two
  // primitives or fewer, and the pages no node is written to are never touched (a first touch
  // of a page costs a VM dearly: it was a third of a build's time). The tree takes them over
  // at the end (BuildNodes).
  struct FreeSlots {
    void operator()(BuildNode* slots) const { std::free(slots); }
  };
  std::unique_ptr<BuildNode[], FreeSlots> slots_;
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
  checked_uint32(2 * std::uint64_t(primitive_bounds.size()),
                 "SAH build: twice the primitive count; build in chunks (build.chunk_triangles)");
  LargeArray<SahReference> references(primitive_bounds.size());
  tbb::parallel_for(std::size_t{0}, primitive_bounds.size(), [&](std::size_t i) {
    references[i] = {primitive_bounds[i], static_cast<std::uint32_t>(i), 0};
  });
  return build_sah_tree(std::move(references), options);
}

BuildTree build_sah_tree(LargeArray<SahReference> references, const SahOptions& options) {
  if (references.empty()) throw std::invalid_argument("SAH builder: no primitives");
  // Node and primitive ids are 32-bit, and a tree of n leaves has 2n - 1 nodes.
  checked_uint32(2 * std::uint64_t(references.size()),
                 "SAH build: twice the primitive count; build in chunks (build.chunk_triangles)");
  if (options.block_size < 1) throw std::invalid_argument("SAH builder: block size 0");
  if (options.max_leaf_size < 1 || options.max_leaf_size > 16) {
    throw std::invalid_argument(fmt::format("SAH builder: max leaf size {} is outside 1..16", options.max_leaf_size));
  }
  if (options.bins < 2 || options.bins > kMaxBins) {
    throw std::invalid_argument(fmt::format("SAH builder: {} bins is outside 2..{}", options.bins, kMaxBins));
  }
  BuildTree tree;
  Builder builder(std::move(references), options, tree);
  builder.build();
  return tree;
}

}  // namespace wavetrace
