// `hmq:width=8`: HMQ's global grid and leaf records under quantized 8-wide nodes
// (accel/bvh/quantized_wide_node.hpp), the same top Ray-Strips' wide layout has. A leaf
// child's weight is its record's size in 2-byte units, so records need no offset table.
#include <algorithm>
#include <bit>
#include <chrono>
#include <span>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/accel/bvh/quantized_wide_tree.hpp"
#include "wavetrace/build_config.hpp"  // WAVETRACE_AVX2, WAVETRACE_FMA, WAVETRACE_BMI2
#include "wavetrace/accel/bvh/quantized_wide_walk.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/hmq/block_check.hpp"
#include "wavetrace/accel/hmq/hmq_accelerator.hpp"
#include "wavetrace/accel/hmq/leaf_hit.hpp"
#include "wavetrace/accel/hmq/snapped_tree.hpp"
#include "wavetrace/accel/probed_accelerator.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace {

#if WAVETRACE_AVX2 && WAVETRACE_FMA
namespace {

using namespace hmq;
// Leaf records start 2-byte aligned; a reference counts 2-byte units (at most 254 a record:
// 508 bytes, above the largest, 463: a 41-bit header, a 32-bit id base, 14 triangles over 42
// vertices of 3 x 25 bits, 31-bit id deltas and 3-bit corners).
constexpr std::size_t kUnit = 2;
constexpr std::size_t kSlackBytes = 8;  // read slack after the last record for unaligned 8-byte stream loads

// What an hmq:width=8 world saves besides its arrays, `PREFIX` + "hmq8.state" (112 bytes):
//   offset  size  field
//        0    56  the global grid, as in "hmq.state" (hmq_accelerator.cpp)
//       56    12  root frame lower, float x, y, z (the binary tree's root box)
//       68    12  root frame upper
//       80     8  hierarchy bytes (nodes and record padding)
//       88     8  geometry bytes of the leaf records (vertices and connectivity)
//       96     8  other bytes of the leaf records (triangle ids and corners)
//      104     4  children of all nodes (leaves and inner nodes below the root), uint32
//      108     4  leaves, uint32
// Arrays, either apart (the default):
//   "hmq8.nodes"  QuantizedWideNode[], node 0 the root, child_base a node index;
//   "hmq8.leaves" bytes, the leaf records, a leaf reference its offset in 2-byte units, 8
//                 bytes of slack at the end;
// or together (accel.hmq.leaves_beside_nodes), one array instead of the two:
//   "hmq8.tree"   64-byte units (element size 64): the root node at unit 0; each group of
//                 sibling nodes 64-byte aligned, followed by the leaf records of its nodes;
//                 child_base a unit index, a leaf reference the record's offset from the
//                 array's start in 2-byte units; zeros pad each group's start and the end
//                 (at least 8 bytes of slack after the last record). Units no node names
//                 are records or padding.
struct WideHmqSavedState {
  GlobalGrid grid;
  Bounds3 root;
  std::uint64_t hierarchy_bytes, geometry_bytes, other_bytes;
  std::uint32_t children, leaves;
};
static_assert(sizeof(WideHmqSavedState) == 112);
constexpr std::uint32_t kWideHmqSavedVersion = 2;  // 2: leaf records as one bit string

// A tree's leaf records, encoded in batches on every core and appended in the order the
// tree references its leaves: the bytes one encoder going leaf by leaf would append.
class LeafRecordWriter {
 public:
  LeafRecordWriter(const SnappedTree& snapped, std::size_t triangles) : snapped_(snapped) {
    // Reserved past the records' usual 7-8 bytes a triangle: grown by doubling, they were
    // copied and their pages touched twice over (pages reserved and never written are not resident).
    records_.reserve(triangles * 12 + kSlackBytes);
    pending_.reserve(kBatchLeaves);
  }

  void add(const BuildNode& leaf, const Bounds3& box) {
    pending_.push_back({&leaf, snap_outward(snapped_.grid, Box{box.lower, box.upper})});
    if (pending_.size() == kBatchLeaves) flush();
  }

  void flush() {
    PhaseClock clock;
    const std::size_t blocks = (pending_.size() + kBlockLeaves - 1) / kBlockLeaves;
    if (block_bytes_.size() < blocks) block_bytes_.resize(blocks);
    if (block_parts_.size() < blocks) block_parts_.resize(blocks);
    const std::size_t first_weight = weights_.size();
    weights_.resize(first_weight + pending_.size());
    tbb::parallel_for(std::size_t{0}, blocks, [&](std::size_t block) {
      LargeArray<std::byte>& out = block_bytes_[block];
      PartBytes& parts = block_parts_[block] = {};
      out.clear();
      const auto triangles_of = [&](std::size_t i) {
        const BuildNode& leaf = *pending_[i].leaf;
        return std::span<const std::uint32_t>(snapped_.tree.primitive_order.data() + leaf.first, leaf.count);
      };
      for (std::size_t i = block * kBlockLeaves, end = std::min(pending_.size(), i + kBlockLeaves); i < end; ++i) {
        if (i + kCornersAhead < end) prefetch_leaf_corners(snapped_.quantized, triangles_of(i + kCornersAhead));
        if (i + kGridPointsAhead < end) prefetch_leaf_grid_points(snapped_.quantized, triangles_of(i + kGridPointsAhead));
        const std::size_t at = out.size();
        const std::size_t identity = encode_leaf(snapped_.quantized, triangles_of(i), pending_[i].box, out) / 8;
        const std::size_t record = out.size() - at;
        out.resize(at + (record + kUnit - 1) / kUnit * kUnit, std::byte{0});
        parts.other += identity;
        parts.geometry += record - identity;
        parts.hierarchy += out.size() - at - record;
        const std::size_t weight = (out.size() - at) / kUnit;
        if (weight < 1 || weight > QuantizedWideNode::kMaxLeafWeight) {
          throw std::logic_error("quantized wide tree: a leaf weight outside 1 .. 254");
        }
        weights_[first_weight + i] = static_cast<std::uint8_t>(weight);
      }
    });
    for (std::size_t block = 0; block < blocks; ++block) {
      records_.insert(records_.end(), block_bytes_[block].begin(), block_bytes_[block].end());
      parts_.other += block_parts_[block].other;
      parts_.geometry += block_parts_[block].geometry;
      parts_.hierarchy += block_parts_[block].hierarchy;
    }
    pending_.clear();
    seconds_ += clock.lap();
  }

  const std::vector<std::uint8_t>& weights() const { return weights_; }
  const PartBytes& parts() const { return parts_; }
  double seconds() const { return seconds_; }
  // The batch's working memory: its leaves and the blocks' buffers.
  std::size_t batch_bytes() const {
    std::size_t bytes = pending_.capacity() * sizeof(PendingLeaf);
    for (const LargeArray<std::byte>& buffer : block_bytes_) bytes += buffer.capacity();
    return bytes;
  }
  LargeArray<std::byte> take_records() { return std::move(records_); }

 private:
  static constexpr std::size_t kBatchLeaves = 8192, kBlockLeaves = 256;
  // Leaves ahead of the one encoded whose corners, then grid points, are fetched.
  static constexpr std::size_t kCornersAhead = 4, kGridPointsAhead = 2;
  struct PendingLeaf {
    const BuildNode* leaf;
    GridBox box;
  };
  const SnappedTree& snapped_;
  LargeArray<std::byte> records_;
  std::vector<std::uint8_t> weights_;  // each record's size in units, in the references' order
  PartBytes parts_;
  std::vector<PendingLeaf> pending_;
  std::vector<LargeArray<std::byte>> block_bytes_;
  std::vector<PartBytes> block_parts_;
  double seconds_ = 0.0;
};

// Gives each node's leaf children their records' weights and its leaf_base the units before
// its first leaf: laid out with weights of 1, a node's leaf_base counted the leaves before it.
void set_leaf_weights(std::span<QuantizedWideNode> nodes, const std::vector<std::uint8_t>& weights) {
  std::vector<std::uint64_t> units_before(weights.size() + 1, 0);
  for (std::size_t leaf = 0; leaf < weights.size(); ++leaf) units_before[leaf + 1] = units_before[leaf] + weights[leaf];
  if (units_before.back() >= (std::uint64_t{1} << 31)) {
    throw std::length_error("quantized wide tree: the leaf references pass 2^31; build in smaller chunks (build.chunk_triangles)");
  }
  tbb::parallel_for(std::size_t{0}, nodes.size(), [&](std::size_t n) {
    QuantizedWideNode& node = nodes[n];
    std::size_t leaf = node.leaf_base;
    node.leaf_base = static_cast<std::uint32_t>(units_before[leaf]);
    for (std::uint8_t& meta : node.meta) {
      if (meta != 0 && meta != QuantizedWideNode::kInnerMeta) meta = weights[leaf++];
    }
  });
}

class WideHmqAccelerator final : public ProbedAccelerator<WideHmqAccelerator> {
  friend class ProbedAccelerator<WideHmqAccelerator>;

 public:
  WideHmqAccelerator(const TriangleMesh& mesh, const HmqOptions& options) {
    const auto start = std::chrono::steady_clock::now();
    const SnappedTree snapped = build_snapped_tree(mesh, options);
    build_.phases = snapped.phases;
    PhaseClock clock;
    grid_ = snapped.grid;
    // The tree is laid out with every leaf weighing 1, so a node's leaf_base counts the leaves
    // before it; the records are encoded in batches on every core as the leaves come, and the
    // nodes' weights and leaf_base set from their sizes once the tree is done. Encoding is
    // timed apart from the nodes (two clock reads a batch).
    LeafRecordWriter writer(snapped, mesh.triangle_count());
    QuantizedWideTree tree = build_quantized_wide_tree(snapped.tree, [&](const BuildNode& leaf, const Bounds3& box) {
      writer.add(leaf, box);
      return 1u;
    }, options.layout);
    writer.flush();
    set_leaf_weights(tree.nodes, writer.weights());
    build_.phases.add("nodes", clock.lap() - writer.seconds());
    build_.phases.add("leaves", writer.seconds());
    LargeArray<std::byte> leaves = writer.take_records();
    PartBytes parts = writer.parts();
    std::size_t encode_peak = tree.nodes.capacity() * sizeof(QuantizedWideNode) + leaves.size() +
                              writer.weights().size() + writer.batch_bytes();  // reserved, untouched: not held
    root_ = tree.root_frame;
    children_ = tree.children;
    node_count_ = tree.nodes.size();
    parts.hierarchy += node_count_ * sizeof(QuantizedWideNode);
    if (options.leaves_beside_nodes) {
      InterleavedWideTree together = interleave_leaf_records(tree.nodes, leaves, kUnit, kSlackBytes);
      encode_peak += together.units.size() * sizeof(QuantizedWideNode);
      parts.hierarchy += together.padding_bytes;
      nodes_ = StoredArray<QuantizedWideNode>(std::move(together.units));
      leaves_beside_ = true;
    } else {
      leaves.resize(leaves.size() + kSlackBytes, std::byte{0});
      parts.hierarchy += kSlackBytes;
      nodes_ = StoredArray<QuantizedWideNode>(std::move(tree.nodes));
      leaves_ = StoredArray<std::byte>(std::move(leaves));  // no copy: the reserve covers the slack
    }
    clock.lap(build_.phases, options.leaves_beside_nodes ? "interleave" : "store");
    parts_ = parts;
    triangles_ = mesh.triangle_count();
    leaf_count_ = 0;
    for (const BuildNode& node : snapped.tree.nodes) leaf_count_ += node.leaf();
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = std::max(snapped.peak_bytes, encode_peak) + snapped.quantized.lines.size() * sizeof(glm::ivec3) +
                        snapped.tree.nodes.size() * sizeof(BuildNode) + memory().total();
  }

  explicit WideHmqAccelerator(const SectionLoader& loader) {
    loader.expect_kind("hmq8", kWideHmqSavedVersion);
    SectionLoader in = loader;
    archive(*this, in);
  }

  template <typename Archive>
  static void archive(auto& self, Archive& a) {
    WideHmqSavedState state{self.grid_,
                            self.root_,
                            self.parts_.hierarchy,
                            self.parts_.geometry,
                            self.parts_.other,
                            static_cast<std::uint32_t>(self.children_),
                            static_cast<std::uint32_t>(self.leaf_count_)};
    a.value("hmq8.state", state);
    if constexpr (Archive::kLoading) self.leaves_beside_ = a.has("hmq8.tree");
    if (self.leaves_beside_) {
      a.array("hmq8.tree", self.nodes_);
    } else {
      a.array("hmq8.nodes", self.nodes_);
      a.array("hmq8.leaves", self.leaves_);
    }
    archive_common_state(a, self.triangles_, self.build_);
    if constexpr (Archive::kLoading) {
      self.grid_ = state.grid;
      self.root_ = state.root;
      self.parts_ = {state.hierarchy_bytes, state.geometry_bytes, state.other_bytes};
      self.children_ = state.children;
      self.leaf_count_ = state.leaves;
      const std::span<const QuantizedWideNode> nodes(self.nodes_.data(), self.nodes_.size());
      if (self.leaves_beside_) {
        const std::span<const std::byte> leaves = self.nodes_.bytes();
        self.node_count_ = check_tree_from_root(nodes, a, "hmq8.tree", [&](std::uint32_t units, std::uint8_t) {
          check_leaf_record(leaves, std::uint64_t(units) * kUnit, self.triangles_, a, "hmq8.tree");
        });
      } else {
        if (self.nodes_.empty() || self.leaves_.size() < kSlackBytes) a.fail("hmq8.nodes", "is empty: no hmq8 structure was saved");
        const std::span<const std::byte> leaves(self.leaves_.data(), self.leaves_.size());
        check_tree(nodes, a, "hmq8.nodes", [&](std::uint32_t units, std::uint8_t) {
          check_leaf_record(leaves, std::uint64_t(units) * kUnit, self.triangles_, a, "hmq8.leaves");
        });
        self.node_count_ = self.nodes_.size();
      }
    }
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    out.add_value(prefix + "kind", saved_kind("hmq8", kWideHmqSavedVersion));
    SectionSaver saver(out, prefix);
    archive(*this, saver);
  }

  std::string name() const override { return "hmq8"; }
  bool reads_through_frames() const override { return true; }

  // Camera rays eight at a time (two 2x2 quads): nodes decoded once a packet, leaves decoded
  // and gathered once a packet, each ray tested against them alone (the same hits as single
  // rays). On room:1M primary rays: 3.1-3.5 Mrays/s single, 5.0 in packets of 4, 6.2-6.8 of 8,
  // 6.1 of 16.
  void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    walk_with(kernel_isa(), [&]<KernelIsa kIsa>() {
      NullProbe probe;
      QuantizedWidePacketStack stack;
      LeafTriangles leaf;   // the packet's leaf of the moment
      DecodedLeaf scratch;  // and the columns it is gathered from
      const std::byte* leaves = leaf_records();
      for (std::uint32_t begin = range.begin; begin < range.end; begin += kWidePacketRays) {
        const std::uint32_t end = std::min<std::uint32_t>(begin + kWidePacketRays, range.end);
        SingleRay packet[kWidePacketRays];
        float tmax[kWidePacketRays];
        LeafHit best[kWidePacketRays];
        unsigned live = 0;
        for (std::uint32_t i = begin; i < end; ++i) {
          if (!(rays.flags[i] & ray_flags::alive)) continue;
          packet[i - begin] = load_ray(rays, i);
          tmax[i - begin] = packet[i - begin].tmax;
          live |= 1u << (i - begin);
        }
        if (live != 0) {
          walk_quantized_wide_packet<kIsa>(nodes_.data(), root_, packet, live, tmax, probe, stack,
                                     [&](std::uint32_t units, const Bounds3& box, unsigned members) {
                                       prepare_leaf<kIsa>(leaves + std::size_t(units) * kUnit, grid_,
                                                          Box{box.lower, box.upper}, leaf, scratch, probe);
                                       for (; members != 0; members &= members - 1) {
                                         const int r = std::countr_zero(members);
                                         test_leaf_triangles<false, kIsa>(leaf, packet[r].sheared, packet[r].tmin, tmax[r], best[r]);
                                       }
                                     });
        }
        for (std::uint32_t i = begin; i < end; ++i) {
          if (live >> (i - begin) & 1u) {
            write_leaf_hit<true>(best[i - begin], hits, i);
          } else {
            hits.set_miss(i);
          }
        }
      }
    });
  }

  MemoryReport memory() const override { return {parts_.hierarchy, parts_.geometry, parts_.other}; }
  BuildReport build() const override { return build_; }

  std::string build_notes() const override {
    const double triangles = double(std::max<std::size_t>(1, triangles_));
    return fmt::format(
        "grid {}x{}x{} bits, vertex error <= {:.3g}; {} 8-wide nodes ({:.2f} children each) over {} leaves ({:.1f} "
        "triangles each); bytes/tri: nodes+padding {:.2f}, vertices+connectivity {:.2f}, ids+corners {:.2f}",
        grid_.bits.x, grid_.bits.y, grid_.bits.z, grid_.max_vertex_error, node_count_,
        double(children_) / double(std::max<std::size_t>(1, node_count_)), leaf_count_,
        triangles / double(std::max<std::size_t>(1, leaf_count_)), double(parts_.hierarchy) / triangles,
        double(parts_.geometry) / triangles, double(parts_.other) / triangles);
  }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    if (leaves_beside_) return {nodes_.bytes()};
    return {nodes_.bytes(), leaves_.bytes()};
  }

  std::optional<TriangleMesh> represented_mesh(const TriangleMesh& source) const override {
    return snapped_mesh(grid_, source);
  }
  glm::vec3 represented_point(const glm::vec3& point) const override { return grid_.point(grid_.snap(point)); }

 private:
  template <bool kAnyHit, KernelIsa kIsa, typename Probe>
  void traverse(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe) const {
    QuantizedWideStack stack;
    DecodedLeafCache decoded;
    const std::byte* leaves = leaf_records();
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      float tmax = ray.tmax;
      LeafHit best;
      walk_quantized_wide<kIsa>(nodes_.data(), root_, ray, tmax, probe, stack, [&](std::uint32_t units, const Bounds3& box) {
        test_leaf_record<kAnyHit, kIsa>(leaves + std::size_t(units) * kUnit, grid_, Box{box.lower, box.upper}, ray.sheared,
                                  ray.tmin, tmax, best, probe, decoded);
        return kAnyHit && best.found;
      }, [&](std::uint32_t units) { return leaves + std::size_t(units) * kUnit; });
      write_leaf_hit<!kAnyHit>(best, hits, i);
      probe.end_ray();  // best's streams were read from the frames the probe let go here
    });
  }

  // Leaf references count 2-byte units from here: the records' own array, or the one array
  // that holds nodes and records together.
  const std::byte* leaf_records() const {
    return leaves_beside_ ? reinterpret_cast<const std::byte*>(nodes_.data()) : leaves_.data();
  }

  GlobalGrid grid_;
  Bounds3 root_;
  StoredArray<QuantizedWideNode> nodes_;  // with leaves_beside_, the nodes and the leaf records
  StoredArray<std::byte> leaves_;         // empty with leaves_beside_
  bool leaves_beside_ = false;
  PartBytes parts_;
  std::size_t children_ = 0, leaf_count_ = 0, triangles_ = 0, node_count_ = 0;
  BuildReport build_;
};

}  // namespace

std::unique_ptr<Accelerator> make_wide_hmq_accelerator(const TriangleMesh& mesh, const HmqOptions& options) {
  return std::make_unique<WideHmqAccelerator>(mesh, options);
}

std::unique_ptr<Accelerator> load_wide_hmq_accelerator(const SectionLoader& loader) {
  return std::make_unique<WideHmqAccelerator>(loader);
}

#else  // a build below x86-64-v3

constexpr const char* kNeedsAvx2 = "hmq:width=8 traverses in AVX2 and FMA lanes: build with WAVETRACE_ARCH=x86-64-v3 or newer";
std::unique_ptr<Accelerator> make_wide_hmq_accelerator(const TriangleMesh&, const HmqOptions&) {
  throw std::invalid_argument(kNeedsAvx2);
}
std::unique_ptr<Accelerator> load_wide_hmq_accelerator(const SectionLoader& loader) { loader.fail("kind", kNeedsAvx2); }

#endif

}  // namespace wavetrace
