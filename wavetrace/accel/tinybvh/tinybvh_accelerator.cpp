// tinybvh's BVH8_CPU and binary BVH behind the Accelerator interface, one ray at a time as
// tinybvh traces them; without WAVETRACE_TINYBVH only the names exist and making one throws.
#include "wavetrace/accel/tinybvh/tinybvh_accelerator.hpp"

#include <chrono>
#include <stdexcept>
#include <vector>

#include <fmt/format.h>

#if WAVETRACE_TINYBVH
#define TINYBVH_IMPLEMENTATION
#include <tiny_bvh.h>  // a SYSTEM include directory: its own warnings are not ours
#include <glm/geometric.hpp>

#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/ray_loop.hpp"
#include "wavetrace/memory/kernel_isa_choice.hpp"  // to_string(KernelIsa)
#endif

namespace wavetrace {

TinyBvhLayout parse_tinybvh_layout(const std::string& text) {
  if (text == "bvh8") return TinyBvhLayout::bvh8;
  if (text == "bvh2") return TinyBvhLayout::bvh2;
  throw std::invalid_argument(fmt::format("unknown tinybvh layout '{}' (bvh8, bvh2)", text));
}

std::string to_string(TinyBvhLayout layout) { return layout == TinyBvhLayout::bvh8 ? "bvh8" : "bvh2"; }

#if WAVETRACE_TINYBVH

namespace {

// tinybvh normalizes a ray's direction and has no tmin: the query starts at origin + tmin *
// direction and its distances are in units of the normalized direction. Rays with tmin = 0
// (bench accel's) are asked exactly what our walks are asked.
struct PeerRay {
  tinybvh::Ray ray;
  float tmin, length;
  PeerRay(const SingleRay& in)
      : ray(tinybvh::bvhvec3(in.origin.x + in.direction.x * in.tmin, in.origin.y + in.direction.y * in.tmin,
                             in.origin.z + in.direction.z * in.tmin),
            tinybvh::bvhvec3(in.direction.x, in.direction.y, in.direction.z), 0.0f),
        tmin(in.tmin),
        length(glm::length(in.direction)) {
    ray.hit.t = (in.tmax - in.tmin) * length;
  }
};

class TinyBvhAccelerator final : public Accelerator {
 public:
  TinyBvhAccelerator(const TriangleMesh& mesh, const TinyBvhOptions& options) : mesh_(mesh), options_(options) {
    const auto start = std::chrono::steady_clock::now();
    // tinybvh reads a vertex as 16 bytes, aligned: a copy of the positions with w = 0.
    vertices_.reserve(mesh.positions.size());
    for (const glm::vec3& p : mesh.positions) vertices_.emplace_back(p.x, p.y, p.z, 0.0f);
    const tinybvh::bvhvec4slice slice(vertices_.data(), static_cast<std::uint32_t>(vertices_.size()),
                                      sizeof(tinybvh::bvhvec4));
    const auto* indices = reinterpret_cast<const std::uint32_t*>(mesh.triangles.data());
    const auto count = static_cast<std::uint32_t>(mesh.triangle_count());
    if (options.layout == TinyBvhLayout::bvh8) {
      wide_.Build(slice, indices, count);
    } else {
      binary_.Build(slice, indices, count);
    }
    build_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    build_.peak_bytes = memory().total();
  }

  std::string name() const override { return "tinybvh-" + to_string(options_.layout); }
  std::string isa() const override { return std::string(to_string(KernelIsa::baseline)); }  // its code, our -march

  void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    for_each_ray(rays, hits, range, [&](const SingleRay& in, std::uint32_t i) {
      PeerRay peer(in);
      const float tmax = peer.ray.hit.t;
      if (options_.layout == TinyBvhLayout::bvh8) {
        wide_.Intersect(peer.ray);
      } else {
        binary_.Intersect(peer.ray);
      }
      if (peer.ray.hit.t < tmax) {
        hits.set_hit(i, peer.tmin + peer.ray.hit.t / peer.length, peer.ray.hit.prim, peer.ray.hit.u, peer.ray.hit.v);
      } else {
        hits.set_miss(i);
      }
    });
    set_surfaces_from_mesh(hits, range, mesh_);
  }

  void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const override {
    for_each_ray(rays, hits, range, [&](const SingleRay& in, std::uint32_t i) {
      const PeerRay peer(in);
      const bool occluded = options_.layout == TinyBvhLayout::bvh8 ? wide_.IsOccluded(peer.ray)
                                                                   : binary_.IsOccluded(peer.ray);
      hits.set_miss(i);
      // tinybvh says whether a ray was blocked, not by what: primitive 0 stands for "occluded".
      if (occluded) hits.primitive[i] = 0;
    });
  }

  // hierarchy: what the walk reads (BVH8_CPU's nodes with its leaves' triangle copies
  // interleaved; the binary BVH's nodes and triangle indices); geometry: the 16-byte vertex
  // copy and the mesh's indices; other: what BVH8_CPU keeps of its build (the binary and the
  // 8-wide tree it was converted from).
  MemoryReport memory() const override {
    MemoryReport report;
    report.geometry = vertices_.size() * sizeof(tinybvh::bvhvec4) + mesh_.triangles.size() * sizeof(glm::uvec3);
    const tinybvh::BVH& binary = options_.layout == TinyBvhLayout::bvh8 ? wide_.bvh8.bvh : binary_;
    const std::size_t binary_bytes =
        std::size_t{binary.allocatedNodes} * sizeof(tinybvh::BVH::BVHNode) + std::size_t{binary.idxCount} * 4;
    if (options_.layout == TinyBvhLayout::bvh8) {
      report.hierarchy = std::size_t{wide_.usedBlocks} * 64;  // blocks of one cache line
      report.other = binary_bytes + std::size_t{wide_.bvh8.allocatedNodes} * sizeof(tinybvh::MBVH<8>::MBVHNode);
    } else {
      report.hierarchy = binary_bytes;
    }
    return report;
  }
  BuildReport build() const override { return build_; }

 private:
  const TriangleMesh& mesh_;
  TinyBvhOptions options_;
  std::vector<tinybvh::bvhvec4> vertices_;
  tinybvh::BVH8_CPU wide_;
  tinybvh::BVH binary_;
  BuildReport build_;
};

}  // namespace

bool tinybvh_built_in() { return true; }

std::unique_ptr<Accelerator> make_tinybvh_accelerator(const TriangleMesh& mesh, const TinyBvhOptions& options) {
  return std::make_unique<TinyBvhAccelerator>(mesh, options);
}

#else

bool tinybvh_built_in() { return false; }

std::unique_ptr<Accelerator> make_tinybvh_accelerator(const TriangleMesh&, const TinyBvhOptions&) {
  throw std::invalid_argument(
      "accelerator 'tinybvh' is not built in: configure with -DWAVETRACE_TINYBVH=path/to/tiny_bvh.h (github.com/jbikker/tinybvh)");
}

#endif

}  // namespace wavetrace
