// Stripification of one sub-mesh (§4.2): its triangles as few, long generalized triangle
// strips. Three stripifiers: OpenMesh's StripifierT (the rasterization stripifier the paper's
// Stripe stands for), its algorithm on flat arrays, and our own dual-path walker.
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

enum class StripifierKind {
  // Ours: walks the sub-mesh's dual graph from its most constrained triangle, always to the
  // unused neighbour with the fewest unused neighbours (so the strip hugs the boundary of
  // what is left and winds up compact), turning through a repeated triangle when needed.
  dual_path,
  // OpenMesh's StripifierT on a TriMesh copy of the sub-mesh (non-manifold faces it cannot
  // hold become strips of one triangle).
  openmesh,
  // OpenMesh's algorithm on the sub-mesh's own arrays: from each triangle not yet in a strip,
  // in order, a strip grown from each of its three edges, the longest kept. OpenMesh's strips
  // where it holds the sub-mesh whole; a non-manifold edge is a boundary to it.
  longest_of_three,
};
StripifierKind parse_stripifier(const std::string& text);  // "dual_path" | "openmesh" | "longest_of_three"
std::string to_string(StripifierKind kind);

inline constexpr std::uint32_t kNoTriangle = std::numeric_limits<std::uint32_t>::max();

// A generalized strip: triangle k has the corners (vertices[k], vertices[k+1], vertices[k+2]).
struct TriangleStrip {
  std::vector<std::uint32_t> vertices;   // mesh vertex ids, triangles.size() + 2 of them
  std::vector<std::uint32_t> triangles;  // the mesh triangle of each strip triangle (repeats
                                         // after turns); kNoTriangle for a degenerate one
};

// Strips covering exactly the given mesh triangles (each at least once, never another),
// none longer than `max_triangles` strip triangles.
std::vector<TriangleStrip> stripify(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                    StripifierKind kind, std::uint32_t max_triangles);

std::vector<TriangleStrip> stripify_dual_path(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                              std::uint32_t max_triangles);
std::vector<TriangleStrip> stripify_openmesh(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                             std::uint32_t max_triangles);
std::vector<TriangleStrip> stripify_longest_of_three(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                                     std::uint32_t max_triangles);

// Strips longer than `max_triangles` cut into pieces that overlap in two vertices; pieces of
// swaps only dropped.
std::vector<TriangleStrip> cut_long_strips(std::vector<TriangleStrip> strips, std::uint32_t max_triangles);

}  // namespace wavetrace
