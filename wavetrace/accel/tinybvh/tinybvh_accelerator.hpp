// tinybvh (github.com/jbikker/tinybvh) as a peer in the harness, so that `bench accel` sets
// our walks beside its BVH8_CPU on the same rays and threads in one run. Its header is never
// copied into the tree: configure with -DWAVETRACE_TINYBVH=path/to/tiny_bvh.h to build it in.
#pragma once

#include <memory>
#include <string>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// bvh8: BVH8_CPU, its 8-wide AVX2 walk (Fuetterling et al.'s child order, four triangles a
// leaf in SoA); bvh2: its binary BVH in Wald's 32-byte nodes over the indexed mesh.
enum class TinyBvhLayout { bvh8, bvh2 };

struct TinyBvhOptions {
  TinyBvhLayout layout = TinyBvhLayout::bvh8;
  bool operator==(const TinyBvhOptions&) const = default;
};

TinyBvhLayout parse_tinybvh_layout(const std::string& text);  // "bvh8" | "bvh2"
std::string to_string(TinyBvhLayout layout);

// Whether this build carries tinybvh (WAVETRACE_TINYBVH was given to CMake).
bool tinybvh_built_in();

// Builds tinybvh's structure over `mesh`, which must outlive the accelerator (hit surfaces
// are read from it). Throws std::invalid_argument naming the CMake option when this build
// has no tinybvh.
std::unique_ptr<Accelerator> make_tinybvh_accelerator(const TriangleMesh& mesh, const TinyBvhOptions& options);

}  // namespace wavetrace
