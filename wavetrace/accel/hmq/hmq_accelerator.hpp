// `hmq`: Segovia and Ernst's Hierarchical Mesh Quantization (2010). Vertices are snapped to
// one global grid and stored in the BVH's leaves as bit-packed offsets to the nearer leaf
// box plane; connectivity as tabulated strip sets; the BVH below its top (kept as 32-byte
// float nodes) as 4-byte nodes quantized against their parents, in blocks with forward
// slots, leaf records interleaved after each block (hmq_format.hpp). Traversal decodes
// nodes and leaves on the fly; nothing decompressed is cached.
#pragma once

#include <cstdint>
#include <memory>
#include <optional>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/hmq/hmq_options.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// Throws std::invalid_argument for options outside their ranges or set together.
std::unique_ptr<Accelerator> make_hmq_accelerator(const TriangleMesh& mesh, const HmqOptions& options);
// The hmq structure saved under the loader's prefix, traced in place (format in hmq_accelerator.cpp).
class SectionLoader;
std::unique_ptr<Accelerator> load_hmq_accelerator(const SectionLoader& loader);
// The 8-wide layout's (wide_hmq_accelerator.cpp); make_hmq_accelerator calls it for width 8.
std::unique_ptr<Accelerator> make_wide_hmq_accelerator(const TriangleMesh& mesh, const HmqOptions& options);
std::unique_ptr<Accelerator> load_wide_hmq_accelerator(const SectionLoader& loader);

}  // namespace wavetrace
