// Chunked build and traversal. A batch is traced in rounds: each ray first lists the chunks
// whose boxes it enters (top-level BVH), nearest first; round k hands every ray its k-th
// chunk, unless its nearest hit so far lies before that chunk's box, and each chunk answers
// its rays as one compacted batch, so sub-accelerators keep their batch (and packet) paths
// and pay one virtual call per chunk and round, not per ray.
#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/chunked/chunk_router.hpp"

#include <algorithm>
#include <chrono>
#include <exception>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>

#include <fmt/format.h>
#include <malloc.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include "wavetrace/accel/bvh/bvh_node.hpp"
#include "wavetrace/accel/bvh/bvh_walk.hpp"
#include "wavetrace/accel/bvh/tree_check.hpp"
#include "wavetrace/accel/bvh/node_layout.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/nearest_hit.hpp"
#include "wavetrace/kernels/ray_box.hpp"
#include "wavetrace/memory/process_memory.hpp"

namespace wavetrace {
namespace {

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct Chunk {
  std::size_t first = 0;  // the source's id of the chunk's triangle 0
  std::size_t count = 0;
  Bounds3 bounds;
  std::unique_ptr<const TriangleMesh> mesh;  // kept only when the sub-accelerator reads it
  std::unique_ptr<Accelerator> accelerator;  // null once streamed to a file (ChunkStream)
  MemoryReport memory;                       // the sub-accelerator's, kept when it is freed
};

// A chunk a ray enters, and where.
struct ChunkVisit {
  float distance;
  std::uint32_t chunk;
};

// Per-thread working memory of one traced range, grown to the largest range seen.
struct RoundScratch {
  std::unique_ptr<Batch> batch;
  std::vector<ChunkVisit> visits;
  std::vector<std::uint32_t> visit_begin, visit_next;  // per ray: its visits, the next one due
  std::vector<float> nearest;                          // per ray: nearest hit so far (or tmax)
  std::vector<std::uint32_t> due_chunk, chunk_start, cursor, order;

  void reserve(std::size_t rays, std::size_t chunks) {
    if (!batch || batch->rays.capacity() < rays) batch = std::make_unique<Batch>(std::max<std::size_t>(rays, 64));
    visit_begin.resize(rays + 1);
    visit_next.resize(rays);
    nearest.resize(rays);
    due_chunk.resize(rays);
    order.resize(rays);
    chunk_start.assign(chunks + 1, 0);
  }
};

// Scratch for calls that may be suspended mid-round: taken for a call, given back after it.
class RoundScratchPool {
 public:
  std::unique_ptr<RoundScratch> take() {
    std::lock_guard lock(mutex_);
    if (free_.empty()) return std::make_unique<RoundScratch>();
    std::unique_ptr<RoundScratch> scratch = std::move(free_.back());
    free_.pop_back();
    return scratch;
  }
  void give(std::unique_ptr<RoundScratch> scratch) {
    std::lock_guard lock(mutex_);
    free_.push_back(std::move(scratch));
  }

 private:
  std::mutex mutex_;
  std::vector<std::unique_ptr<RoundScratch>> free_;
};

// One call's scratch from `pool` (none when `pool` is null), given back when the call ends.
struct PooledScratch {
  explicit PooledScratch(RoundScratchPool* from) : pool(from), scratch(from != nullptr ? from->take() : nullptr) {}
  ~PooledScratch() {
    if (pool != nullptr) pool->give(std::move(scratch));
  }
  PooledScratch(const PooledScratch&) = delete;
  PooledScratch& operator=(const PooledScratch&) = delete;
  RoundScratchPool* pool;
  std::unique_ptr<RoundScratch> scratch;
};

// Chunks built at the same time: one per worker thread, as many as half the memory the
// machine has available now can hold at a build's measured 200 bytes per triangle, and no
// more than `limit` (0: no limit). One at a time, a build's temporaries are one chunk's, its
// cores shared inside the chunk (build.chunks_at_once; measurements.md, "building one chunk at a time").
std::size_t chunks_built_at_once(std::size_t chunk_triangles, std::size_t limit) {
  const std::size_t threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  const std::size_t affordable = available_memory_bytes() / 2 / (chunk_triangles * 200);
  return std::clamp<std::size_t>(affordable, 1, limit == 0 ? threads : std::min(threads, limit));
}

// A saved chunked world, under `PREFIX`: "kind" ("chunked", version 1), "common"
// (section_archive.hpp), "chunked.top" (BvhNode, bvh_node.hpp; a leaf's first is a chunk's
// index, its count 0x80000001), "chunked.chunks" (40 bytes a chunk:
//   offset  size  field
//        0     8  first: the source's id of the chunk's triangle 0, uint64
//        8     8  count of triangles, uint64
//       16    24  box: float lower x, y, z, upper x, y, z)
// and each chunk's own accelerator under PREFIX + "chunk.N/" (N from 0, in decimal).
struct SavedChunk {
  std::uint64_t first, count;
  Bounds3 bounds;
};
static_assert(sizeof(SavedChunk) == 40);
constexpr std::uint32_t kChunkedSavedVersion = 1;

class ChunkedAccelerator final : public Accelerator, public ChunkSet {
 public:
  ChunkedAccelerator(SectionLoader& in, const ChunkLoader& load_chunk) {
    in.expect_kind(kChunkedKind, kChunkedSavedVersion);
    StoredArray<SavedChunk> saved;
    in.array("chunked.chunks", saved);
    in.array("chunked.top", top_);
    std::size_t triangles = 0;
    archive_common_state(in, triangles, build_);
    if (saved.empty() || top_.empty()) in.fail("chunked.chunks", "is empty: no chunk was saved");
    check_tree(std::span<const BvhNode>(top_.data(), top_.size()), in, "chunked.top", [&](const BvhNode& leaf) {
      if (leaf.first >= saved.size()) in.fail("chunked.top", "names a chunk that does not exist");
    });
    chunks_.resize(saved.size());
    // Chunks are checked on every core: checking each node and leaf record is most of a
    // world's load (about 12 of room:1G's 15 seconds on one core). Of several damaged
    // chunks the lowest is named, the same on every run.
    std::vector<std::exception_ptr> failures(saved.size());
    tbb::parallel_for(std::size_t{0}, saved.size(), [&](std::size_t c) {
      try {
        SectionLoader chunk_in(in.file(), in.prefix() + fmt::format("chunk.{}/", c));
        chunks_[c] = Chunk{saved[c].first, saved[c].count, saved[c].bounds, nullptr, load_chunk(chunk_in), {}};
        chunks_[c].memory = chunks_[c].accelerator->memory();
        in.file()->chunk_checked();
      } catch (...) {
        failures[c] = std::current_exception();
      }
    });
    for (const std::exception_ptr& failure : failures) {
      if (failure) std::rethrow_exception(failure);
    }
    lay_out_chunk_boxes();
  }

  void save(SectionWriter& out, const std::string& prefix) const override {
    if (streamed_to_ != nullptr && (streamed_to_ != &out || streamed_prefix_ != prefix)) {
      throw std::logic_error("a world streamed to a file while it was built is saved to that file only");
    }
    out.add_value(prefix + "kind", saved_kind(kChunkedKind, kChunkedSavedVersion));
    LargeArray<SavedChunk> saved;
    for (const Chunk& chunk : chunks_) saved.push_back({chunk.first, chunk.count, chunk.bounds});
    SectionSaver saver(out, prefix);
    saver.array("chunked.chunks", StoredArray<SavedChunk>(std::move(saved)));
    saver.array("chunked.top", top_);
    std::size_t triangles = this->triangles();
    archive_common_state(saver, triangles, build_);
    if (streamed_to_ != nullptr) return;  // the chunks are in the file already
    for (std::size_t c = 0; c < chunks_.size(); ++c) {
      chunks_[c].accelerator->save(out, prefix + fmt::format("chunk.{}/", c));
    }
  }

  ChunkedAccelerator(const TriangleSource& source, std::size_t chunk_triangles, const ChunkBuilder& build_chunk,
                     bool keeps_mesh, const ChunkStream* stream, std::size_t at_once_limit) {
    if (chunk_triangles < kMinChunkTriangles || chunk_triangles > kMaxChunkTriangles) {
      throw std::invalid_argument(fmt::format("build.chunk_triangles = {}: must be in [{}, {}]", chunk_triangles,
                                              kMinChunkTriangles, kMaxChunkTriangles));
    }
    if (source.triangle_count() >= kInvalidPrimitive) {
      throw std::invalid_argument(fmt::format("{} triangles: hits name triangles with 32-bit ids, at most {}",
                                              source.triangle_count(), kInvalidPrimitive - 1));
    }
    const auto start = std::chrono::steady_clock::now();
    // The chunked build's own phases are wall seconds; "chunk." phases add up every chunk's
    // build, so they are thread-seconds where chunks are built at once ("chunks" the wall).
    PhaseClock clock;
    const std::vector<ChunkRange> ranges = plan_chunks(source.object_starts(), source.triangle_count(), chunk_triangles);
    chunks_.resize(ranges.size());
    clock.lap(build_.phases, "plan");
    std::size_t finished_bytes = 0;
    for (std::size_t wave_begin = 0; wave_begin < ranges.size();) {
      const std::size_t wave_end = std::min(ranges.size(), wave_begin + chunks_built_at_once(chunk_triangles, at_once_limit));
      // Extracted, at once where the source allows (the serial parts of one chunk's
      // extraction, a third of it, overlap another's) and else one after another (a PLY
      // file's faces are read in order), then built at once.
      std::vector<std::unique_ptr<const TriangleMesh>> meshes(wave_end - wave_begin);
      const auto extract = [&](std::size_t c) {
        meshes[c - wave_begin] = std::make_unique<const TriangleMesh>(source.extract(ranges[c].first, ranges[c].count));
      };
      if (source.extracts_concurrently()) {
        tbb::parallel_for(wave_begin, wave_end, extract);
      } else {
        for (std::size_t c = wave_begin; c < wave_end; ++c) extract(c);
      }
      clock.lap(build_.phases, "extract");
      tbb::parallel_for(wave_begin, wave_end, [&](std::size_t c) {
        const TriangleMesh& mesh = *meshes[c - wave_begin];
        chunks_[c] = Chunk{ranges[c].first, ranges[c].count, mesh.bounds(), nullptr, build_chunk(mesh), {}};
        if (stream != nullptr && stream->observe) stream->observe(c, ranges[c].first, mesh, *chunks_[c].accelerator);
      });
      clock.lap(build_.phases, "chunks");
      // The wave's builds held their meshes, their temporaries and every chunk finished before.
      std::size_t wave_bytes = 0;
      for (std::size_t c = wave_begin; c < wave_end; ++c) {
        wave_bytes += meshes[c - wave_begin]->bytes() + chunks_[c].accelerator->build().peak_bytes;
      }
      build_.peak_bytes = std::max(build_.peak_bytes, finished_bytes + wave_bytes);
      for (std::size_t c = wave_begin; c < wave_end; ++c) {
        Chunk& chunk = chunks_[c];
        chunk.memory = chunk.accelerator->memory();
        build_.phases.add(chunk.accelerator->build().phases, "chunk.");
        if (stream != nullptr) {
          // Written in chunk order, so a chunk's sections lie together in the file.
          chunk.accelerator->save(stream->out, stream->prefix + fmt::format("chunk.{}/", c));
          if (c != 0) {
            chunk.accelerator.reset();
            continue;
          }
        }
        finished_bytes += chunk.memory.total();
        if (keeps_mesh) {
          chunk.mesh = std::move(meshes[c - wave_begin]);
          finished_bytes += chunk.mesh->bytes();
        }
      }
      // The wave's meshes and temporaries go back to the OS before the next wave: glibc keeps
      // freed blocks under its mmap threshold, which rises to the largest block a process has
      // freed, so after a pass that freed large buffers (auto's, over the scene) each wave's
      // temporaries stayed resident, on top of the next's: builtin:sphere:1M under auto at
      // 121 MB peaked at 121 MB, 83 MB with this; 7% more build time (pages faulted again).
      clock.lap(build_.phases, stream != nullptr ? "write" : "keep");
      meshes.clear();
      malloc_trim(0);
      clock.lap(build_.phases, "release");
      wave_begin = wave_end;
    }
    if (stream != nullptr) {
      streamed_to_ = &stream->out;
      streamed_prefix_ = stream->prefix;
    }
    build_top();
    lay_out_chunk_boxes();
    clock.lap(build_.phases, "top");
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  }

  std::string name() const override { return chunks_.front().accelerator->name(); }
  std::string isa() const override { return chunks_.front().accelerator ? chunks_.front().accelerator->isa() : ""; }
  void use_isa(KernelIsa isa) override {
    for (Chunk& chunk : chunks_) {
      if (chunk.accelerator) chunk.accelerator->use_isa(isa);  // else streamed to a file
    }
  }

  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    trace<false>(rays, hits, range, probe, ChunkQuery::closest,
                 [](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) { sub.intersect_closest(r, h, g); });
  }
  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    trace<true>(rays, hits, range, probe, ChunkQuery::any,
                [](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) { sub.intersect_any(r, h, g); });
  }
  void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    NullProbe probe;
    trace<false>(rays, hits, range, probe, ChunkQuery::coherent,
                 [](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) { sub.intersect_coherent(r, h, g); });
  }
  bool probed() const override { return chunks_.front().accelerator->probed(); }
  // Its top tree is read in place (a few pages, which the mapped pool keeps), its chunks as they read.
  bool reads_through_frames() const override { return chunks_.front().accelerator->reads_through_frames(); }
  // Probed rounds report the reads of the chunks answered here; a router's chunks are read
  // (and counted) by their owners.
  void intersect_closest_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                RecordingProbe& probe) const override {
    trace<false>(rays, hits, range, probe, ChunkQuery::closest,
                 [&](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) {
                   sub.intersect_closest_probed(r, h, g, probe);
                 });
  }
  void intersect_any_probed(const RayBatch& rays, HitBatch& hits, RayRange range, RecordingProbe& probe) const override {
    trace<true>(rays, hits, range, probe, ChunkQuery::any,
                [&](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) {
                  sub.intersect_any_probed(r, h, g, probe);
                });
  }

  ChunkSet* chunk_set() override { return this; }
  std::size_t chunk_count() const override { return chunks_.size(); }
  std::size_t chunk_triangles(std::size_t chunk) const override { return chunks_[chunk].count; }
  std::size_t chunk_bytes(std::size_t chunk) const override { return chunks_[chunk].memory.total(); }
  void query_chunk(std::size_t chunk, ChunkQuery query, const RayBatch& rays, HitBatch& hits,
                   RayRange range) const override {
    const Accelerator& sub = *chunks_[chunk].accelerator;
    switch (query) {
      case ChunkQuery::closest: sub.intersect_closest(rays, hits, range); break;
      case ChunkQuery::any: sub.intersect_any(rays, hits, range); break;
      case ChunkQuery::coherent: sub.intersect_coherent(rays, hits, range); break;
    }
  }
  void route(const ChunkRouter* router) override { router_ = router; }
  void count_rays_due(const RayBatch& rays, HitBatch& hits, std::span<std::uint64_t> rays_due) const override {
    if (rays_due.size() != chunks_.size()) throw std::invalid_argument("count_rays_due: one count a chunk");
    if (router_ != nullptr) throw std::logic_error("count_rays_due: the world is routed; count before routing it");
    NullProbe probe;
    trace<false>(rays, hits, rays.all(), probe, ChunkQuery::closest,
                 [](const Accelerator& sub, const RayBatch& r, HitBatch& h, RayRange g) { sub.intersect_closest(r, h, g); },
                 rays_due.data());
  }

  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = top_.size() * sizeof(BvhNode);
    report.other = chunks_.size() * sizeof(Chunk);
    for (const Chunk& chunk : chunks_) {
      const MemoryReport& part = chunk.memory;
      report.hierarchy += part.hierarchy;
      report.geometry += part.geometry;
      report.other += part.other;
    }
    return report;
  }
  BuildReport build() const override { return build_; }

  std::string build_notes() const override {
    std::size_t largest = 0;
    for (const Chunk& chunk : chunks_) largest = std::max(largest, chunk.count);
    std::string notes = fmt::format("{} chunks of up to {} triangles under a top BVH of {} nodes", chunks_.size(),
                                    largest, top_.size());
    const std::string first = chunks_.front().accelerator->build_notes();
    if (!first.empty()) notes += "; chunk 0: " + first;
    return notes;
  }

  // Every chunk snaps to the one global grid (make_world_accelerator): the first answers.
  glm::vec3 represented_point(const glm::vec3& point) const override {
    return chunks_.empty() ? point : chunks_.front().accelerator->represented_point(point);
  }

  std::optional<TriangleMesh> represented_mesh(const TriangleMesh& source) const override {
    if (source.triangle_count() != triangles()) throw std::invalid_argument("represented_mesh: not the mesh of this world");
    if (streamed_to_ != nullptr) throw std::logic_error(kStreamedIsNotTraced);
    TriangleMesh result = source;
    bool moved = false;
    const MeshTriangleSource ranges(source);
    for (const Chunk& chunk : chunks_) {
      const TriangleMesh part = ranges.extract(chunk.first, chunk.count);
      const std::optional<TriangleMesh> represented = chunk.accelerator->represented_mesh(part);
      if (!represented) continue;
      moved = true;
      for (std::size_t t = 0; t < chunk.count; ++t) {
        for (int k = 0; k < 3; ++k) {
          result.positions[source.triangles[chunk.first + t][k]] = represented->positions[part.triangles[t][k]];
        }
      }
    }
    if (!moved) return std::nullopt;
    return result;
  }

  std::vector<std::span<const std::byte>> memory_spans() const override {
    std::vector<std::span<const std::byte>> spans = {top_.bytes()};
    for (const Chunk& chunk : chunks_) {
      if (!chunk.accelerator) continue;  // streamed to a file
      for (const auto& span : chunk.accelerator->memory_spans()) spans.push_back(span);
    }
    return spans;
  }

 private:
  std::size_t triangles() const {
    std::size_t total = 0;
    for (const Chunk& chunk : chunks_) total += chunk.count;
    return total;
  }

  void build_top() {
    std::vector<Bounds3> boxes;
    for (const Chunk& chunk : chunks_) boxes.push_back(chunk.bounds);
    SahOptions sah;
    sah.max_leaf_size = 1;
    const BuildTree tree = build_sah_tree(boxes, sah);
    LargeArray<BvhNode> top;
    flatten_tree(tree, node_order(tree, NodeLayout::depth_first), top,
                 [&](const BuildNode& leaf) { return tree.primitive_order[leaf.first]; });
    top_ = StoredArray<BvhNode>(std::move(top));
  }

  // Up to this many chunks are listed by testing their boxes in lanes (list_chunks), blocks
  // of kLanes chunks at a time, each block's box first.
  static constexpr std::size_t kLanes = 16;
  static constexpr std::size_t kMostChunksInLanes = kLanes * kLanes * 4;
  struct BoxLanes {
    LargeArray<float> lower[3], upper[3];
    std::size_t size() const { return lower[0].size(); }
    bool empty() const { return lower[0].empty(); }
    void resize(std::size_t boxes) {  // every box empty
      for (int axis = 0; axis < 3; ++axis) {
        lower[axis].assign(boxes, kInfinity);
        upper[axis].assign(boxes, -kInfinity);
      }
    }
    Bounds3 get(std::size_t i) const {
      return {glm::vec3(lower[0][i], lower[1][i], lower[2][i]), glm::vec3(upper[0][i], upper[1][i], upper[2][i])};
    }
    void set(std::size_t i, const Bounds3& box) {
      for (int axis = 0; axis < 3; ++axis) lower[axis][i] = box.lower[axis], upper[axis][i] = box.upper[axis];
    }
  };
  // The chunks' boxes by coordinate in blocks of kLanes, and each block's box, padded with
  // empty boxes (whose lanes are never read back).
  void lay_out_chunk_boxes() {
    chunk_lanes_ = {};
    block_lanes_ = {};
    if (chunks_.size() > kMostChunksInLanes) return;
    const std::size_t blocks = (chunks_.size() + kLanes - 1) / kLanes;
    chunk_lanes_.resize(blocks * kLanes);
    block_lanes_.resize((blocks + kLanes - 1) / kLanes * kLanes);
    for (std::size_t c = 0; c < chunks_.size(); ++c) {
      chunk_lanes_.set(c, chunks_[c].bounds);
      Bounds3 block = block_lanes_.get(c / kLanes);
      block.extend(chunks_[c].bounds);
      block_lanes_.set(c / kLanes, block);
    }
  }

  // Entry distances (or +inf) of the ray into boxes [first, first + kLanes) of `boxes`.
  static void enter_lanes(const BoxLanes& boxes, std::size_t first, const BoxRay& ray, float tmin, float tmax,
                          float* entry) {
    const float* const lower[3] = {boxes.lower[0].data() + first, boxes.lower[1].data() + first,
                                   boxes.lower[2].data() + first};
    const float* const upper[3] = {boxes.upper[0].data() + first, boxes.upper[1].data() + first,
                                   boxes.upper[2].data() + first};
    intersect_boxes_soa(ray, lower, upper, kLanes, tmin, tmax, entry);
  }

  // The chunks ray i enters within [tmin, tmax], nearest first, appended to `visits`.
  template <typename Probe>
  void list_chunks(const RayBatch& rays, std::uint32_t i, std::vector<ChunkVisit>& visits, Probe& probe) const {
    const glm::vec3 origin(rays.origin_x[i], rays.origin_y[i], rays.origin_z[i]);
    const glm::vec3 direction(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
    const BoxRay box_ray = make_box_ray(origin, direction);
    const float tmin = rays.tmin[i], tmax = rays.tmax[i];
    const std::size_t begin = visits.size();
    // The lanes are the process's own memory, not the file's: a probe that counts every read
    // (the simulated pager and caches, the tally) sees the top BVH's instead, the paper's
    // reads; one that only keeps the real pager's order has nothing to see.
    if (!chunk_lanes_.empty() && (!Probe::kRecords || !probe.counts_reads())) {
      // Boxes in lanes: for up to a thousand chunks cheaper than walking the top BVH a box at
      // a time. A ray enters a chunk's box only if it enters its block's (the block's box
      // holds it, and the slab arithmetic is monotonic in the box). Ties leave in chunk order
      // where the walk left them in its own; a ray's nearest hit does not depend on it.
      alignas(64) float block_entry[kLanes], entry[kLanes];
      const std::size_t blocks = chunk_lanes_.size() / kLanes;
      for (std::size_t first_block = 0; first_block < blocks; first_block += kLanes) {
        if (blocks > 1) enter_lanes(block_lanes_, first_block, box_ray, tmin, tmax, block_entry);
        for (std::size_t b = first_block; b < std::min(blocks, first_block + kLanes); ++b) {
          if (blocks > 1 && block_entry[b - first_block] == kInfinity) continue;
          enter_lanes(chunk_lanes_, b * kLanes, box_ray, tmin, tmax, entry);
          for (std::size_t k = 0; k < kLanes && b * kLanes + k < chunks_.size(); ++k) {
            if (entry[k] != kInfinity) visits.push_back({entry[k], std::uint32_t(b * kLanes + k)});
          }
        }
      }
    } else {
      walk_bvh(top_.data(), box_ray, tmin, tmax, probe, [&](const BvhNode& leaf) {
        const float distance = intersect_box(box_ray, leaf.lower, leaf.upper, tmin, tmax);
        if (distance != kInfinity) visits.push_back({distance, leaf.first});
        return false;
      });
    }
    // Rays enter few chunks: an insertion sort.
    for (std::size_t a = begin + 1; a < visits.size(); ++a) {
      const ChunkVisit visit = visits[a];
      std::size_t b = a;
      for (; b > begin && visits[b - 1].distance > visit.distance; --b) visits[b] = visits[b - 1];
      visits[b] = visit;
    }
  }

  // `rays_due` (null, or one count a chunk): each round's rays added to their chunk's count.
  template <bool kAnyHit, typename Probe, typename Query>
  void trace(const RayBatch& rays, HitBatch& hits, RayRange range, Probe& probe, ChunkQuery kind, Query&& query,
             std::uint64_t* rays_due = nullptr) const {
    if (streamed_to_ != nullptr) throw std::logic_error(kStreamedIsNotTraced);
    const std::uint32_t n = range.size();
    if (n == 0) return;
    // A routed call may be suspended while its rays travel (ChunkRouter::answer_elsewhere):
    // its thread runs other calls meanwhile, and it may resume on another thread, so its
    // scratch is its own, from a pool, not the thread's.
    thread_local RoundScratch thread_scratch;
    const PooledScratch pooled(router_ != nullptr ? &scratch_pool_ : nullptr);
    RoundScratch& scratch = pooled.scratch != nullptr ? *pooled.scratch : thread_scratch;
    scratch.reserve(n, chunks_.size());
    scratch.visits.clear();
    for (std::uint32_t r = 0; r < n; ++r) {
      const std::uint32_t i = range.begin + r;
      hits.set_miss(i);
      scratch.visit_begin[r] = static_cast<std::uint32_t>(scratch.visits.size());
      scratch.visit_next[r] = scratch.visit_begin[r];
      scratch.nearest[r] = rays.tmax[i];
      if (rays.flags[i] & ray_flags::alive) list_chunks(rays, i, scratch.visits, probe);
    }
    scratch.visit_begin[n] = static_cast<std::uint32_t>(scratch.visits.size());
    RayBatch& sub_rays = scratch.batch->rays;
    HitBatch& sub_hits = scratch.batch->hits;
    constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
    while (true) {
      // Each ray's next chunk, unless its nearest hit lies before it (then no later one can do better).
      std::fill(scratch.chunk_start.begin(), scratch.chunk_start.end(), 0u);
      std::uint32_t due = 0;
      for (std::uint32_t r = 0; r < n; ++r) {
        std::uint32_t& next = scratch.visit_next[r];
        scratch.due_chunk[r] = kNone;
        if (next == scratch.visit_begin[r + 1]) continue;
        const ChunkVisit& visit = scratch.visits[next];
        if (visit.distance > pruning_distance(scratch.nearest[r])) {
          next = scratch.visit_begin[r + 1];
          continue;
        }
        ++next;
        scratch.due_chunk[r] = visit.chunk;
        ++scratch.chunk_start[visit.chunk + 1];
        ++due;
      }
      if (due == 0) return;
      for (std::size_t c = 0; c < chunks_.size(); ++c) {
        if (rays_due != nullptr) rays_due[c] += scratch.chunk_start[c + 1];
        scratch.chunk_start[c + 1] += scratch.chunk_start[c];
      }
      // Rays grouped by chunk, in their batch order within each group (coherent rays stay coherent).
      scratch.cursor.assign(scratch.chunk_start.begin(), scratch.chunk_start.end() - 1);
      std::vector<std::uint32_t>& cursor = scratch.cursor;
      for (std::uint32_t r = 0; r < n; ++r) {
        if (scratch.due_chunk[r] == kNone) continue;
        const std::uint32_t slot = cursor[scratch.due_chunk[r]]++;
        scratch.order[slot] = r;
        const std::uint32_t i = range.begin + r;
        sub_rays.origin_x[slot] = rays.origin_x[i];
        sub_rays.origin_y[slot] = rays.origin_y[i];
        sub_rays.origin_z[slot] = rays.origin_z[i];
        sub_rays.direction_x[slot] = rays.direction_x[i];
        sub_rays.direction_y[slot] = rays.direction_y[i];
        sub_rays.direction_z[slot] = rays.direction_z[i];
        sub_rays.tmin[slot] = rays.tmin[i];
        sub_rays.tmax[slot] = scratch.nearest[r];
        sub_rays.kind[slot] = rays.kind[i];
        sub_rays.flags[slot] = ray_flags::alive;
      }
      // Each ray is due at one chunk a round, so the chunks' answers touch disjoint slots and
      // may come in any order; a router's travel while the local chunks are asked.
      const auto local_chunks = [&] {
        for (std::size_t c = 0; c < chunks_.size(); ++c) {
          const std::uint32_t begin = scratch.chunk_start[c], end = scratch.chunk_start[c + 1];
          if (begin == end || (router_ != nullptr && !router_->is_local(c))) continue;
          query(*chunks_[c].accelerator, sub_rays, sub_hits, RayRange{begin, end});
          if (router_ != nullptr) router_->meanwhile();
        }
      };
      if (router_ != nullptr) {
        // An observed walk stays on its thread: its probe counts reads to that thread's slot.
        router_->answer_elsewhere(kind, sub_rays, sub_hits, scratch.chunk_start, local_chunks, !Probe::kRecords);
      } else {
        local_chunks();
      }
      for (std::size_t c = 0; c < chunks_.size(); ++c) {
        const std::uint32_t begin = scratch.chunk_start[c], end = scratch.chunk_start[c + 1];
        if (begin == end) continue;
        const auto first = static_cast<std::uint32_t>(chunks_[c].first);
        for (std::uint32_t slot = begin; slot < end; ++slot) {
          if (!sub_hits.is_hit(slot)) continue;
          const std::uint32_t r = scratch.order[slot], i = range.begin + r;
          if constexpr (kAnyHit) {
            hits.primitive[i] = first + sub_hits.primitive[slot];
            scratch.nearest[r] = -kInfinity;  // found: no further chunk is due
          } else if (replaces_nearest(
                         sub_hits.t[slot], scratch.nearest[r], hits.is_hit(i),
                         [&] { return first + sub_hits.primitive[slot]; }, [&] { return hits.primitive[i]; })) {
            hits.copy_hit(i, sub_hits, slot);
            hits.primitive[i] = first + sub_hits.primitive[slot];
            scratch.nearest[r] = sub_hits.t[slot];
          }
        }
      }
    }
  }

  static constexpr const char* kStreamedIsNotTraced =
      "a world streamed to a file while it was built is for saving: load the file to trace it";

  std::vector<Chunk> chunks_;
  StoredArray<BvhNode> top_;
  // list_chunks' boxes in lanes, empty past kMostChunksInLanes: made at build and load, never
  // saved, and left out of memory() and memory_spans() (24 KB at most; the probed walks whose
  // reads the pager counts walk top_).
  BoxLanes chunk_lanes_, block_lanes_;
  const ChunkRouter* router_ = nullptr;  // data-parallel: who answers the chunks not held here
  mutable RoundScratchPool scratch_pool_;  // the routed calls' scratch
  BuildReport build_;
  const SectionWriter* streamed_to_ = nullptr;  // set when every chunk went to this writer as it was built
  std::string streamed_prefix_;
};

}  // namespace

std::vector<ChunkRange> plan_chunks(std::span<const std::size_t> object_starts, std::size_t triangles,
                                    std::size_t chunk_triangles) {
  std::vector<ChunkRange> chunks;
  for (std::size_t o = 0; o < object_starts.size(); ++o) {
    const std::size_t begin = object_starts[o];
    const std::size_t end = o + 1 < object_starts.size() ? object_starts[o + 1] : triangles;
    const std::size_t size = end - begin;
    const std::size_t pieces = (size + chunk_triangles - 1) / chunk_triangles;
    for (std::size_t k = 0; k < pieces; ++k) {
      const std::size_t first = begin + size * k / pieces, next = begin + size * (k + 1) / pieces;
      chunks.push_back({first, next - first});
    }
  }
  return chunks;
}

std::unique_ptr<Accelerator> load_chunked_accelerator(SectionLoader& in, const ChunkLoader& load_chunk) {
  return std::make_unique<ChunkedAccelerator>(in, load_chunk);
}

std::unique_ptr<Accelerator> make_chunked_accelerator(const TriangleSource& source, std::size_t chunk_triangles,
                                                      const ChunkBuilder& build_chunk, bool keeps_mesh,
                                                      const ChunkStream* stream, std::size_t at_once_limit) {
  return std::make_unique<ChunkedAccelerator>(source, chunk_triangles, build_chunk, keeps_mesh, stream, at_once_limit);
}

}  // namespace wavetrace
