// Stochastic pruning (Cook et al. 2007, which the paper used for its furry squirrel): keep
// each triangle with probability `share` and scale it about its centroid by 1/sqrt(share),
// so the expected area, and roughly the occlusion, of aggregate detail is kept where
// clustering would erase it. The result is a triangle soup.
#pragma once

#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// Deterministic (the choice hashes the triangle index, `first_id` + the mesh's own: a chunk
// of a scene keeps the triangles the whole scene would). share in (0, 1].
TriangleMesh simplify_stochastically(const TriangleMesh& mesh, double share, std::size_t first_id = 0);

}  // namespace wavetrace
