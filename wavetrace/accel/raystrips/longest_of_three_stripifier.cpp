// OpenMesh's StripifierT, the rasterization stripifier the paper's Stripe stands for, on flat
// arrays: from each triangle not yet in a strip, in order, three strips are grown, one from
// each of its edges and in both directions, and the longest is kept. Written here rather
// than called because OpenMesh needs a TriMesh copy of every sub-mesh (its half-edge kernel's
// checks, property handles, a std::list a strip): its stripifier took three times the SAH's
// time in a raystrips build (53.8 thread-seconds at room:64M). On a sub-mesh OpenMesh holds
// whole, these are its strips, vertex for vertex (tested).
#include <algorithm>
#include <limits>
#include <stdexcept>
#include <string>

#include "wavetrace/accel/raystrips/stripify.hpp"

namespace wavetrace {
namespace {

constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();
constexpr std::uint64_t kEmpty = ~std::uint64_t{0};  // no edge: its two vertices would be one

// Half-edge h = 3 t + k of local triangle t runs from corner k to corner k + 1, as OpenMesh's
// add_face(a, b, c) links them; the triangle's own half-edge (where OpenMesh's walk starts)
// is its last, c -> a.
constexpr std::uint32_t next(std::uint32_t h) { return h % 3 == 2 ? h - 2 : h + 1; }
constexpr std::uint32_t prev(std::uint32_t h) { return h % 3 == 0 ? h + 2 : h - 1; }

// One strip grown from a half-edge: the vertices and triangles met going back (front_*,
// in the order met; they come first in the strip, reversed) and going on (back_*), and
// whether the strip needs a swap at its start to keep its winding (`flip`).
struct Experiment {
  std::vector<std::uint32_t> front_vertices, back_vertices, front_faces, back_faces;
  bool flip = false;
  std::size_t vertex_count() const { return front_vertices.size() + back_vertices.size() + (flip ? 1 : 0); }
};

// An edge's slot in the table that pairs half-edges.
struct EdgeSlot {
  std::uint64_t edge;  // low vertex << 32 | high vertex, or kEmpty
  std::uint32_t first, second;
  std::uint32_t count;
};

// A thread's arrays, kept from one sub-mesh to the next: under the 8-wide top sub-meshes are
// 24 triangles, and allocating these afresh for each was most of the stripifier's time.
struct Scratch {
  std::vector<std::uint32_t> opposite;  // per half-edge, or kNone
  std::vector<std::uint8_t> state;      // per local triangle: kProcessed (in a strip), kUsed (in this experiment)
  std::vector<std::uint32_t> degenerate;
  std::vector<EdgeSlot> table;
  Experiment experiments[3];
};

class LongestOfThree {
 public:
  LongestOfThree(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles, Scratch& scratch)
      : mesh_(mesh), triangles_(triangles), opposite_(scratch.opposite), state_(scratch.state),
        degenerate_(scratch.degenerate), table_(scratch.table), experiments_(scratch.experiments) {
    opposite_.assign(3 * triangles.size(), kNone);
    state_.assign(triangles.size(), 0);
    degenerate_.clear();
    // Degenerate triangles, which OpenMesh refuses, take no part in the walk.
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
      const glm::uvec3& c = corners(t);
      if (c.x == c.y || c.y == c.z || c.z == c.x) {
        state_[t] = kProcessed;
        degenerate_.push_back(t);
      }
    }
    pair_half_edges();
  }

  std::vector<TriangleStrip> run() {
    std::vector<TriangleStrip> strips;
    // Degenerate triangles are strips of one, first, as the OpenMesh path makes them.
    for (const std::uint32_t t : degenerate_) {
      const glm::uvec3& c = corners(t);
      strips.push_back({{c.x, c.y, c.z}, {triangles_[t]}});
    }
    Experiment* experiments = experiments_;
    for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
      if (state_[t] & kProcessed) continue;
      const std::uint32_t start[3] = {3 * t + 2, 3 * t, 3 * t + 1};
      std::size_t best = 0;
      for (std::size_t i = 0; i < 3; ++i) {
        grow(start[i], experiments[i]);
        if (experiments[i].vertex_count() > experiments[best].vertex_count()) best = i;
        for (const std::uint32_t face : experiments[i].front_faces) state_[face] &= ~kUsed;
        for (const std::uint32_t face : experiments[i].back_faces) state_[face] &= ~kUsed;
      }
      const Experiment& chosen = experiments[best];
      for (const std::uint32_t face : chosen.front_faces) state_[face] |= kProcessed;
      for (const std::uint32_t face : chosen.back_faces) state_[face] |= kProcessed;
      strips.push_back(to_strip(chosen));
    }
    return strips;
  }

 private:
  static constexpr std::uint8_t kProcessed = 1, kUsed = 2;

  const glm::uvec3& corners(std::uint32_t t) const { return mesh_.triangles[triangles_[t]]; }
  std::uint32_t from(std::uint32_t h) const { return corners(h / 3)[int(h % 3)]; }
  std::uint32_t to(std::uint32_t h) const { return corners(h / 3)[int(next(h) % 3)]; }

  // Half-edges a -> b and b -> a are opposite where they are the edge's only two, as in a
  // mesh OpenMesh holds; any other edge is a boundary to the walk. The edges meet in an
  // open-addressing table (a sub-mesh is a few hundred triangles: sorting its half-edges
  // took most of the stripifier's time).
  void pair_half_edges() {
    std::size_t size = 16;
    while (size < 2 * opposite_.size()) size *= 2;
    std::vector<EdgeSlot>& table = table_;
    table.assign(size, EdgeSlot{kEmpty, 0, 0, 0});
    for (std::uint32_t h = 0; h < opposite_.size(); ++h) {
      if (state_[h / 3] & kProcessed) continue;
      const std::uint32_t a = from(h), b = to(h);
      const std::uint64_t edge = std::uint64_t(std::min(a, b)) << 32 | std::max(a, b);
      std::size_t at = std::size_t((edge * 0x9E3779B97F4A7C15ull) >> 40) & (size - 1);
      while (table[at].edge != kEmpty && table[at].edge != edge) at = (at + 1) & (size - 1);
      EdgeSlot& slot = table[at];
      if (slot.count == 0) slot.edge = edge, slot.first = h;
      if (slot.count == 1) slot.second = h;
      ++slot.count;
    }
    for (const EdgeSlot& slot : table) {
      // Opposite directions: the two triangles agree on their winding.
      if (slot.count == 2 && from(slot.first) == to(slot.second)) {
        opposite_[slot.first] = slot.second;
        opposite_[slot.second] = slot.first;
      }
    }
  }

  // OpenMesh's steps: "right" crosses the edge after h, "left" the edge h itself.
  std::uint32_t right(std::uint32_t h) const {
    const std::uint32_t o = opposite_[next(h)];
    return o == kNone ? kNone : next(o);
  }
  std::uint32_t left(std::uint32_t h) const {
    const std::uint32_t o = opposite_[h];
    return o == kNone ? kNone : next(o);
  }
  // The triangle of h joins the strip unless the walk left the mesh or met a triangle taken.
  bool take(std::uint32_t h, std::vector<std::uint32_t>& faces) {
    if (h == kNone || state_[h / 3] != 0) return false;
    state_[h / 3] |= kUsed;
    faces.push_back(h / 3);
    return true;
  }

  void grow(std::uint32_t start, Experiment& strip) {
    strip.front_vertices.clear();
    strip.front_faces.clear();
    strip.back_faces.clear();
    strip.back_vertices.assign({from(start), to(start)});
    // On: the first step lands on the start triangle itself.
    for (std::uint32_t h = next(start);; h = right(h)) {
      if (!take(h, strip.back_faces)) break;
      strip.back_vertices.push_back(to(h));
      h = left(h);
      if (!take(h, strip.back_faces)) break;
      strip.back_vertices.push_back(to(h));
    }
    // Back, across the start edge.
    strip.flip = false;
    for (std::uint32_t h = prev(start);;) {
      h = right(h);
      if (!take(h, strip.front_faces)) break;
      strip.front_vertices.push_back(to(h));
      strip.flip = true;
      h = left(h);
      if (!take(h, strip.front_faces)) break;
      strip.front_vertices.push_back(to(h));
      strip.flip = false;
    }
  }

  TriangleStrip to_strip(const Experiment& e) const {
    TriangleStrip strip;
    strip.vertices.reserve(e.vertex_count());
    strip.triangles.reserve(e.vertex_count() - 2);
    if (e.flip) {
      strip.vertices.push_back(e.front_vertices.back());
      strip.triangles.push_back(kNoTriangle);  // the swap: zero area, never hit
    }
    strip.vertices.insert(strip.vertices.end(), e.front_vertices.rbegin(), e.front_vertices.rend());
    strip.vertices.insert(strip.vertices.end(), e.back_vertices.begin(), e.back_vertices.end());
    for (auto face = e.front_faces.rbegin(); face != e.front_faces.rend(); ++face) strip.triangles.push_back(triangles_[*face]);
    for (const std::uint32_t face : e.back_faces) strip.triangles.push_back(triangles_[face]);
    return strip;
  }

  const TriangleMesh& mesh_;
  std::span<const std::uint32_t> triangles_;
  std::vector<std::uint32_t>& opposite_;
  std::vector<std::uint8_t>& state_;
  std::vector<std::uint32_t>& degenerate_;
  std::vector<EdgeSlot>& table_;
  Experiment* experiments_;
};

}  // namespace

std::vector<TriangleStrip> stripify_longest_of_three(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                                     std::uint32_t max_triangles) {
  if (max_triangles < 1) throw std::invalid_argument("a strip needs room for one triangle");
  if (triangles.empty()) return {};
  if (triangles.size() > (kNone - 3) / 3) {
    throw std::length_error("a sub-mesh of " + std::to_string(triangles.size()) +
                            " triangles is beyond the stripifier's 32-bit half-edge ids");
  }
  thread_local Scratch scratch;
  return cut_long_strips(LongestOfThree(mesh, triangles, scratch).run(), max_triangles);
}

}  // namespace wavetrace
