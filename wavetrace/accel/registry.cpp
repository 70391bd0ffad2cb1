// Name-to-builder table of the accelerators.
#include "wavetrace/accel/registry.hpp"

#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/kernels/checked_narrowing.hpp"

#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {

std::vector<std::string> accelerator_names() { return {"embree", "bvh", "raystrips", "hmq", "grid", "mlgrid", "arraygrid"}; }

double estimated_bytes_per_triangle(const AcceleratorOptions& options) {
  const std::string& type = options.type;
  // The largest of the README's tables (room, subdivided scans; chunked room up to 256M).
  if (type == "embree") return options.embree.mode == EmbreeMode::compact ? 78.0 : 87.0;
  if (type == "bvh") return options.bvh.width == 8 ? 74.0 : 60.0;
  if (type == "raystrips") return options.raystrips.width == 8 ? 22.0 : 26.0;  // binary: 22.1 on room:8M, 25.7 on 256M
  if (type == "hmq") return 12.5;
  if (type == "arraygrid") return 230.0;  // 224 on builtin:sphere:1M
  return 48.0;  // grid, mlgrid: cells and lists vary with the scene; 44 on builtin:sphere:1M
}

double estimated_build_bytes_per_triangle(const std::string& type) {
  // Embree's builder: VmHWM 0.26 GB above the finished render's resident memory on room:8M
  // (its allocation monitor said ~15 B/tri on room:64M); ours, the binned SAH build's arrays
  // and the chunk's mesh: 165 B/tri on a monolithic room:64M, 180 per chunk triangle for
  // bvh:width=8 on room:8M. In chunks of 125k on room:1M and sphere:1M (render VmHWM less an
  // empty render's 18 MB and the finished structure, over the two chunks built at once):
  // hmq:width=8 147 and 196, raystrips:width=8 174 and 182, bvh:width=8 266 and 221. These
  // are not each an upper bound: auto's estimate adds them to a structure and a process
  // allowance that are (12.5 and 22 B/tri against 9-15 measured, 32 MB against 18), and
  // `bench report` sets every candidate's sum against its measured render peak.
  // The grids' counting build holds a count per cell and the lists' positions (bench accel
  // saw no VmHWM rise above its start on builtin:sphere:1M): bounded here by a cell count.
  if (type == "grid" || type == "mlgrid") return 24.0;
  if (type == "embree") return 32.0;
  return type == "bvh" ? 190.0 : 165.0;
}

bool builds_in_chunks(const std::string& type) { return type == "hmq" || type == "raystrips" || type == "bvh"; }
bool holds_own_geometry(const std::string& type) { return type == "hmq" || type == "raystrips"; }

std::unique_ptr<Accelerator> make_world_accelerator(const TriangleSource& source, const TriangleMesh* whole,
                                                    const AcceleratorOptions& options) {
  checked_uint32(source.triangle_count(), "triangles of a scene, which hits name by 32-bit ids");
  AcceleratorOptions chunk_options = options;
  chunk_options.hmq.grid_bounds = source.bounds();  // one global grid, whether chunked or not
  if (builds_in_chunks(options.type) && source.triangle_count() > options.chunk_triangles) {
    return make_chunked_accelerator(
        source, options.chunk_triangles,
        [&](const TriangleMesh& chunk) { return make_accelerator(chunk, chunk_options); }, !holds_own_geometry(options.type));
  }
  if (whole != nullptr) return make_accelerator(*whole, chunk_options);
  if (!holds_own_geometry(options.type)) {
    throw std::logic_error(fmt::format("'{}' reads its mesh in place: the caller must keep the whole mesh", options.type));
  }
  const TriangleMesh mesh = source.extract(0, source.triangle_count());
  return make_accelerator(mesh, chunk_options);
}

bool saves_structure(const std::string& type) { return type == "hmq" || type == "raystrips" || type == "bvh"; }

std::unique_ptr<Accelerator> load_accelerator(SectionLoader& in) {
  const SavedKind kind = in.file()->value<SavedKind>(in.prefix() + "kind");
  const std::string type(kind.type, strnlen(kind.type, sizeof(kind.type)));
  if (type == "hmq") return load_hmq_accelerator(in);
  if (type == "hmq8") return load_wide_hmq_accelerator(in);
  if (type == "raystrips") return load_raystrips_accelerator(in);
  if (type == "bvh") return load_bvh_accelerator(in);
  if (type == "chunked") return load_chunked_accelerator(in, [](SectionLoader& chunk) { return load_accelerator(chunk); });
  in.fail("kind", fmt::format("names accelerator '{}', which this build cannot load", type));
}

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
