// `bvh` with width 8: the same SAH tree collapsed into 8-wide nodes for AVX2 box tests.
#pragma once

#include <memory>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/accel/bvh/bvh_options.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

std::unique_ptr<Accelerator> make_wide_bvh_accelerator(const TriangleMesh& mesh, const BvhOptions& options);
// A bvh or bvh8 saved under the loader's prefix (bvh_build.hpp), traced in place.
class SectionLoader;
std::unique_ptr<Accelerator> load_wide_bvh_accelerator(SectionLoader& in);

}  // namespace wavetrace
