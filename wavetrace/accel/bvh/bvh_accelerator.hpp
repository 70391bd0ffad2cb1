// `bvh`: the papers' uncompressed baseline, a binned-SAH binary BVH of 32-byte nodes over
// an indexed face set (32-bit indices, float vertices), with watertight triangle tests.
#pragma once

#include <memory>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_options.hpp"
#include "wavetrace/accel/bvh/sah_builder.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// Either width; `mesh` must outlive the accelerator (with input order its buffers are read in place).
std::unique_ptr<Accelerator> make_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options);
// A bvh or bvh8 saved under the loader's prefix (bvh_build.hpp), traced in place.
class SectionLoader;
std::unique_ptr<Accelerator> load_bvh_accelerator(SectionLoader& in);

}  // namespace wavetrace
