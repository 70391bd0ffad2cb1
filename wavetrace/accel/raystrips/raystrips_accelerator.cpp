// Ray-Strips build (SAH cut into sub-meshes, stripify, top SAH BVH over the strips, encode)
// and traversal: single rays through the top BVH and each strip, and 2x2 packets for
// coherent rays (§5.3).
#include "wavetrace/accel/raystrips/raystrips_accelerator.hpp"
#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2

#include <algorithm>
#include <chrono>
#include <limits>
#include <numeric>
#include <stdexcept>
#include <type_traits>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/bvh/bvh_walk.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/raystrips/strip_check.hpp"
#include "wavetrace/accel/bvh/leaf_query.hpp"
#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/accel/bvh/quantized_wide_tree.hpp"
#include "wavetrace/accel/bvh/quantized_wide_walk.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/accel/raystrips/strip_encode.hpp"
#include "wavetrace/accel/raystrips/strip_packet.hpp"
#include "wavetrace/accel/raystrips/strip_traversal.hpp"
#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"

namespace wavetrace {
namespace {

using Clock = std::chrono::steady_clock;
using ray_strip::StripView;

double seconds_since(Clock::time_point start) { return std::chrono::duration<double>(Clock::now() - start).count(); }

void check_options(const RayStripsOptions& options) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument("raystrips: " + message);
  };
  require(options.submesh_triangles >= 2 && options.submesh_triangles <= ray_strip::kMaxTriangles,
          fmt::format("submesh_triangles = {}: must be 0 (by width) or 2 .. {}", options.submesh_triangles,
                      ray_strip::kMaxTriangles));
  require(options.strips_per_leaf >= 1 && options.strips_per_leaf <= 16,
          fmt::format("strips_per_leaf = {}: must be 0 (by width) or 1 .. 16", options.strips_per_leaf));
  require(options.run_triangles >= 2 && options.run_triangles <= 64,
          fmt::format("run_triangles = {}: must be 2 .. 64", options.run_triangles));
  require(options.packet_min_active >= 1 && options.packet_min_active <= kPacketRays,
          fmt::format("packet_min_active = {}: must be 1 .. {}", options.packet_min_active, kPacketRays));
  require(options.width == 2 || options.width == 8,
          fmt::format("width = {}: must be 2 (binary top) or 8 (quantized 8-wide top)", options.width));
#if !(WAVETRACE_AVX2 && WAVETRACE_FMA)
  require(options.width == 2, "width = 8 traverses in AVX2 and FMA lanes: build with WAVETRACE_ARCH=x86-64-v3 or newer");
#endif
}

// The sub-meshes: ranges of the SAH tree's primitive order under the highest nodes that
// hold at most `threshold` triangles.
std::vector<std::pair<std::uint32_t, std::uint32_t>> cut_submeshes(const BuildTree& tree, std::uint32_t threshold) {
  // Subtree ranges, children before parents (the builder partitions in place, so a
  // subtree's primitives are one contiguous range).
  std::vector<std::pair<std::uint32_t, std::uint32_t>> range(tree.nodes.size());
  std::vector<std::uint32_t> order;
  order.reserve(tree.nodes.size());
  std::vector<std::uint32_t> stack = {0};
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    order.push_back(node);
    if (!tree.nodes[node].leaf()) {
      stack.push_back(tree.nodes[node].left);
      stack.push_back(tree.nodes[node].right);
    }
  }
  for (auto it = order.rbegin(); it != order.rend(); ++it) {
    const BuildNode& node = tree.nodes[*it];
    if (node.leaf()) {
      range[*it] = {node.first, node.count};
    } else {
      const auto& left = range[node.left];
      const auto& right = range[node.right];
      range[*it] = {std::min(left.first, right.first), left.second + right.second};
    }
  }
  std::vector<std::pair<std::uint32_t, std::uint32_t>> submeshes;
  stack = {0};
  while (!stack.empty()) {
    const std::uint32_t node = stack.back();
    stack.pop_back();
    if (range[node].second <= threshold || tree.nodes[node].leaf()) {
      submeshes.push_back(range[node]);
    } else {
      stack.push_back(tree.nodes[node].right);
      stack.push_back(tree.nodes[node].left);
    }
  }
  return submeshes;
}

// The strips of one top leaf read in order, `count` of them (binary top) or up to `end`
// (wide top): each one's header reported to the probe and, in plain walks, the first lines of
// its vertices asked for as it is read. A class, not a loop taking a lambda, so that the
// AVX-512 walk inlines it (a lambda is not of that target).
template <typename Until>
class LeafStrips {
 public:
  LeafStrips(const std::byte* data, Until until) : data_(data), until_(until) {}

  bool done() const {
    if constexpr (std::is_integral_v<Until>) {
      return read_ == until_;
    } else {
      return data_ >= until_;
    }
  }

  template <typename Probe>
  [[gnu::always_inline]] ray_strip::StripView next(const glm::vec3* positions, Probe& probe) {
    probe.read(data_, ray_strip::kHeaderBytes);
    const ray_strip::StripView strip(data_);
    if constexpr (!Probe::kRecords) {
      const char* first_vertex = reinterpret_cast<const char*>(positions + strip.vertex_base());
      _mm_prefetch(first_vertex, _MM_HINT_T0);
      _mm_prefetch(first_vertex + 64, _MM_HINT_T0);
      _mm_prefetch(first_vertex + 128, _MM_HINT_T0);
    }
    data_ += strip.size();
    ++read_;
    return strip;
  }

 private:
  const std::byte* data_;
  Until until_;
  std::uint32_t read_ = 0;
};

// What a raystrips world saves besides its arrays, `PREFIX` + "raystrips.state" (184 bytes):
//   offset  size  field
//        0     4  run_triangles, uint32 (traversal's span size)
//        4     4  packet_min_active, uint32
//        8     4  packets, uint32 (0 or 1)
//       12     4  stripifier, uint32 (0: dual_path, 1: openmesh, 2: longest_of_three; build notes only)
//       16     4  submesh_triangles, uint32 (build notes only)
//       20     4  strips_per_leaf, uint32 (build notes only)
//       24     4  width of the top, uint32 (2 or 8)
//       28     4  zero
//       32    24  the 8-wide top's root frame: float lower x, y, z, upper x, y, z (width 2: unused)
//       56   128  the build's statistics, 16 fields of 8 bytes in RayStripStats' order: strips
//                 (uint64), 11 doubles (mean triangles .. encode seconds), 4 byte counts (uint64)
// and the triangle count and build report in "common" (section_archive.hpp). Arrays:
// "raystrips.nodes" (width 2: BvhNode, bvh_node.hpp; a leaf's first is a word offset into the
// strips), "raystrips.wide_nodes" (width 8: QuantizedWideNode, a leaf child's reference is its
// number) and "raystrips.leaf_words" (width 8: uint32, leaf n's strips are the words
// [leaf_words[n], leaf_words[n + 1]) of the strips; one entry more than leaves), the unused
// ones empty; "raystrips.strips" (bytes, ray_strip_format.hpp), "raystrips.positions" (float x, y, z).
struct RayStripsSavedOptions {
  std::uint32_t run_triangles, packet_min_active, packets, stripifier, submesh_triangles, strips_per_leaf, width, zero;
};
// 5: no tree under 15 triangles; 4: 8-bit indices, no tree under 7 triangles; 3: 8-bit split
// planes; 2: the width 8 top
constexpr std::uint32_t kRayStripsSavedVersion = 5;

class RayStripsAccelerator final : public ProbedAccelerator<RayStripsAccelerator> {
  friend class ProbedAccelerator<RayStripsAccelerator>;

 public:
  explicit RayStripsAccelerator(const SectionLoader& loader) {
    loader.expect_kind("raystrips", kRayStripsSavedVersion);
    SectionLoader in = loader;
    archive(*this, in);
  }

  template <typename Archive>
  static void archive(auto& self, Archive& a) {
    struct State {
      RayStripsSavedOptions options;
      Bounds3 root;
      RayStripStats stats;
    };
    static_assert(sizeof(State) == 184);
    State state{{self.options_.run_triangles, self.options_.packet_min_active, self.options_.packets ? 1u : 0u,
                 static_cast<std::uint32_t>(self.options_.stripifier), self.options_.submesh_triangles,
                 self.options_.strips_per_leaf, self.options_.width, 0},
                self.root_,
                self.stats_};
    a.value("raystrips.state", state);
    a.array("raystrips.nodes", self.nodes_);
    a.array("raystrips.wide_nodes", self.wide_nodes_);
    a.array("raystrips.leaf_words", self.leaf_words_);
    a.array("raystrips.strips", self.strip_bytes_);
    a.array("raystrips.positions", self.positions_);
    archive_common_state(a, self.triangles_, self.build_);
    if constexpr (Archive::kLoading) {
      self.options_.run_triangles = state.options.run_triangles;
      self.options_.packet_min_active = state.options.packet_min_active;
      self.options_.packets = state.options.packets != 0;
      self.options_.stripifier = static_cast<StripifierKind>(state.options.stripifier);
      self.options_.submesh_triangles = state.options.submesh_triangles;
      self.options_.strips_per_leaf = state.options.strips_per_leaf;
      self.options_.width = state.options.width;
      self.root_ = state.root;
      self.stats_ = state.stats;
      if (state.options.width != 2 && state.options.width != 8) a.fail("raystrips.state", "holds a top width other than 2 or 8");
      if (state.options.stripifier > static_cast<std::uint32_t>(StripifierKind::longest_of_three)) {
        a.fail("raystrips.state", "names a stripifier this version does not know");
      }
      if (state.options.width == 2 && self.nodes_.empty()) a.fail("raystrips.nodes", "is empty: no raystrips structure was saved");
      // Every top and every strip a traversal reads is checked (tree_check.hpp, strip_check.hpp).
      const std::span<const std::byte> strip_bytes(self.strip_bytes_.data(), self.strip_bytes_.size());
      // The strips a leaf's traversal reads from byte `at`: `count` of them (binary top), or
      // those starting before byte `end` (8-wide top, count kUntilEnd).
      constexpr std::uint64_t kUntilEnd = ~std::uint64_t{0};
      const auto check_strips = [&](std::uint64_t at, std::uint64_t count, std::uint64_t end) {
        std::uint64_t s = 0;
        for (; s < count && at < end; ++s) {
          std::size_t size = 0;
          const auto problem = ray_strip::strip_problem(strip_bytes, at, self.positions_.size(), self.triangles_, size);
          if (problem) a.fail("raystrips.strips", *problem);
          at += size;
        }
        if (count != kUntilEnd && s < count) a.fail("raystrips.nodes", "has a leaf of more strips than follow it");
      };
      if (state.options.width == 2) {
        check_tree(std::span<const BvhNode>(self.nodes_.data(), self.nodes_.size()), a, "raystrips.nodes",
                   [&](const BvhNode& leaf) {
                     check_strips(std::uint64_t(leaf.first) * 4, leaf.triangle_count(), strip_bytes.size());
                   });
      }
      if (state.options.width == 8 && (self.wide_nodes_.empty() || self.leaf_words_.size() < 2)) {
        a.fail("raystrips.wide_nodes", "is empty: no raystrips structure was saved");
      }
      // Leaf l's strips are the words [leaf_words[l], leaf_words[l + 1]) of the strip bytes.
      if (state.options.width == 8) {
        check_tree(std::span<const QuantizedWideNode>(self.wide_nodes_.data(), self.wide_nodes_.size()), a,
                   "raystrips.wide_nodes", [&](std::uint32_t leaf, std::uint8_t) {
                     if (std::uint64_t(leaf) + 1 >= self.leaf_words_.size()) {
                       a.fail("raystrips.wide_nodes", "has a leaf that does not exist");
                     }
                   });
        for (std::size_t l = 0; l + 1 < self.leaf_words_.size(); ++l) {
          if (self.leaf_words_[l] > self.leaf_words_[l + 1] ||
              std::uint64_t(self.leaf_words_[l + 1]) * 4 > self.strip_bytes_.size()) {
            a.fail("raystrips.leaf_words", "names strips out of order or past the strip bytes");
          }
          check_strips(std::uint64_t(self.leaf_words_[l]) * 4, kUntilEnd, std::uint64_t(self.leaf_words_[l + 1]) * 4);
        }
      }
      if (state.options.run_triangles < 2 || state.options.run_triangles > 64 || state.options.packet_min_active < 1 ||
          state.options.packet_min_active > kPacketRays) {
        a.fail("raystrips.state", "holds traversal settings out of range");
      }
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    out.add_value(prefix + "kind", saved_kind("raystrips", kRayStripsSavedVersion));
    SectionSaver saver(out, prefix);
    archive(*this, saver);
  }

  RayStripsAccelerator(const TriangleMesh& mesh, const RayStripsOptions& requested) : options_(requested.resolved()) {
    const RayStripsOptions& options = options_;
    check_options(options);
    if (mesh.triangle_count() == 0) throw std::invalid_argument("raystrips: the mesh has no triangles");
    triangles_ = mesh.triangle_count();
    const auto start = Clock::now();
    PhaseClock clock;

    // 1. SAH cut into sub-meshes.
    LargeArray<Bounds3> triangle_bounds(mesh.triangle_count());
    tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
      Bounds3 bounds;
      for (int k = 0; k < 3; ++k) bounds.extend(mesh.positions[mesh.triangles[t][k]]);
      triangle_bounds[t] = bounds;
    });
    clock.lap(build_.phases, "bounds");
    SahOptions sah;
    sah.max_leaf_size = 4;
    sah.bins = options.bins;
    sah.cut_size = options.submesh_triangles;
    BuildTree cut_tree = build_sah_tree(triangle_bounds, sah);
    sah.cut_size = 0;
    std::size_t peak = cut_tree.peak_bytes + triangle_bounds.size() * sizeof(Bounds3);
    const auto submeshes = cut_submeshes(cut_tree, options.submesh_triangles);
    // The tree stops at the sub-meshes: each one's triangles go in Morton order of their
    // centroids in its box, the spatial order the SAH's levels below gave them (the stripifier
    // starts its strips in triangle order, and strips came out 4% shorter in build order).
    tbb::parallel_for(std::size_t{0}, submeshes.size(), [&](std::size_t s) {
      const auto [first, count] = submeshes[s];
      std::uint32_t* order = cut_tree.primitive_order.data() + first;
      Bounds3 box;
      for (std::uint32_t k = 0; k < count; ++k) box.extend(triangle_bounds[order[k]].center());
      const glm::vec3 extent = glm::max(box.extent(), glm::vec3(std::numeric_limits<float>::min()));
      std::vector<std::pair<std::uint64_t, std::uint32_t>> keyed(count);
      for (std::uint32_t k = 0; k < count; ++k) {
        const glm::vec3 cell = (triangle_bounds[order[k]].center() - box.lower) / extent * 1023.0f;
        keyed[k] = {morton3d_encode(std::uint64_t(cell.x), std::uint64_t(cell.y), std::uint64_t(cell.z)), order[k]};
      }
      std::sort(keyed.begin(), keyed.end());
      for (std::uint32_t k = 0; k < count; ++k) order[k] = keyed[k].second;
    });
    triangle_bounds = {};
    clock.lap(build_.phases, "sah");
    stats_.sah_seconds = seconds_since(start);

    // 2. Stripify each sub-mesh.
    const auto stripify_start = Clock::now();
    std::vector<std::vector<TriangleStrip>> per_submesh(submeshes.size());
    tbb::parallel_for(std::size_t{0}, submeshes.size(), [&](std::size_t s) {
      const auto [first, count] = submeshes[s];
      per_submesh[s] = stripify(mesh, std::span(cut_tree.primitive_order.data() + first, count), options.stripifier,
                                ray_strip::kMaxTriangles);
    });
    std::vector<TriangleStrip> strips;
    for (auto& group : per_submesh) {
      for (auto& strip : group) strips.push_back(std::move(strip));
    }
    per_submesh = {};
    clock.lap(build_.phases, "stripify");
    stats_.stripify_seconds = seconds_since(stripify_start);

    // 3. The top BVH over the strips, and the strips in its leaf order.
    const auto encode_start = Clock::now();
    LargeArray<Bounds3> strip_bounds(strips.size());
    tbb::parallel_for(std::size_t{0}, strips.size(), [&](std::size_t s) {
      Bounds3 bounds;
      for (const std::uint32_t vertex : strips[s].vertices) bounds.extend(mesh.positions[vertex]);
      strip_bounds[s] = bounds;
    });
    sah.max_leaf_size = options.strips_per_leaf;
    const BuildTree top = build_sah_tree(strip_bounds, sah);
    peak = std::max(peak, top.peak_bytes + strip_bounds.size() * sizeof(Bounds3));
    strip_bounds = {};
    // The strips in storage order: the top's leaves in the order its layout references them.
    // Each strip's frame is its top leaf's box as traversal sees it: the float box of a binary
    // leaf, the decoded box of a wide one.
    std::vector<std::uint32_t> strip_order;
    std::vector<Bounds3> strip_frame;
    strip_order.reserve(strips.size());
    strip_frame.reserve(strips.size());
    auto store_leaf = [&](const BuildNode& leaf, const Bounds3& frame) {
      for (std::uint32_t k = 0; k < leaf.count; ++k) {
        strip_order.push_back(top.primitive_order[leaf.first + k]);
        strip_frame.push_back(frame);
      }
    };
    const std::vector<std::uint32_t> node_order_list = node_order(top, NodeLayout::depth_first);
    std::vector<std::size_t> leaf_first_strip;  // width 8: each leaf's first place in strip_order
    QuantizedWideTree wide;
    if (options.width == 8) {
      wide = build_quantized_wide_tree(top, [&](const BuildNode& leaf, const Bounds3& box) {
        leaf_first_strip.push_back(strip_order.size());
        store_leaf(leaf, box);
        return 1u;  // references number the leaves
      });
    } else {
      for (const std::uint32_t built : node_order_list) {
        if (top.nodes[built].leaf()) store_leaf(top.nodes[built], top.nodes[built].bounds);
      }
    }
    clock.lap(build_.phases, "top");
    // Vertices renumbered by first use in storage order, so a strip's indices lie close together.
    std::vector<std::uint32_t> vertex_id(mesh.vertex_count(), kNoTriangle);
    std::uint32_t next_vertex = 0;
    for (const std::uint32_t s : strip_order) {
      for (const std::uint32_t vertex : strips[s].vertices) {
        if (vertex_id[vertex] == kNoTriangle) vertex_id[vertex] = next_vertex++;
      }
    }
    LargeArray<glm::vec3> positions(next_vertex);
    for (std::uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      if (vertex_id[v] != kNoTriangle) positions[vertex_id[v]] = mesh.positions[v];
    }

    clock.lap(build_.phases, "vertices");
    std::vector<StripEncoding> encodings(strips.size());
    std::vector<std::size_t> offset(strips.size() + 1, 0);
    for (std::size_t i = 0; i < strip_order.size(); ++i) {
      const TriangleStrip& strip = strips[strip_order[i]];
      encodings[i] = choose_encoding(strip, vertex_id);
      offset[i + 1] = offset[i] + encodings[i].size(static_cast<std::uint32_t>(strip.triangles.size()));
    }
    if (offset.back() / 4 >= BvhNode::kLeafFlag) {
      throw std::length_error("raystrips: the strips need more than 8 GiB, beyond the top BVH's 31-bit word offsets");
    }
    LargeArray<std::byte> strip_bytes(offset.back());
    tbb::parallel_for(std::size_t{0}, strip_order.size(), [&](std::size_t i) {
      encode_strip(strips[strip_order[i]], encodings[i], vertex_id, positions, mesh, strip_frame[i],
                   strip_bytes.data() + offset[i]);
    });

    if (options.width == 8) {
      // Leaf n's strips run from its first strip's word to the next leaf's.
      LargeArray<std::uint32_t> leaf_words(leaf_first_strip.size() + 1);
      for (std::size_t n = 0; n < leaf_first_strip.size(); ++n) leaf_words[n] = static_cast<std::uint32_t>(offset[leaf_first_strip[n]] / 4);
      leaf_words.back() = static_cast<std::uint32_t>(offset.back() / 4);
      root_ = wide.root_frame;
      wide_nodes_ = StoredArray<QuantizedWideNode>(std::move(wide.nodes));
      leaf_words_ = StoredArray<std::uint32_t>(std::move(leaf_words));
    } else {
      // Flatten the top BVH: a leaf's `first` is the word offset of its first strip.
      std::size_t next_strip = 0;
      LargeArray<BvhNode> nodes;
      flatten_tree(top, node_order_list, nodes, [&](const BuildNode& leaf) {
        const std::uint32_t first = checked_uint32(
            offset[next_strip] / 4, "raystrips strip offset in 4-byte words; build in smaller chunks (build.chunk_triangles)");
        next_strip += leaf.count;
        return first;
      });
      nodes_ = StoredArray<BvhNode>(std::move(nodes));
    }
    strip_bytes_ = StoredArray<std::byte>(std::move(strip_bytes));
    positions_ = StoredArray<glm::vec3>(std::move(positions));
    clock.lap(build_.phases, "encode");
    stats_.encode_seconds = seconds_since(encode_start);
    collect_stats(strips, encodings, strip_order);
    build_.seconds = seconds_since(start);
    const std::size_t strips_held = strips.capacity() * sizeof(TriangleStrip) + stats_.strip_vectors_bytes;
    build_.peak_bytes = std::max(peak, strips_held + vertex_id.size() * 4) + memory().total();
  }

  std::string name() const override { return "raystrips"; }

  void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    if (!options_.packets) return intersect_closest(rays, hits, range);
#if WAVETRACE_AVX2 && WAVETRACE_FMA
    if (options_.width == 8) return intersect_coherent_wide(rays, hits, range);
#endif
    walk_with(kernel_isa(), [&]<KernelIsa>() {
      PacketTraversal packets{nodes_.data(), strip_bytes_.data(), positions_.data(), options_.run_triangles,
                              options_.packet_min_active};
      for (std::uint32_t begin = range.begin; begin < range.end; begin += kPacketRays) {
        const std::uint32_t end = std::min(begin + kPacketRays, range.end);
        packets.trace(rays, hits, {begin, end}, [&](const StripRay& ray, std::uint32_t i) { write_hit(ray, hits, i); });
      }
    });
  }
  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = nodes_.size() * sizeof(BvhNode) + wide_nodes_.size() * sizeof(QuantizedWideNode) +
                       leaf_words_.size() * sizeof(std::uint32_t) + stats_.header_and_tree_bytes;
    report.geometry = positions_.size() * sizeof(glm::vec3) + stats_.index_bytes;
    report.other = stats_.record_bytes;
    return report;
  }

  BuildReport build() const override { return build_; }

  std::string build_notes() const override {
    const RayStripStats& s = stats_;
    return fmt::format(
        "{} strips ({}), {:.1f} triangles per strip ({:.1f} with turn repeats), {:.2f} strips per top leaf, "
        "{:.2f}% of triangles in strips of one, {:.1f}% turn repeats, {:.1f}% 8-bit and {:.1f}% 16-bit indices, "
        "{:.1f}% short records; "
        "build: SAH cut {:.3f} s, stripify {:.3f} s, top BVH + encode {:.3f} s",
        s.strips, to_string(options_.stripifier), s.mean_triangles, s.mean_strip_triangles, s.strips_per_leaf,
        100.0 * s.single_share, 100.0 * s.repeat_share, 100.0 * s.byte_index_share, 100.0 * s.short_index_share,
        100.0 * s.short_record_share,
        s.sah_seconds, s.stripify_seconds, s.encode_seconds);
  }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    return {nodes_.bytes(), wide_nodes_.bytes(), leaf_words_.bytes(), strip_bytes_.bytes(), positions_.bytes()};
  }

 private:
  struct RayStripStats {
    std::size_t strips = 0;
    double mean_triangles = 0, mean_strip_triangles = 0, strips_per_leaf = 0;
    double single_share = 0, repeat_share = 0, byte_index_share = 0, short_index_share = 0, short_record_share = 0;
    double sah_seconds = 0, stripify_seconds = 0, encode_seconds = 0;
    std::size_t header_and_tree_bytes = 0, index_bytes = 0, record_bytes = 0, strip_vectors_bytes = 0;
  };

  void collect_stats(const std::vector<TriangleStrip>& strips, const std::vector<StripEncoding>& encodings,
                     const std::vector<std::uint32_t>& strip_order) {
    RayStripStats& s = stats_;
    s.strips = strips.size();
    std::size_t distinct = 0, listed = 0, in_singles = 0, byte_indices = 0, short_indices = 0, short_records = 0, leaves = 0;
    for (std::size_t i = 0; i < strip_order.size(); ++i) {
      const TriangleStrip& strip = strips[strip_order[i]];
      const auto n = static_cast<std::uint32_t>(strip.triangles.size());
      std::size_t real = 0;
      for (std::size_t k = 0; k < n; ++k) {
        const std::uint32_t t = strip.triangles[k];
        real += t != kNoTriangle && (k == 0 || strip.triangles[k - 1] != t);
      }
      distinct += real;
      listed += n;
      if (real == 1) ++in_singles;
      byte_indices += (encodings[i].widths & ray_strip::kByteIndices) != 0;
      short_indices += (encodings[i].widths & ray_strip::kShortIndices) != 0;
      short_records += (encodings[i].widths & ray_strip::kShortRecords) != 0;
      const ray_strip::StripLayout layout = ray_strip::strip_layout(n, encodings[i].widths);
      s.header_and_tree_bytes += layout.indices;
      s.index_bytes += layout.records - layout.indices;
      s.record_bytes += layout.size - layout.records;
      s.strip_vectors_bytes += (strip.vertices.capacity() + strip.triangles.capacity()) * 4;
    }
    for (const BvhNode& node : nodes_) leaves += node.leaf();
    if (!leaf_words_.empty()) leaves = leaf_words_.size() - 1;
    s.mean_triangles = double(distinct) / double(strips.size());
    s.mean_strip_triangles = double(listed) / double(strips.size());
    s.strips_per_leaf = double(strips.size()) / double(leaves);
    s.single_share = double(in_singles) / double(distinct);
    s.repeat_share = double(listed - distinct) / double(listed);
    s.byte_index_share = double(byte_indices) / double(strips.size());
    s.short_index_share = double(short_indices) / double(strips.size());
    s.short_record_share = double(short_records) / double(strips.size());
  }

  // The hit in the mesh's numbering: triangle id and barycentrics in its corner order.
  // With kSurface (closest-hit queries) also the hit's point and normal.
  template <bool kSurface = true, typename Probe = NullProbe>
  void write_hit(const StripRay& ray, HitBatch& hits, std::uint32_t i, Probe* probe = nullptr) const {
    if (!ray.found()) return hits.set_miss(i);
    const StripView strip(ray.hit.strip);
    if constexpr (Probe::kRecords) probe->read(strip.record_address(ray.hit.triangle), 4);
    const std::uint32_t corners = strip.corners(ray.hit.triangle);
    hits.set_hit(i, ray.hit.t, strip.triangle(ray.hit.triangle), ray.hit.weights[corners / 3],
                 ray.hit.weights[corners % 3]);
    if constexpr (!kSurface) return;
    const glm::vec3 strip_corner[3] = {positions_[strip.vertex(ray.hit.triangle)],
                                       positions_[strip.vertex(ray.hit.triangle + 1)],
                                       positions_[strip.vertex(ray.hit.triangle + 2)]};
    set_surface_from_strip(hits, i, strip_corner, corners);
  }

  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
#if WAVETRACE_AVX2 && WAVETRACE_FMA
    if (options_.width == 8) return traverse_wide<kAnyHit, kIsa>(rays, hits, range, probe);
#endif
    const glm::vec3* positions = positions_.data();
    for_each_ray(rays, hits, range, [&](const SingleRay& single, std::uint32_t i) {
      StripRay ray(single);
      walk_bvh(nodes_.data(), ray.box, ray.tmin, ray.tmax, probe, [&](const BvhNode& leaf) {
        float near, far;
        if (!clip_to_box(ray.box, leaf.lower, leaf.upper, ray.tmin, pruning_distance(ray.tmax), near, far)) return false;
        const std::byte* strip_data = strip_bytes_.data() + std::size_t(leaf.first) * 4;
        return trace_strips<kAnyHit>(ray, Bounds3{leaf.lower, leaf.upper}, strip_data, leaf.triangle_count(), near, far,
                                     positions, probe);
      });
      write_hit<!kAnyHit>(ray, hits, i, &probe);
    });
  }

#if WAVETRACE_AVX2 && WAVETRACE_FMA
  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse_wide(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    const glm::vec3* positions = positions_.data();
    const std::uint32_t* leaf_words = leaf_words_.data();
    QuantizedWideStack stack;
    for_each_ray(rays, hits, range, [&](const SingleRay& single, std::uint32_t i) {
      StripRay ray(single);
      walk_quantized_wide<kIsa>(wide_nodes_.data(), root_, single, ray.tmax, probe, stack, [&](std::uint32_t leaf, const Bounds3& box) {
        float near, far;
        if (!clip_to_box(ray.box, box.lower, box.upper, ray.tmin, pruning_distance(ray.tmax), near, far)) return false;
        probe.read(leaf_words + leaf, 2 * sizeof(std::uint32_t));
        const std::byte* strip_data = strip_bytes_.data() + std::size_t(leaf_words[leaf]) * 4;
        const std::byte* end = strip_bytes_.data() + std::size_t(leaf_words[leaf + 1]) * 4;
        return trace_strips<kAnyHit, kIsa>(ray, box, strip_data, end, near, far, positions, probe);
      }, [&](std::uint32_t leaf) { return strip_bytes_.data() + std::size_t(leaf_words[leaf]) * 4; });
      write_hit<!kAnyHit>(ray, hits, i, &probe);
    });
  }
#endif

#if WAVETRACE_AVX2 && WAVETRACE_FMA
  // Camera rays eight at a time through the wide top (walk_quantized_wide_packet, as
  // hmq:width=8 walks them): each node decoded once a packet, each top leaf's strips traced by
  // every ray that reached it alone, so that each ray's hit is the single ray's.
  void intersect_coherent_wide(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    walk_with(kernel_isa(), [&]<KernelIsa kIsa>() {
      NullProbe probe;
      QuantizedWidePacketStack stack;
      const glm::vec3* positions = positions_.data();
      const std::uint32_t* leaf_words = leaf_words_.data();
      for (std::uint32_t begin = range.begin; begin < range.end; begin += kWidePacketRays) {
        const std::uint32_t end = std::min<std::uint32_t>(begin + kWidePacketRays, range.end);
        SingleRay packet[kWidePacketRays];
        for (std::uint32_t r = 0; r < kWidePacketRays; ++r) packet[r] = load_ray(rays, std::min(begin + r, end - 1));
        // Slots past `end` repeat the last ray and are never live.
        StripRay strip_ray[kWidePacketRays] = {StripRay(packet[0]), StripRay(packet[1]), StripRay(packet[2]),
                                               StripRay(packet[3]), StripRay(packet[4]), StripRay(packet[5]),
                                               StripRay(packet[6]), StripRay(packet[7])};
        float tmax[kWidePacketRays];
        unsigned live = 0;
        for (std::uint32_t r = 0; r < kWidePacketRays; ++r) {
          tmax[r] = strip_ray[r].tmax;
          if (begin + r < end && (rays.flags[begin + r] & ray_flags::alive)) live |= 1u << r;
        }
        if (live != 0) {
          walk_quantized_wide_packet<kIsa>(
              wide_nodes_.data(), root_, packet, live, tmax, probe, stack,
              [&](std::uint32_t leaf, const Bounds3& box, unsigned members) {
                const std::byte* strip_data = strip_bytes_.data() + std::size_t(leaf_words[leaf]) * 4;
                const std::byte* strips_end = strip_bytes_.data() + std::size_t(leaf_words[leaf + 1]) * 4;
                for (; members != 0; members &= members - 1) {
                  const int r = std::countr_zero(members);
                  StripRay& ray = strip_ray[r];
                  float near, far;
                  if (!clip_to_box(ray.box, box.lower, box.upper, ray.tmin, pruning_distance(ray.tmax), near, far)) {
                    continue;
                  }
                  trace_strips<false, kIsa>(ray, box, strip_data, strips_end, near, far, positions, probe);
                  tmax[r] = ray.tmax;
                }
              });
        }
        for (std::uint32_t i = begin; i < end; ++i) {
          if (live >> (i - begin) & 1u) {
            write_hit<true>(strip_ray[i - begin], hits, i);
          } else {
            hits.set_miss(i);
          }
        }
      }
    });
  }
#endif

  // The strips of one top leaf (whose box is `frame`), from `strip_data` on: `count` of them,
  // or (wide top) up to `end`. True when an any-hit query is answered.
  template <bool kAnyHit, KernelIsa kIsa = KernelIsa::baseline, typename Probe, typename Until>
  bool trace_strips(StripRay& ray, const Bounds3& frame, const std::byte* strip_data, Until until, float near,
                    float far, const glm::vec3* positions, Probe& probe) const {
#if WAVETRACE_SIXTEEN_LANES
    // Probes that record each read see the strips one at a time, in the order they are read.
    if constexpr (kIsa == KernelIsa::avx512 && !Probe::kRecords) {
      return trace_packed_strips<kAnyHit>(ray, frame, strip_data, until, near, far, positions, probe);
    }
#endif
    for (LeafStrips<Until> strips(strip_data, until); !strips.done();) {
      const StripView strip = strips.next(positions, probe);
      ray.traverse<kAnyHit>(strip, frame, positions, near, far, options_.run_triangles, probe);
      if (kAnyHit && ray.found()) return true;
    }
    return false;
  }

#if WAVETRACE_SIXTEEN_LANES
  // trace_strips in the AVX-512 walks: the short strips packed whole into sixteen lanes
  // (PackedStrips) and tested a pack at a time, the others walked one by one as before.
  template <bool kAnyHit, typename Probe, typename Until>
  [[WAVETRACE_AVX512_TARGET]] bool trace_packed_strips(StripRay& ray, const Bounds3& frame, const std::byte* strip_data,
                                                       Until until, float near, float far, const glm::vec3* positions,
                                                       Probe& probe) const {
    PackedStrips pack;
    for (LeafStrips<Until> strips(strip_data, until); !strips.done();) {
      const StripView strip = strips.next(positions, probe);
      const bool has_tree = ray_strip::has_tree(strip.triangles());
      // The packed strips are tested before a strip with a tree, not only when the next one
      // does not fit: an any-hit query answers with the first hit in strip order, as the
      // baseline walk does.
      if (!pack.empty() && (has_tree || !pack.fits(strip.triangles()))) {
        ray.test_packed<kAnyHit>(pack, positions);
        if (kAnyHit && ray.found()) return true;
        pack.clear();
      }
      if (has_tree) {
        ray.traverse<kAnyHit>(strip, frame, positions, near, far, options_.run_triangles, probe);
        if (kAnyHit && ray.found()) return true;
      } else {
        probe.read(strip.vertex_address(0), (strip.triangles() + 2) * strip.index_width());
        pack.add(strip);
      }
    }
    if (!pack.empty()) ray.test_packed<kAnyHit>(pack, positions);
    return kAnyHit && ray.found();
  }
#endif

  RayStripsOptions options_;
  StoredArray<BvhNode> nodes_;                      // width 2
  StoredArray<QuantizedWideNode> wide_nodes_;       // width 8
  StoredArray<std::uint32_t> leaf_words_;           // width 8
  Bounds3 root_;                                    // width 8: the root's frame
  StoredArray<std::byte> strip_bytes_;
  StoredArray<glm::vec3> positions_;
  RayStripStats stats_;
  std::size_t triangles_ = 0;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_raystrips_accelerator(const TriangleMesh& mesh, const RayStripsOptions& options) {
  return std::make_unique<RayStripsAccelerator>(mesh, options);
}

std::unique_ptr<Accelerator> load_raystrips_accelerator(const SectionLoader& loader) {
  return std::make_unique<RayStripsAccelerator>(loader);
}

}  // namespace wavetrace
