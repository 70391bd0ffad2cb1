// Name-to-builder table of the accelerators.
#include "accel/registry.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {

std::vector<std::string> accelerator_names() { return {"embree", "bvh", "raystrips", "hmq", "grid", "mlgrid", "arraygrid"}; }

std::unique_ptr<Accelerator> make_accelerator(const TriangleMesh& mesh, const AcceleratorOptions& options) {
  if (options.type == "embree") return make_embree_accelerator(mesh, options.embree);
  if (options.type == "bvh") return make_bvh_accelerator(mesh, options.bvh);
  if (options.type == "raystrips") return make_raystrips_accelerator(mesh, options.raystrips);
  if (options.type == "hmq") return make_hmq_accelerator(mesh, options.hmq);
  if (options.type == "grid") return make_hashed_grid_accelerator(mesh, options.grid);
  if (options.type == "arraygrid") return make_array_grid_accelerator(mesh, options.arraygrid);
  if (options.type == "mlgrid") {
    HashedGridOptions grid = options.mlgrid;
    if (grid.macrocell_factor < 2) throw std::invalid_argument("mlgrid needs a macrocell factor of 2 or more");
    return make_hashed_grid_accelerator(mesh, grid);
  }
  std::string known;
  for (const std::string& name : accelerator_names()) known += (known.empty() ? "" : ", ") + name;
  throw std::invalid_argument(fmt::format("unknown accelerator '{}' (available: {})", options.type, known));
}

}  // namespace wavetrace
