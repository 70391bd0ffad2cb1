// Embree 3 wrapper: one triangle geometry with shared buffers, traced per ray
// (rtcIntersect1/rtcOccluded1, the configuration the papers and PLATFORM.md measure) or a
// batch range at a time through Embree's stream entries over our columns.
#include "wavetrace/accel/embree/embree_accelerator.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/ray_loop.hpp"

#include <atomic>
#include <chrono>
#include <limits>
#include <stdexcept>
#include <vector>

#include <embree3/rtcore.h>
#include <fmt/format.h>
#include <tbb/info.h>
#include <pmmintrin.h>
#include <xmmintrin.h>

namespace wavetrace {
namespace {

// Embree reports every allocation and free here; we keep the live total and its peak.
struct MemoryMonitor {
  std::atomic<std::int64_t> current{0};
  std::atomic<std::int64_t> peak{0};

  static bool callback(void* self, ssize_t bytes, bool /*post*/) {
    auto* monitor = static_cast<MemoryMonitor*>(self);
    const std::int64_t now = monitor->current.fetch_add(bytes, std::memory_order_relaxed) + bytes;
    std::int64_t seen = monitor->peak.load(std::memory_order_relaxed);
    while (now > seen && !monitor->peak.compare_exchange_weak(seen, now, std::memory_order_relaxed)) {
    }
    return true;
  }
};

void raise_embree_error(RTCDevice device, const char* what) {
  const RTCError code = rtcGetDeviceError(device);
  if (code != RTC_ERROR_NONE) throw std::runtime_error(fmt::format("embree: {} failed (error {})", what, int(code)));
}

class EmbreeAccelerator final : public Accelerator {
 public:
  EmbreeAccelerator(const TriangleMesh& mesh, const EmbreeOptions& options) : mesh_(mesh), options_(options) {
    const auto start = std::chrono::steady_clock::now();
    PhaseClock clock;
    // Embree's TBB scheduler holds threads=N as a process-wide tbb::global_control of
    // min(N, cores) for the device's life, and TBB obeys the smallest such limit: any N would
    // cap every arena of ours at the cores, and `--threads 8` on 2 cores ran on 2. N is
    // passed only where it lowers Embree's builds below the cores; above, Embree takes them all.
    const bool below_cores = options.threads > 0 && options.threads < tbb::info::default_concurrency();
    std::string config = below_cores ? fmt::format("threads={}", options.threads) : std::string();
    if (options.isa != "native") config += (config.empty() ? "isa=" : ",isa=") + options.isa;
    device_ = rtcNewDevice(config.empty() ? nullptr : config.c_str());
    if (device_ == nullptr) throw std::runtime_error("embree: could not create a device");
    rtcSetDeviceMemoryMonitorFunction(device_, &MemoryMonitor::callback, &monitor_);

    clock.lap(build_.phases, "device");
    scene_ = rtcNewScene(device_);
    RTCSceneFlags flags = RTC_SCENE_FLAG_NONE;
    if (options.mode == EmbreeMode::compact) flags = RTC_SCENE_FLAG_COMPACT;
    if (options.mode == EmbreeMode::robust) flags = RTC_SCENE_FLAG_ROBUST;
    rtcSetSceneFlags(scene_, flags);

    RTCGeometry geometry = rtcNewGeometry(device_, RTC_GEOMETRY_TYPE_TRIANGLE);
    // Embree may read 16 bytes at the last vertex; validate_and_clean reserves that slack.
    const glm::vec3* vertices = mesh.positions.data();
    if (mesh.positions.capacity() <= mesh.positions.size()) {
      padded_vertices_.reserve(mesh.positions.size() + 1);
      padded_vertices_.assign(mesh.positions.begin(), mesh.positions.end());
      vertices = padded_vertices_.data();
    }
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, vertices, 0,
                               sizeof(glm::vec3), mesh.positions.size());
    rtcSetSharedGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, mesh.triangles.data(), 0,
                               sizeof(glm::uvec3), mesh.triangles.size());
    rtcSetGeometryMask(geometry, 0xFFFFFFFFu);
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene_, geometry);
    rtcReleaseGeometry(geometry);
    clock.lap(build_.phases, "geometry");
    rtcCommitScene(scene_);
    raise_embree_error(device_, "building the scene");
    clock.lap(build_.phases, "commit");
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = static_cast<std::size_t>(monitor_.peak.load()) + mesh_bytes();
  }

  ~EmbreeAccelerator() override {
    rtcReleaseScene(scene_);
    rtcReleaseDevice(device_);
  }

  std::string isa() const override { return options_.isa; }  // Embree's own choice under "native"
  std::string name() const override {
    const std::string isa = options_.isa == "native" ? "" : "-" + options_.isa;
    return (options_.mode == EmbreeMode::standard ? "embree" : "embree-" + to_string(options_.mode)) + isa;
  }

  // A stream of one ray (the megakernel's) goes to rtcIntersect1: the same hits, without
  // the stream's set-up.
  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    intersect_distance(rays, hits, range);
    set_surfaces_from_mesh(hits, range, mesh_);
  }

  void intersect_distance(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    if (options_.queries == EmbreeQueries::stream && range.size() > 1) {
      intersect_stream(rays, hits, range, RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT);
    } else {
      intersect_single(rays, hits, range);
    }
  }

  void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    if (options_.queries == EmbreeQueries::single || range.size() == 1) {
      intersect_closest(rays, hits, range);
      return;
    }
    intersect_stream(rays, hits, range, RTC_INTERSECT_CONTEXT_FLAG_COHERENT);
    set_surfaces_from_mesh(hits, range, mesh_);
  }

  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    if (options_.queries == EmbreeQueries::stream && range.size() > 1) {
      occluded_stream(rays, hits, range);
      return;
    }
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      hits.set_miss(i);
      RTCRay query;
      fill_ray(ray, i, query);
      rtcOccluded1(scene_, &context, &query);
      // Embree says which ray was blocked, not by what: report primitive 0 as "occluded".
      if (query.tfar == -std::numeric_limits<float>::infinity()) hits.primitive[i] = 0;
    });
  }

  MemoryReport memory() const override {
    MemoryReport report;
    report.hierarchy = static_cast<std::size_t>(monitor_.current.load());
    report.geometry = mesh_bytes();
    return report;
  }

  BuildReport build() const override { return build_; }

 private:
  // t, primitive, u, v of each ray; the caller adds the surfaces.
  void intersect_single(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    for_each_ray(rays, hits, range, [&](const SingleRay& ray, std::uint32_t i) {
      RTCRayHit query;
      fill_ray(ray, i, query.ray);
      query.hit.geomID = RTC_INVALID_GEOMETRY_ID;
      query.hit.primID = RTC_INVALID_GEOMETRY_ID;
      rtcIntersect1(scene_, &context, &query);
      if (query.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
        hits.set_miss(i);
      } else {
        hits.set_hit(i, query.ray.tfar, query.hit.primID, query.hit.u, query.hit.v);
      }
    });
  }

  // The columns Embree's pointer-SoA stream reads and writes that a batch does not have.
  struct StreamScratch {
    std::vector<float> time;
    std::vector<unsigned> mask, id, flags, geometry;
    std::vector<float> normal_x, normal_y, normal_z;
    void reserve(std::size_t count) {
      if (time.size() >= count) return;
      time.assign(count, 0.0f);
      mask.assign(count, 0xFFFFFFFFu);
      flags.assign(count, 0u);
      id.resize(count);
      for (std::size_t i = 0; i < count; ++i) id[i] = unsigned(i);
      geometry.resize(count);
      normal_x.resize(count);
      normal_y.resize(count);
      normal_z.resize(count);
    }
  };
  static StreamScratch& stream_scratch(std::size_t count) {
    thread_local StreamScratch scratch;
    scratch.reserve(count);
    return scratch;
  }

  // The range's rays in place: origins, directions and tnear from the batch, tfar in the
  // hit's t column (Embree shortens it to the hit), u, v and primitive written by Embree.
  // A dead ray gets tfar = -inf, which Embree skips as an empty segment.
  RTCRayNp stream_rays(const RayBatch& rays, HitBatch& hits, RayRange range, StreamScratch& scratch) const {
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      hits.t[i] = (rays.flags[i] & ray_flags::alive) ? rays.tmax[i] : -std::numeric_limits<float>::infinity();
    }
    const std::uint32_t b = range.begin;
    return {const_cast<float*>(rays.origin_x + b), const_cast<float*>(rays.origin_y + b),
            const_cast<float*>(rays.origin_z + b),  const_cast<float*>(rays.tmin + b),
            const_cast<float*>(rays.direction_x + b), const_cast<float*>(rays.direction_y + b),
            const_cast<float*>(rays.direction_z + b), scratch.time.data(),
            hits.t + b, scratch.mask.data(), scratch.id.data(), scratch.flags.data()};
  }

  void intersect_stream(const RayBatch& rays, HitBatch& hits, RayRange range, RTCIntersectContextFlags flags) const {
    StreamScratch& scratch = stream_scratch(range.size());
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = flags;
    const std::uint32_t b = range.begin;
    std::fill_n(scratch.geometry.data(), range.size(), RTC_INVALID_GEOMETRY_ID);
    RTCRayHitNp query;
    query.ray = stream_rays(rays, hits, range, scratch);
    query.hit = {scratch.normal_x.data(), scratch.normal_y.data(), scratch.normal_z.data(), hits.u + b, hits.v + b,
                 hits.primitive + b, scratch.geometry.data(), {nullptr}};
    rtcIntersectNp(scene_, &context, &query, range.size());
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      if (scratch.geometry[i - b] == RTC_INVALID_GEOMETRY_ID) hits.set_miss(i);
    }
  }

  void occluded_stream(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    StreamScratch& scratch = stream_scratch(range.size());
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    RTCRayNp query = stream_rays(rays, hits, range, scratch);
    rtcOccludedNp(scene_, &context, &query, range.size());
    for (std::uint32_t i = range.begin; i < range.end; ++i) {
      const bool occluded = hits.t[i] == -std::numeric_limits<float>::infinity() && (rays.flags[i] & ray_flags::alive);
      hits.set_miss(i);
      // Embree says which ray was blocked, not by what: report primitive 0 as "occluded".
      if (occluded) hits.primitive[i] = 0;
    }
  }

  static void fill_ray(const SingleRay& single, std::uint32_t i, RTCRay& ray) {
    ray.org_x = single.origin.x;
    ray.org_y = single.origin.y;
    ray.org_z = single.origin.z;
    ray.dir_x = single.direction.x;
    ray.dir_y = single.direction.y;
    ray.dir_z = single.direction.z;
    ray.tnear = single.tmin;
    ray.tfar = single.tmax;
    ray.time = 0.0f;
    ray.mask = 0xFFFFFFFFu;
    ray.id = i;
    ray.flags = 0;
  }

  std::size_t mesh_bytes() const {
    return mesh_.positions.size() * sizeof(glm::vec3) + mesh_.triangles.size() * sizeof(glm::uvec3);
  }

  const TriangleMesh& mesh_;
  EmbreeOptions options_;
  std::vector<glm::vec3> padded_vertices_;
  MemoryMonitor monitor_;
  RTCDevice device_ = nullptr;
  RTCScene scene_ = nullptr;
  BuildReport build_;
};

}  // namespace

EmbreeMode parse_embree_mode(const std::string& text) {
  if (text == "default") return EmbreeMode::standard;
  if (text == "compact") return EmbreeMode::compact;
  if (text == "robust") return EmbreeMode::robust;
  throw std::invalid_argument(fmt::format("unknown embree mode '{}' (default, compact, robust)", text));
}

std::string to_string(EmbreeMode mode) {
  switch (mode) {
    case EmbreeMode::compact: return "compact";
    case EmbreeMode::robust: return "robust";
    default: return "default";
  }
}

EmbreeQueries parse_embree_queries(const std::string& text) {
  if (text == "single") return EmbreeQueries::single;
  if (text == "stream") return EmbreeQueries::stream;
  throw std::invalid_argument(fmt::format("unknown embree queries '{}' (single, stream)", text));
}

std::string to_string(EmbreeQueries queries) { return queries == EmbreeQueries::stream ? "stream" : "single"; }

std::string parse_embree_isa(const std::string& text) {
  if (text == "native" || text == "avx2" || text == "sse4.2") return text;
  throw std::invalid_argument(fmt::format("unknown embree isa '{}' (native, avx2, sse4.2)", text));
}

std::unique_ptr<Accelerator> make_embree_accelerator(const TriangleMesh& mesh, const EmbreeOptions& options) {
  return std::make_unique<EmbreeAccelerator>(mesh, options);
}

void set_embree_thread_float_mode() {
  _MM_SET_FLUSH_ZERO_MODE(_MM_FLUSH_ZERO_ON);
  _MM_SET_DENORMALS_ZERO_MODE(_MM_DENORMALS_ZERO_ON);
}

}  // namespace wavetrace
