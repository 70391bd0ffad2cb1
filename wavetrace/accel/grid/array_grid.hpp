// `arraygrid`: the classic multi-level array grid the paper compares with (§2, Listing 1).
// A uniform grid (Woo's heuristic, density ρ = 4) whose cells holding at least 8 triangles
// are refined into grids of their own, down to depth 2; empty cells are null.
//
// Layout: nodes (one per grid, 48 bytes) and cells (8 bytes each) in two arrays, items in a
// third.
//   ArrayGridNode  lower (12 B) | cell_size (12 B) | cells (3 × 4 B) | first_cell (4 B) | pad
//                  cell (x, y, z) of the node is cells[first_cell + (z·My + y)·Mx + x]
//   ArrayGridCell  reference (4 B) | count (4 B)
//                  count = 0 and reference = 0: null (empty)
//                  reference & 1 = 1: an inner cell, its grid is nodes[reference >> 1]
//                  reference & 1 = 0: a leaf, its triangles items[reference >> 1 .. + count)
// Triangles are read in place from the mesh; a triangle is listed in every cell its
// bounding box overlaps.
#pragma once

#include <memory>

#include "wavetrace/accel/accelerator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

struct ArrayGridOptions {
  double density = 4.0;             // ρ of Woo's heuristic per grid
  std::uint32_t refine_items = 8;   // a cell with at least this many triangles is refined
  std::uint32_t max_depth = 2;      // grids nest down to this depth (root grid: depth 0)
  // Resolution guards: refinement stops once all grids hold this many cells, or once the
  // triangle lists made so far hold this many entries (thin triangles crossing many small
  // cells, as in builtin:fur, otherwise multiply the lists at every level).
  std::size_t max_cells = std::size_t{1} << 28;
  std::size_t max_entries = std::size_t{1} << 28;
  bool operator==(const ArrayGridOptions&) const = default;
};

std::unique_ptr<Accelerator> make_array_grid_accelerator(const TriangleMesh& mesh, const ArrayGridOptions& options);

}  // namespace wavetrace
