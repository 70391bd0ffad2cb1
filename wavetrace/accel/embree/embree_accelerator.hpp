// The reference accelerator: Embree 3 over the scene's own vertex and index buffers.
#pragma once

#include <memory>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

enum class EmbreeMode { standard, compact, robust };

// How a batch's rays reach Embree: rtcIntersect1/rtcOccluded1 per ray, or the whole range
// at once through rtcIntersectNp/rtcOccludedNp over the batch's own columns (flagged
// coherent for camera rays, so Embree traces them as a stream of packets).
enum class EmbreeQueries { single, stream };

struct EmbreeOptions {
  EmbreeMode mode = EmbreeMode::standard;
  EmbreeQueries queries = EmbreeQueries::stream;
  int threads = 0;  // build threads; 0 = the TBB arena's
  std::string isa = "native";  // Embree's kernels: the best this CPU has, or an ISA Embree names (avx2, sse4.2)
  bool operator==(const EmbreeOptions&) const = default;
};

EmbreeMode parse_embree_mode(const std::string& text);  // "default" | "compact" | "robust"
std::string to_string(EmbreeMode mode);
EmbreeQueries parse_embree_queries(const std::string& text);  // "single" | "stream"
std::string to_string(EmbreeQueries queries);
std::string parse_embree_isa(const std::string& text);  // "native" | "avx2" | "sse4.2"

// Builds an Embree scene over `mesh`, which must outlive the accelerator (its buffers are
// shared, not copied). Memory is Embree's own, measured by its memory monitor, plus the
// mesh's vertex and index buffers.
std::unique_ptr<Accelerator> make_embree_accelerator(const TriangleMesh& mesh, const EmbreeOptions& options);

// Embree asks for flush-to-zero and denormals-are-zero in every thread that traces.
void set_embree_thread_float_mode();

}  // namespace wavetrace
