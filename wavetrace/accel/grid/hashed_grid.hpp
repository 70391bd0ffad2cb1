// `grid`: the one-level hashed grid of Costa and Pereira (2010, §3.1–3.2) — a uniform grid
// of density ρ (Woo's heuristic) whose empty cells cost one bit each, the non-empty ones
// found through row displacement hashing (Lagae and Dutré 2008) — traversed by 3D-DDA.
// `mlgrid` (§3.3) is the same grid with levels of macrocell bits that traversal uses to jump
// over empty blocks; a level-k bit covers factor^k cells per side (x fastest, like D).
//
// Layout (all arrays 32-bit words except D), for a grid of Mx × My × Mz cells:
//   D  Mx·My·Mz bits          bit d = (z·My + y)·Mx + x, in 64-bit words lowest bit first
//                             (word d / 64, bit d % 64): set where the cell's list is not empty
//   O  My·Mz words            O[z·My + y]: where row (y, z) starts in H (rows overlap, never
//                             collide; 0 for a row with no bit set in D, never read)
//   H  NH + 1 words           H[O[z·My + y] + x] .. H[... + 1]: the cell's range in L
//   L  Σ items per cell words  triangle indices, ascending within a cell
// A cell (x, y, z) holds triangles L[H[h] .. H[h + 1]) with h = O[z·My + y] + x, when its D
// bit is set; otherwise it is empty and H is not read. Triangles are read in place from the
// mesh (its indexed face set). A triangle is listed in every cell it overlaps (or, as in the
// paper, every cell its bounding box overlaps: `bounding_box_lists`). The build makes the grid
// in slabs of z layers, and a slab's rows take slots after the slabs before it, so O places
// rows first fit within a slab, as the paper does within the whole grid.
#pragma once

#include <memory>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct HashedGridOptions {
  double density = 32.0;  // ρ: cells per triangle; the paper's choice for the hashed grid
  // The resolution guard: cells in all are capped here (the density is lowered to fit, and
  // the build reports it), since a scene like builtin:stadium would otherwise explode.
  std::size_t max_cells = std::size_t{1} << 30;
  // mlgrid (§3.3): levels of macrocells, each a bit per block of factor^k cells, so that
  // traversal jumps over empty space; 0 for the plain one-level grid. The paper: 6.
  std::uint32_t macrocell_factor = 0;
  // The paper lists a triangle in every cell its bounding box overlaps; by default only the
  // cells the triangle itself overlaps are listed (kernels/triangle_cell_runs.hpp): a strand
  // lying across the grid then fills n cells rather than n^3. Hits are the same either way.
  bool bounding_box_lists = false;
  bool operator==(const HashedGridOptions&) const = default;
};

// The cells per axis the grid takes over `bounds` for `triangles` (the box's extent floored
// at a millionth of its diagonal): what a build will choose, known before it (accel.type = auto
// counts triangles per cell on it).
struct GridResolution {
  glm::uvec3 cells{1};
  glm::dvec3 size{1.0};  // the extent the cells divide
  bool capped = false;   // the resolution guard lowered the density
};
GridResolution hashed_grid_resolution(const Bounds3& bounds, std::size_t triangles, const HashedGridOptions& options);

// `mesh` must outlive the accelerator (its arrays are read in place).
std::unique_ptr<Accelerator> make_hashed_grid_accelerator(const TriangleMesh& mesh, const HashedGridOptions& options);

}  // namespace wavetrace
