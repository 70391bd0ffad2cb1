// Ordering keys of the reordering paper (§4.3, §6): a ray's hit point, origin and/or
// direction quantized in the scene's box and laid along a Z or Hilbert curve.
//   origin       3D, 20 bits per axis     hph          3D, 20 bits (a 60-bit key, the paper's k)
//   origin_dir   5D, 12 bits              hph_origin   6D, 10 bits
//                                         hph_dir      5D, 12 bits
// A direction is two dimensions: its octahedral map onto the unit square. Bit 63 puts
// shadow rays after closest-hit rays, so trace gets long runs of one query kind; below it a
// shadow ray's index is counted from the curve's far end (the sweep back: reorder_keys.cpp).
#pragma once

#include <cstdint>
#include <string>

#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

enum class ReorderHeuristic { none, origin, origin_dir, hph, hph_origin, hph_dir };
enum class CurveKind { morton, hilbert };

ReorderHeuristic parse_reorder_heuristic(const std::string& text);  // throws std::invalid_argument
std::string to_string(ReorderHeuristic heuristic);
CurveKind parse_curve_kind(const std::string& text);
std::string to_string(CurveKind curve);
bool uses_hit_points(ReorderHeuristic heuristic);  // needs approx_hit before zsort

// Writes rays.sort_key for rays [0, count) (enabling the column). Hit-point heuristics
// read the approximate hit column, which approx_hit fills. `bounds` is the scene's box.
void compute_sort_keys(RayBatch& rays, ReorderHeuristic heuristic, CurveKind curve, const Bounds3& bounds);

}  // namespace wavetrace
