// The world's query interface: every accelerator answers closest-hit and any-hit for a
// range of a ray batch and reports what it costs in memory and build time.
#pragma once

#include <cstddef>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "wavetrace/accel/build_phases.hpp"
#include "wavetrace/kernels/kernel_isa.hpp"
#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

class SectionWriter;
class ChunkSet;

// Bytes by part, as the papers split them.
struct MemoryReport {
  std::size_t hierarchy = 0;  // nodes of the acceleration structure
  std::size_t geometry = 0;   // vertices, indices, triangle data
  std::size_t other = 0;      // everything else the structure keeps alive
  std::size_t total() const { return hierarchy + geometry + other; }
};

struct BuildReport {
  double seconds = 0.0;
  std::size_t peak_bytes = 0;  // highest memory the build held at once, result included
  BuildPhases phases;          // where the seconds went (empty where a build does not say)
};

class Accelerator {
 public:
  virtual ~Accelerator() = default;

  virtual std::string name() const = 0;

  // For each ray in range: the nearest hit in [tmin, tmax] into hits (t, primitive, u, v),
  // or primitive = kInvalidPrimitive and t = +inf on a miss. Rays whose alive flag is clear
  // are skipped and their hit slot marked as a miss.
  virtual void intersect_closest(const RayBatch& rays, HitBatch& hits, RayRange range) const = 0;

  // For each ray in range: whether anything lies in [tmin, tmax]; an occluded ray gets a
  // valid primitive (any one it found), a free ray kInvalidPrimitive.
  virtual void intersect_any(const RayBatch& rays, HitBatch& hits, RayRange range) const = 0;

  // The nearest hits as intersect_closest finds them (t, primitive, u, v), without their
  // points and normals, which may be left as they were: for a query that wants only where a
  // ray stops (approx_hit's walk of the proxy, where Embree's surfaces cost 8-18% of the
  // stage). The default is intersect_closest.
  virtual void intersect_distance(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    intersect_closest(rays, hits, range);
  }

  // Closest hits of coherent rays: camera rays sharing an origin, consecutive rays close
  // in the image (2x2 blocks in the Z-curve pixel order). Accelerators with packet
  // traversal use it; the default is intersect_closest.
  virtual void intersect_coherent(const RayBatch& rays, HitBatch& hits, RayRange range) const {
    intersect_closest(rays, hits, range);
  }

  // The same queries with every memory read reported to `probe`, for the pager and the
  // cache simulator. Only accelerators whose traversal is ours can do this (probed() is
  // true); the defaults throw std::logic_error. Embree's traversal cannot be observed.
  virtual bool probed() const { return false; }
  virtual void intersect_closest_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                        RecordingProbe& probe) const;
  virtual void intersect_any_probed(const RayBatch& rays, HitBatch& hits, RayRange range,
                                    RecordingProbe& probe) const;
  // Whether the probed walks read the paged file through the probe's frames (RecordingProbe::
  // resident and resident_record, each ray ending in end_ray) wherever they read it much, so
  // that a real pager may keep its pages in frames (FilePager::use_frames).
  virtual bool reads_through_frames() const { return false; }

  // The instruction set its walks run (accel.isa in the stats): one of the kernel sets
  // compiled into this binary (kernels/kernel_isa.hpp), or Embree's setting; empty where
  // there is no choice. use_isa switches to a set runnable_kernel_isas() lists; the
  // accelerators without a choice ignore it.
  virtual std::string isa() const { return {}; }
  virtual void use_isa(KernelIsa isa) {}

  virtual MemoryReport memory() const = 0;
  virtual BuildReport build() const = 0;
  // What the build chose that a user should know (resolution, guards that fired); may be empty.
  virtual std::string build_notes() const { return {}; }

  // The surface the accelerator answers for, when it is not `source` itself: a lossy
  // representation (hmq snaps vertices to a grid) returns `source` with its vertices moved
  // as it decodes them, so that tests and the leak bench can ask exact questions of it.
  virtual std::optional<TriangleMesh> represented_mesh(const TriangleMesh& source) const { return std::nullopt; }
  // Where a vertex at `point` lies on that surface (hmq: snapped to its global grid). Lights
  // are sampled there: samples on the exact emitter lie behind or inside the represented one,
  // which would shadow its own light.
  virtual glm::vec3 represented_point(const glm::vec3& point) const { return point; }

  // Writes the structure as sections named PREFIX + part (its format beside its code), for
  // load_accelerator to trace in place. The default throws std::logic_error: Embree's
  // structure cannot be written (a world rebuilds it from the saved geometry).
  virtual void save(SectionWriter& out, const std::string& prefix) const;

  // The byte ranges traversal reads, for the pager; empty where memory cannot be observed.
  virtual std::vector<std::span<const std::byte>> memory_spans() const { return {}; }

  // A chunked world's chunks (for a data-parallel render to own and route); null otherwise.
  virtual ChunkSet* chunk_set() { return nullptr; }
};

}  // namespace wavetrace
