// Our stripifier: a greedy walk over the sub-mesh's dual graph. OpenMesh's StripifierT is
// built for vertex-cache reuse and grows each strip straight until it runs out; a Ray-Strip
// wants few, long strips (every strip costs a top-BVH leaf) whose halves are spatially
// compact (they are the kd-tree's boxes), so the walk starts at the most constrained
// triangle and keeps to the boundary of the unused region, turning whenever that pays.
#include <algorithm>
#include <array>
#include <stdexcept>

#include "wavetrace/accel/raystrips/stripify.hpp"

namespace wavetrace {
namespace {

struct EdgeSlot {
  std::uint32_t low, high;  // the edge's vertices, low < high
  std::uint32_t slot;       // 3 * local triangle + edge
  bool operator<(const EdgeSlot& other) const {
    return low != other.low ? low < other.low : (high != other.high ? high < other.high : slot < other.slot);
  }
};

bool is_degenerate(const glm::uvec3& corners) {
  return corners.x == corners.y || corners.y == corners.z || corners.z == corners.x;
}

// neighbour[3 t + e]: the local triangle across edge e = (corner e, corner e + 1) of t, or
// kNoTriangle on a boundary or non-manifold edge (more than two triangles share it).
std::vector<std::uint32_t> neighbours(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles) {
  std::vector<EdgeSlot> edges;
  edges.reserve(3 * triangles.size());
  for (std::uint32_t t = 0; t < triangles.size(); ++t) {
    const glm::uvec3& corners = mesh.triangles[triangles[t]];
    if (is_degenerate(corners)) continue;
    for (std::uint32_t e = 0; e < 3; ++e) {
      const std::uint32_t a = corners[e], b = corners[(e + 1) % 3];
      edges.push_back({std::min(a, b), std::max(a, b), 3 * t + e});
    }
  }
  std::sort(edges.begin(), edges.end());
  std::vector<std::uint32_t> across(3 * triangles.size(), kNoTriangle);
  for (std::size_t i = 0; i < edges.size();) {
    std::size_t j = i + 1;
    while (j < edges.size() && edges[j].low == edges[i].low && edges[j].high == edges[i].high) ++j;
    if (j - i == 2) {
      across[edges[i].slot] = edges[i + 1].slot / 3;
      across[edges[i + 1].slot] = edges[i].slot / 3;
    }
    i = j;
  }
  return across;
}

std::uint32_t opposite_corner(const glm::uvec3& corners, std::uint32_t a, std::uint32_t b) {
  for (int k = 0; k < 3; ++k) {
    if (corners[k] != a && corners[k] != b) return corners[k];
  }
  return corners.x;  // unreachable for a non-degenerate triangle across (a, b)
}

class DualPathWalker {
 public:
  DualPathWalker(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles)
      : mesh_(mesh), triangles_(triangles), across_(neighbours(mesh, triangles)),
        used_(triangles.size(), false), unused_degree_(triangles.size(), 0) {
    for (std::uint32_t t = 0; t < triangles.size(); ++t) {
      for (int e = 0; e < 3; ++e) unused_degree_[t] += across_[3 * t + e] != kNoTriangle;
    }
  }

  std::vector<TriangleStrip> run(std::uint32_t max_triangles) {
    std::vector<TriangleStrip> strips;
    std::uint32_t remaining = static_cast<std::uint32_t>(triangles_.size());
    while (remaining > 0) {
      TriangleStrip strip = walk_from(most_constrained(), max_triangles);
      remaining -= walked_;
      strips.push_back(std::move(strip));
    }
    return strips;
  }

 private:
  // The unused triangle with the fewest unused neighbours (ties: the first in order).
  std::uint32_t most_constrained() {
    std::uint32_t best = kNoTriangle;
    while (used_[cursor_]) ++cursor_;  // everything before the cursor is used
    for (std::uint32_t t = cursor_; t < triangles_.size(); ++t) {
      if (used_[t]) continue;
      if (best == kNoTriangle || unused_degree_[t] < unused_degree_[best]) best = t;
      if (unused_degree_[best] == 0) break;
    }
    return best;
  }

  void mark_used(std::uint32_t t) {
    used_[t] = true;
    ++walked_;
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t other = across_[3 * t + e];
      if (other != kNoTriangle && !used_[other]) --unused_degree_[other];
    }
  }

  // The unused triangle across the edge (a, b) of local triangle t, if any.
  std::uint32_t unused_across(std::uint32_t t, std::uint32_t a, std::uint32_t b) const {
    const glm::uvec3& corners = mesh_.triangles[triangles_[t]];
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t p = corners[e], q = corners[(e + 1) % 3];
      if ((p == a && q == b) || (p == b && q == a)) {
        const std::uint32_t other = across_[3 * t + e];
        return other != kNoTriangle && !used_[other] ? other : kNoTriangle;
      }
    }
    return kNoTriangle;
  }

  TriangleStrip walk_from(std::uint32_t start, std::uint32_t max_triangles) {
    walked_ = 0;
    TriangleStrip strip;
    const glm::uvec3& corners = mesh_.triangles[triangles_[start]];
    mark_used(start);
    // First step: towards the most constrained unused neighbour.
    int first_edge = -1;
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t other = across_[3 * start + e];
      if (other == kNoTriangle || used_[other]) continue;
      if (first_edge < 0 || unused_degree_[other] < unused_degree_[across_[3 * start + first_edge]]) first_edge = e;
    }
    if (first_edge < 0) first_edge = 0;
    const std::uint32_t p = corners[first_edge], q = corners[(first_edge + 1) % 3];
    strip.vertices = {corners[(first_edge + 2) % 3], p, q};
    strip.triangles = {triangles_[start]};
    std::uint32_t current = start;
    while (strip.triangles.size() + 2 <= max_triangles) {
      const std::size_t size = strip.vertices.size();
      const std::uint32_t r = strip.vertices[size - 3], s = strip.vertices[size - 2], last = strip.vertices[size - 1];
      const std::uint32_t straight = unused_across(current, s, last);
      const std::uint32_t turn = unused_across(current, r, last);
      if (straight == kNoTriangle && turn == kNoTriangle) break;
      const bool take_turn =
          straight == kNoTriangle || (turn != kNoTriangle && unused_degree_[turn] < unused_degree_[straight]);
      std::uint32_t next;
      if (take_turn) {
        // Repeating r makes (s, last, r) = the current triangle again; its last edge is (last, r).
        next = turn;
        strip.vertices.push_back(r);
        strip.triangles.push_back(triangles_[current]);
        strip.vertices.push_back(opposite_corner(mesh_.triangles[triangles_[next]], last, r));
      } else {
        next = straight;
        strip.vertices.push_back(opposite_corner(mesh_.triangles[triangles_[next]], s, last));
      }
      strip.triangles.push_back(triangles_[next]);
      mark_used(next);
      current = next;
    }
    return strip;
  }

  const TriangleMesh& mesh_;
  std::span<const std::uint32_t> triangles_;
  std::vector<std::uint32_t> across_;
  std::vector<bool> used_;
  std::vector<std::uint8_t> unused_degree_;
  std::uint32_t cursor_ = 0;
  std::uint32_t walked_ = 0;
};

}  // namespace

std::vector<TriangleStrip> stripify_dual_path(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                              std::uint32_t max_triangles) {
  if (max_triangles < 1) throw std::invalid_argument("a strip needs room for one triangle");
  if (triangles.empty()) return {};
  return DualPathWalker(mesh, triangles).run(max_triangles);
}

}  // namespace wavetrace
