// Per-batch key computation: the heuristic and curve are chosen once per batch, the loop
// over rays is a template instance with no branch on them.
#include "wavetrace/stages/reorder_keys.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>

#include "wavetrace/kernels/space_filling_curve.hpp"

namespace wavetrace {
namespace {

// Maps a point of the box to cells of 2^bits per axis, clamping what lies outside (camera
// origins, virtual hit points on the box's faces).
struct Quantizer {
  Quantizer(const Bounds3& bounds, int bits) : lower(bounds.lower), cells(float(std::uint32_t{1} << bits)) {
    const glm::vec3 extent = glm::max(bounds.extent(), glm::vec3(1e-30f));
    scale = cells / extent;
  }
  std::uint32_t cell(float value, int axis) const {
    const float position = (value - lower[axis]) * scale[axis];
    return static_cast<std::uint32_t>(std::clamp(position, 0.0f, cells - 1.0f));
  }
  std::uint32_t unit_cell(float unit) const {  // a value in [0, 1]
    return static_cast<std::uint32_t>(std::clamp(unit * cells, 0.0f, cells - 1.0f));
  }
  glm::vec3 lower;
  glm::vec3 scale;
  float cells;
};

// The octahedral map of a unit direction onto [0, 1]^2: continuous over the sphere except
// along the lower hemisphere's diagonal seams, and cheap.
std::array<float, 2> octahedral(float x, float y, float z) {
  const float norm = std::fabs(x) + std::fabs(y) + std::fabs(z);
  float u = x / norm, v = y / norm;
  if (z < 0.0f) {
    const float folded_u = (1.0f - std::fabs(v)) * (u >= 0.0f ? 1.0f : -1.0f);
    const float folded_v = (1.0f - std::fabs(u)) * (v >= 0.0f ? 1.0f : -1.0f);
    u = folded_u;
    v = folded_v;
  }
  return {(u + 1.0f) * 0.5f, (v + 1.0f) * 0.5f};
}

template <ReorderHeuristic kHeuristic>
constexpr int kDimensions = kHeuristic == ReorderHeuristic::hph_origin                                        ? 6
                            : kHeuristic == ReorderHeuristic::origin_dir || kHeuristic == ReorderHeuristic::hph_dir ? 5
                                                                                                                  : 3;

template <ReorderHeuristic kHeuristic, CurveKind kCurve>
void keys_for(RayBatch& rays, const Bounds3& bounds) {
  constexpr int kBits = kHeuristic == ReorderHeuristic::origin || kHeuristic == ReorderHeuristic::hph ? 20
                        : kHeuristic == ReorderHeuristic::hph_origin                                 ? 10
                                                                                                     : 12;
  constexpr int D = kDimensions<kHeuristic>;
  const Quantizer quantize(bounds, kBits);
  const auto cell_of = [&](std::size_t i) {
    const std::array<std::uint32_t, 3> origin{quantize.cell(rays.origin_x[i], 0), quantize.cell(rays.origin_y[i], 1),
                                              quantize.cell(rays.origin_z[i], 2)};
    const auto hit = [&] {
      return std::array<std::uint32_t, 3>{quantize.cell(rays.approx_hit_x[i], 0), quantize.cell(rays.approx_hit_y[i], 1),
                                          quantize.cell(rays.approx_hit_z[i], 2)};
    };
    const auto direction = [&] {
      const auto uv = octahedral(rays.direction_x[i], rays.direction_y[i], rays.direction_z[i]);
      return std::array<std::uint32_t, 2>{quantize.unit_cell(uv[0]), quantize.unit_cell(uv[1])};
    };
    if constexpr (kHeuristic == ReorderHeuristic::origin) {
      return origin;
    } else if constexpr (kHeuristic == ReorderHeuristic::hph) {
      return hit();
    } else if constexpr (kHeuristic == ReorderHeuristic::origin_dir) {
      const auto d = direction();
      return std::array<std::uint32_t, 5>{origin[0], origin[1], origin[2], d[0], d[1]};
    } else if constexpr (kHeuristic == ReorderHeuristic::hph_dir) {
      const auto h = hit();
      const auto d = direction();
      return std::array<std::uint32_t, 5>{h[0], h[1], h[2], d[0], d[1]};
    } else {
      const auto h = hit();
      return std::array<std::uint32_t, 6>{h[0], h[1], h[2], origin[0], origin[1], origin[2]};
    }
  };
  // Shadow rays walk the curve backward. A flush holding both kinds is then two sweeps over
  // the world, forward and back, and each sweep starts where the one before it ended: among the
  // pages a pool under LRU still holds, not among those the last sweep evicted first.
  constexpr std::uint64_t kLastCurveIndex = (std::uint64_t{1} << (D * kBits)) - 1;
  static_assert(D * kBits < 63, "bit 63 is the shadow bit");
  const auto set_key = [&](std::size_t i, std::uint64_t key) {
    rays.sort_key[i] = rays.kind[i] == RayKind::shadow ? (std::uint64_t{1} << 63) | (kLastCurveIndex - key) : key;
  };
  if constexpr (kCurve == CurveKind::morton) {
    for (std::size_t i = 0; i < rays.count; ++i) set_key(i, morton_key<D, kBits>(cell_of(i)));
  } else {
    // Skilling's transform in lanes, kHilbertLanes rays at a time.
    for (std::size_t first = 0; first < rays.count; first += kHilbertLanes) {
      const std::size_t lanes = std::min(kHilbertLanes, rays.count - first);
      std::uint32_t cells[D][kHilbertLanes] = {};
      for (std::size_t lane = 0; lane < lanes; ++lane) {
        const std::array<std::uint32_t, D> cell = cell_of(first + lane);
        for (int d = 0; d < D; ++d) cells[d][lane] = cell[d];
      }
      std::uint64_t keys[kHilbertLanes];
      hilbert_keys<D, kBits>(cells, keys);
      for (std::size_t lane = 0; lane < lanes; ++lane) set_key(first + lane, keys[lane]);
    }
  }
}

template <CurveKind kCurve>
void keys_for_curve(RayBatch& rays, ReorderHeuristic heuristic, const Bounds3& bounds) {
  switch (heuristic) {
    case ReorderHeuristic::origin: return keys_for<ReorderHeuristic::origin, kCurve>(rays, bounds);
    case ReorderHeuristic::origin_dir: return keys_for<ReorderHeuristic::origin_dir, kCurve>(rays, bounds);
    case ReorderHeuristic::hph: return keys_for<ReorderHeuristic::hph, kCurve>(rays, bounds);
    case ReorderHeuristic::hph_origin: return keys_for<ReorderHeuristic::hph_origin, kCurve>(rays, bounds);
    case ReorderHeuristic::hph_dir: return keys_for<ReorderHeuristic::hph_dir, kCurve>(rays, bounds);
    case ReorderHeuristic::none:
      for (std::size_t i = 0; i < rays.count; ++i) rays.sort_key[i] = 0;
      return;
  }
}

}  // namespace

ReorderHeuristic parse_reorder_heuristic(const std::string& text) {
  for (ReorderHeuristic h : {ReorderHeuristic::none, ReorderHeuristic::origin, ReorderHeuristic::origin_dir,
                             ReorderHeuristic::hph, ReorderHeuristic::hph_origin, ReorderHeuristic::hph_dir}) {
    if (to_string(h) == text) return h;
  }
  throw std::invalid_argument("unknown reorder heuristic '" + text +
                              "' (known: none, origin, origin_dir, hph, hph_origin, hph_dir)");
}

std::string to_string(ReorderHeuristic heuristic) {
  switch (heuristic) {
    case ReorderHeuristic::none: return "none";
    case ReorderHeuristic::origin: return "origin";
    case ReorderHeuristic::origin_dir: return "origin_dir";
    case ReorderHeuristic::hph: return "hph";
    case ReorderHeuristic::hph_origin: return "hph_origin";
    case ReorderHeuristic::hph_dir: return "hph_dir";
  }
  return "?";
}

CurveKind parse_curve_kind(const std::string& text) {
  if (text == "morton") return CurveKind::morton;
  if (text == "hilbert") return CurveKind::hilbert;
  throw std::invalid_argument("unknown curve '" + text + "' (known: morton, hilbert)");
}

std::string to_string(CurveKind curve) { return curve == CurveKind::morton ? "morton" : "hilbert"; }

bool uses_hit_points(ReorderHeuristic heuristic) {
  return heuristic == ReorderHeuristic::hph || heuristic == ReorderHeuristic::hph_origin ||
         heuristic == ReorderHeuristic::hph_dir;
}

void compute_sort_keys(RayBatch& rays, ReorderHeuristic heuristic, CurveKind curve, const Bounds3& bounds) {
  rays.enable_sort_key();
  if (uses_hit_points(heuristic) && !rays.has_approx_hit()) {
    throw std::logic_error("hit-point keys need approx_hit before zsort");
  }
  if (curve == CurveKind::morton) {
    keys_for_curve<CurveKind::morton>(rays, heuristic, bounds);
  } else {
    keys_for_curve<CurveKind::hilbert>(rays, heuristic, bounds);
  }
}

}  // namespace wavetrace
