// The grid, the snapped vertices and the SAH tree that both HMQ layouts encode.
#include "wavetrace/accel/hmq/snapped_tree.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "wavetrace/memory/cache_aligned_allocator.hpp"

namespace wavetrace::hmq {

void check_options(const HmqOptions& options) {
  auto require = [](bool ok, const std::string& message) {
    if (!ok) throw std::invalid_argument("hmq: " + message);
  };
  require(options.epsilon >= 0.0 && std::isfinite(options.epsilon),
          fmt::format("epsilon = {}: must be a positive distance (0: unset)", options.epsilon));
  require(options.epsilon == 0.0 || options.bits == 16,
          fmt::format("bits = {} and epsilon = {} are both set; the grid comes from one of them", options.bits,
                      options.epsilon));
  require(options.bits >= 1 && options.bits <= 24, fmt::format("bits = {}: must be 1 .. 24", options.bits));
  require(options.leaf_size <= kMaxLeafTriangles,
          fmt::format("leaf_size = {}: must be 1 .. {} (the strip table's limit; 0: the width's own)", options.leaf_size,
                      kMaxLeafTriangles));
  require(options.top_fraction >= 0.0 && options.top_fraction <= 1.0,
          fmt::format("top_fraction = {}: must be 0 .. 1", options.top_fraction));
  require(options.width == 2 || options.width == 8,
          fmt::format("width = {}: must be 2 (binary blocks) or 8 (8-wide quantized nodes)", options.width));
}

SnappedTree build_snapped_tree(const TriangleMesh& mesh, const HmqOptions& options) {
  check_options(options);
  if (mesh.triangle_count() == 0) throw std::invalid_argument("hmq: the mesh has no triangles");
  SnappedTree snapped;
  PhaseClock clock;
  const Bounds3 grid_box = options.grid_bounds.value_or(mesh.bounds());
  snapped.grid = options.epsilon > 0.0 ? grid_from_epsilon(grid_box, options.epsilon) : grid_from_bits(grid_box, options.bits);
  const GlobalGrid& grid = snapped.grid;
  snapped.quantized = {&mesh, std::vector<glm::ivec3>(mesh.vertex_count())};
  QuantizedMesh& quantized = snapped.quantized;
  tbb::parallel_for(std::size_t{0}, mesh.vertex_count(),
                    [&](std::size_t v) { quantized.lines[v] = grid.snap(mesh.positions[v]); });
  LargeArray<SahReference> references(mesh.triangle_count());
  tbb::parallel_for(std::size_t{0}, mesh.triangle_count(), [&](std::size_t t) {
    Bounds3 box;
    for (int k = 0; k < 3; ++k) box.extend(grid.point(quantized.lines[mesh.triangles[t][k]]));
    references[t] = {box, static_cast<std::uint32_t>(t), 0};
  });
  clock.lap(snapped.phases, "snap");
  SahOptions sah;
  sah.max_leaf_size = options.leaf_triangles();
  sah.bins = options.bins;
  // A leaf record has a fixed cost (header, id base, the vertices it shares with others) that
  // makes small leaves expensive in bytes; a traversal step priced at half a full leaf keeps leaves
  // near full, as in the paper's Table 2 (about 3.3, 6.2 and 9.2 triangles per leaf for
  // leaf sizes 4, 8, 12 on Lucy).
  sah.traversal_cost = 0.5f * float(options.leaf_triangles());
  snapped.tree = build_sah_tree(std::move(references), sah);
  clock.lap(snapped.phases, "sah");
  snapped.peak_bytes = snapped.tree.peak_bytes;
  return snapped;
}

TriangleMesh snapped_mesh(const GlobalGrid& grid, const TriangleMesh& source) {
  TriangleMesh snapped = source;
  for (glm::vec3& p : snapped.positions) p = grid.point(grid.snap(p));
  return snapped;
}

}  // namespace wavetrace::hmq
