// The reference accelerator: Embree 3 over the scene's own vertex and index buffers.
#pragma once

#include <memory>
#include <string>

#include "accel/accelerator.hpp"
#include "scene/triangle_mesh.hpp"

namespace wavetrace {

enum class EmbreeMode { standard, compact, robust };

struct EmbreeOptions {
  EmbreeMode mode = EmbreeMode::standard;
  int threads = 0;  // build threads; 0 = the TBB arena's
};

EmbreeMode parse_embree_mode(const std::string& text);  // "default" | "compact" | "robust"
std::string to_string(EmbreeMode mode);

// Builds an Embree scene over `mesh`, which must outlive the accelerator (its buffers are
// shared, not copied). Memory is Embree's own, measured by its memory monitor, plus the
// mesh's vertex and index buffers.
std::unique_ptr<Accelerator> make_embree_accelerator(const TriangleMesh& mesh, const EmbreeOptions& options);

// Embree asks for flush-to-zero and denormals-are-zero in every thread that traces.
void set_embree_thread_float_mode();

}  // namespace wavetrace
