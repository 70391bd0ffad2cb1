// Accelerators by name, as config files, --accel and the bench harness name them.
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "accel/accelerator.hpp"
#include "accel/bvh/bvh_accelerator.hpp"
#include "accel/embree/embree_accelerator.hpp"
#include "accel/grid/array_grid.hpp"
#include "accel/grid/hashed_grid.hpp"
#include "accel/hmq/hmq_accelerator.hpp"
#include "accel/raystrips/raystrips_accelerator.hpp"
#include "scene/triangle_mesh.hpp"

namespace wavetrace {

struct AcceleratorOptions {
  std::string type = "embree";
  EmbreeOptions embree;
  BvhOptions bvh;
  HashedGridOptions grid;
  HashedGridOptions mlgrid{32.0, std::size_t{1} << 30, 6};
  ArrayGridOptions arraygrid;
  RayStripsOptions raystrips;
  HmqOptions hmq;
};

std::vector<std::string> accelerator_names();

// Throws std::invalid_argument naming an unknown type.
std::unique_ptr<Accelerator> make_accelerator(const TriangleMesh& mesh, const AcceleratorOptions& options);

}  // namespace wavetrace
