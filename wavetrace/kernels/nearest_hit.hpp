// The order each of our accelerators keeps a ray's nearest hit by (Embree and tinybvh keep
// their own): the nearer distance, and at exactly the same distance the smaller triangle id of
// the input mesh.
//
// Why a rule for ties: two triangles can be hit at the same float t (duplicated or coplanar
// faces, a ray through a shared edge or vertex). Kept "first found wins" or "last found
// wins", the answer depends on the order the walk tested them in, and that order depends on
// more than the ray: on the companions of its packet (which rays a heuristic sorted next to
// it), on chunk order, on the layout. Images then differed between reorder heuristics in one
// path of 29.75M at room:64M. With this rule, and walks that never prune a tied triangle
// (pruning_distance), a ray's hit is a function of the ray and the mesh alone. The ids are
// asked for only on an exact tie, where they may cost a decode.
#pragma once

namespace wavetrace {

// True when a hit at `t` replaces the nearest so far, at `nearest_t` (`found` tells whether
// there is one; before the first, `nearest_t` is the ray's tmax and a hit there counts).
template <typename IdOf, typename NearestIdOf>
[[gnu::always_inline]] inline bool replaces_nearest(float t, float nearest_t, bool found, IdOf&& id,
                                                    NearestIdOf&& nearest_id) {
  if (t != nearest_t) return t < nearest_t;
  return !found || id() < nearest_id();
}

// Walks prune a node (a box, a kd-tree half, a chunk) only when it begins beyond this widening
// of the nearest hit's t. A node's entry distance and a triangle's t are rounded differently
// (the slab test's one product against the watertight test's sums and quotient): a triangle
// hit at exactly the nearest t, a tie for the id to decide, can lie in a node whose computed
// entry is an ulp or a few beyond it. Pruned at t itself, whether the tied triangle is tested
// at all would depend on which of the two the walk met first. 2^-12 is far above the rounding
// of either; measured cost in accelerators.md ("Equally near hits": none for the BVHs, HMQ and
// the grids, about 7% for Ray-Strips on a room of flat walls).
inline constexpr float kPruningSlack = 1.0f + 0x1p-12f;
[[gnu::always_inline]] inline float pruning_distance(float tmax) { return tmax * kPruningSlack; }

}  // namespace wavetrace
