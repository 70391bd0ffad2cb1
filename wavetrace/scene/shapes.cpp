// Procedural shapes the builtin scenes are composed of, as generators of any triangle range.
// The sphere is an icosahedron whose faces are split into n x n triangle lattices with
// globally shared vertices, so it is closed.
#include "wavetrace/scene/shapes.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <optional>
#include <map>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <tbb/parallel_for.h>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/kernels/sampling.hpp"
#include "wavetrace/scene/noise.hpp"
#include "wavetrace/scene/shape_generator.hpp"

namespace wavetrace {
namespace {

constexpr float kDisplacementAmplitude = 0.12f;
constexpr float kDisplacementFrequency = 2.5f;
constexpr int kDisplacementOctaves = 7;

// The regular icosahedron: 12 corners, 20 outward-facing (counter-clockwise) faces.
struct Icosahedron {
  std::array<glm::vec3, 12> corners;
  std::array<glm::uvec3, 20> faces;
  std::array<glm::uvec2, 30> edges;  // (low, high) corner pairs
  std::map<std::pair<std::uint32_t, std::uint32_t>, std::uint32_t> edge_of;

  Icosahedron() {
    const float phi = (1.0f + std::sqrt(5.0f)) * 0.5f;
    corners = {glm::vec3(-1, phi, 0), glm::vec3(1, phi, 0),   glm::vec3(-1, -phi, 0), glm::vec3(1, -phi, 0),
               glm::vec3(0, -1, phi), glm::vec3(0, 1, phi),   glm::vec3(0, -1, -phi), glm::vec3(0, 1, -phi),
               glm::vec3(phi, 0, -1), glm::vec3(phi, 0, 1),   glm::vec3(-phi, 0, -1), glm::vec3(-phi, 0, 1)};
    for (glm::vec3& corner : corners) corner = glm::normalize(corner);
    faces = {glm::uvec3(0, 11, 5), glm::uvec3(0, 5, 1),  glm::uvec3(0, 1, 7),   glm::uvec3(0, 7, 10),
             glm::uvec3(0, 10, 11), glm::uvec3(1, 5, 9),  glm::uvec3(5, 11, 4),  glm::uvec3(11, 10, 2),
             glm::uvec3(10, 7, 6), glm::uvec3(7, 1, 8),   glm::uvec3(3, 9, 4),   glm::uvec3(3, 4, 2),
             glm::uvec3(3, 2, 6),  glm::uvec3(3, 6, 8),   glm::uvec3(3, 8, 9),   glm::uvec3(4, 9, 5),
             glm::uvec3(2, 4, 11), glm::uvec3(6, 2, 10),  glm::uvec3(8, 6, 7),   glm::uvec3(9, 8, 1)};
    std::uint32_t next = 0;
    for (const glm::uvec3& face : faces) {
      for (int k = 0; k < 3; ++k) {
        const auto key = std::minmax(face[k], face[(k + 1) % 3]);
        if (edge_of.emplace(std::pair(key.first, key.second), next).second) {
          edges[next++] = glm::uvec2(key.first, key.second);
        }
      }
    }
  }
};

const Icosahedron& icosahedron() {
  static const Icosahedron instance;
  return instance;
}

// Global vertex numbering of the frequency-n icosphere: 12 corners, then n-1 points per
// edge (ordered from the edge's lower corner), then the (n-1)(n-2)/2 interior points per face.
class IcosphereLattice {
 public:
  explicit IcosphereLattice(std::uint32_t n) : n_(n) {}

  std::size_t vertex_count() const { return 12 + 30 * std::size_t(n_ - 1) + 20 * interior_per_face(); }
  std::size_t triangle_count() const { return 20 * std::size_t(n_) * n_; }

  // Vertex id of lattice point (i, j) of face f: A + (B-A) i/n + (C-A) j/n.
  std::uint32_t vertex(std::uint32_t face, std::uint32_t i, std::uint32_t j) const {
    const glm::uvec3& corners = icosahedron().faces[face];
    if (i == 0 && j == 0) return corners.x;
    if (i == n_ && j == 0) return corners.y;
    if (i == 0 && j == n_) return corners.z;
    if (j == 0) return edge_vertex(corners.x, corners.y, i);
    if (i == 0) return edge_vertex(corners.x, corners.z, j);
    if (i + j == n_) return edge_vertex(corners.y, corners.z, j);
    const std::uint32_t local = (i - 1) * (n_ - 1) - (i - 1) * i / 2 + (j - 1);
    return static_cast<std::uint32_t>(12 + 30 * std::size_t(n_ - 1) + face * interior_per_face() + local);
  }

  // Unit-sphere direction of every vertex id.
  glm::vec3 direction(std::size_t id) const {
    const Icosahedron& ico = icosahedron();
    if (id < 12) return ico.corners[id];
    id -= 12;
    if (id < 30 * std::size_t(n_ - 1)) {
      const glm::uvec2 edge = ico.edges[id / (n_ - 1)];
      const float s = float(id % (n_ - 1) + 1) / float(n_);
      return glm::normalize(ico.corners[edge.x] * (1.0f - s) + ico.corners[edge.y] * s);
    }
    id -= 30 * std::size_t(n_ - 1);
    const std::size_t face = id / interior_per_face();
    const std::size_t local = id % interior_per_face();
    const std::uint32_t row = interior_row(local);
    const std::uint32_t i = row + 1;
    const auto j = static_cast<std::uint32_t>(local - interior_row_start(row) + 1);
    const glm::uvec3& corners = ico.faces[face];
    const glm::vec3 a = ico.corners[corners.x], b = ico.corners[corners.y], c = ico.corners[corners.z];
    return glm::normalize(a + (b - a) * (float(i) / n_) + (c - a) * (float(j) / n_));
  }

 private:
  std::size_t interior_per_face() const { return n_ < 3 ? 0 : std::size_t(n_ - 1) * (n_ - 2) / 2; }
  // Interior row r (lattice row i = r + 1) holds n - 2 - r points and starts at
  // r (2n - 3 - r) / 2 within its face: the inverse of vertex()'s numbering.
  std::size_t interior_row_start(std::size_t row) const { return row * (2 * std::size_t(n_) - 3 - row) / 2; }
  // The row of a face's interior point, from the quadratic's root and then exact by integer
  // steps: walking the rows one by one cost O(n) a vertex, most of a billion-triangle
  // room's generation.
  std::uint32_t interior_row(std::size_t local) const {
    const double b = 2.0 * double(n_) - 3.0;
    const double root = 0.5 * (b - std::sqrt(std::max(0.0, b * b - 8.0 * double(local))));
    auto row = static_cast<std::size_t>(std::clamp(root, 0.0, double(n_ - 3)));
    while (row > 0 && interior_row_start(row) > local) --row;
    while (row + 1 <= n_ - 3 && interior_row_start(row + 1) <= local) ++row;
    return static_cast<std::uint32_t>(row);
  }
  std::uint32_t edge_vertex(std::uint32_t from, std::uint32_t to, std::uint32_t steps_from_start) const {
    const std::uint32_t edge = icosahedron().edge_of.at(std::minmax(from, to));
    const std::uint32_t steps = from < to ? steps_from_start : n_ - steps_from_start;
    return 12 + edge * (n_ - 1) + (steps - 1);
  }
  std::uint32_t n_;
};

std::uint32_t icosphere_frequency(std::size_t triangles) {
  const double n = std::round(std::sqrt(double(triangles) / 20.0));
  return static_cast<std::uint32_t>(std::max(1.0, n));
}


class SphereShape final : public ShapeGenerator {
 public:
  // A seed displaces the surface by fractal noise; none leaves it a smooth icosphere.
  SphereShape(std::size_t triangles, const glm::vec3& center, float radius, std::optional<std::uint32_t> seed,
              bool inward = false)
      : n_(icosphere_frequency(triangles)), lattice_(n_), center_(center), radius_(radius), seed_(seed), inward_(inward) {}
  std::size_t triangle_count() const override { return lattice_.triangle_count(); }
  std::size_t vertex_count() const override { return lattice_.vertex_count(); }
  glm::vec3 position(std::uint64_t id) const override {
    const glm::vec3 direction = lattice_.direction(id);
    if (!seed_) return center_ + direction * radius_;
    const float displacement =
        kDisplacementAmplitude * fractal_noise(direction * kDisplacementFrequency, kDisplacementOctaves, *seed_);
    return center_ + direction * (radius_ * (1.0f + displacement));
  }
  // |gradient noise| <= 2 (a corner's gradient has two unit components, its offsets are
  // within 1, the lerps' weights within [0, 1]) and the octaves' amplitudes sum below 1, so
  // the displacement is within 0.24 of the radius: 0.25 leaves room for rounding.
  std::optional<Bounds3> position_bound(std::uint64_t id) const override {
    static_assert(kDisplacementAmplitude * 2.0f < 0.25f);
    if (!seed_) return std::nullopt;
    const glm::vec3 direction = lattice_.direction(id);
    Bounds3 bound;
    bound.extend(center_ + direction * (radius_ * 0.75f));
    bound.extend(center_ + direction * (radius_ * 1.25f));
    return bound;
  }
  // Face f holds n^2 triangles in rows; row i has n-i "up" and n-i-1 "down" triangles,
  // interleaved up, down, up, ..., and starts at i (2n - i) within the face.
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    const std::size_t per_face = std::size_t(n_) * n_;
    std::uint32_t face = static_cast<std::uint32_t>(first / per_face);
    std::size_t in_face = first % per_face;
    std::uint32_t i = 0;
    while (std::size_t(i + 1) * (2 * n_ - i - 1) <= in_face) ++i;
    std::size_t p = in_face - std::size_t(i) * (2 * n_ - i);
    for (std::size_t done = 0; done < count; ++done) {
      const auto j = static_cast<std::uint32_t>(p / 2);
      std::uint64_t* corner = out + 3 * done;
      if (p % 2 == 0) {
        corner[0] = lattice_.vertex(face, i, j);
        corner[1] = lattice_.vertex(face, i + 1, j);
        corner[2] = lattice_.vertex(face, i, j + 1);
      } else {
        corner[0] = lattice_.vertex(face, i + 1, j);
        corner[1] = lattice_.vertex(face, i + 1, j + 1);
        corner[2] = lattice_.vertex(face, i, j + 1);
      }
      if (inward_) std::swap(corner[1], corner[2]);
      if (++p == 2 * std::size_t(n_ - i) - 1) {  // the row is done
        p = 0;
        if (++i == n_) {
          i = 0;
          ++face;
        }
      }
    }
  }

 private:
  std::uint32_t n_;
  IcosphereLattice lattice_;
  glm::vec3 center_;
  float radius_;
  std::optional<std::uint32_t> seed_;
  bool inward_;
};

// The sphere's triangles, each with three vertices of its own.
class SoupShape final : public ShapeGenerator {
 public:
  explicit SoupShape(std::size_t triangles, std::uint32_t seed) : sphere_(triangles, glm::vec3(0.0f), 1.0f, seed) {}
  std::size_t triangle_count() const override { return sphere_.triangle_count(); }
  std::size_t vertex_count() const override { return 3 * sphere_.triangle_count(); }
  glm::vec3 position(std::uint64_t key) const override {
    std::uint64_t corners[3];
    sphere_.corners(key / 3, 1, corners);
    return sphere_.position(corners[key % 3]);
  }
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    for (std::size_t k = 0; k < 3 * count; ++k) out[k] = 3 * first + k;
  }

 private:
  SphereShape sphere_;
};

class TerrainShape final : public ShapeGenerator {
 public:
  TerrainShape(std::size_t triangles, float size, float height, std::uint32_t seed)
      : cells_(static_cast<std::uint32_t>(std::max(1.0, std::round(std::sqrt(double(triangles) / 2.0))))),
        size_(size),
        height_(height),
        seed_(seed) {}
  std::size_t triangle_count() const override { return std::size_t(cells_) * cells_ * 2; }
  std::size_t vertex_count() const override { return std::size_t(cells_ + 1) * (cells_ + 1); }
  glm::vec3 position(std::uint64_t id) const override {
    const std::uint64_t row = cells_ + 1;
    const float fx = float(id % row) / cells_, fz = float(id / row) / cells_;
    const glm::vec3 ground((fx - 0.5f) * size_, 0.0f, (fz - 0.5f) * size_);
    const float y = height_ * fractal_noise(glm::vec3(fx * 4.0f, 0.37f, fz * 4.0f), 8, seed_);
    return ground + glm::vec3(0.0f, y, 0.0f);
  }
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    const std::uint64_t row = cells_ + 1;
    for (std::size_t t = first; t < first + count; ++t) {
      const std::uint64_t cell = t / 2, z = cell / cells_, x = cell % cells_;
      const std::uint64_t v00 = z * row + x, v10 = v00 + 1, v01 = v00 + row, v11 = v01 + 1;
      std::uint64_t* corner = out + 3 * (t - first);
      corner[0] = v00;  // counter-clockwise seen from +y
      corner[1] = t % 2 == 0 ? v01 : v11;
      corner[2] = t % 2 == 0 ? v11 : v10;
    }
  }

 private:
  std::uint32_t cells_;
  float size_, height_;
  std::uint32_t seed_;
};

// Thin open tubes of triangular cross-section growing from a sphere. Roots are spread over
// the icosahedron's faces in rows, so consecutive strands grow side by side and a run of
// strands (a chunk) covers a patch of the sphere, not all of it.
class StrandsShape final : public ShapeGenerator {
 public:
  static constexpr std::uint32_t kSegments = 4, kSides = 3, kRings = kSegments + 1;
  static constexpr std::uint32_t kTrianglesPerStrand = kSegments * kSides * 2;
  static constexpr std::uint32_t kVerticesPerStrand = kRings * kSides;

  StrandsShape(std::size_t triangles, float radius, float length, float width, std::uint32_t seed)
      : strands_(std::max<std::size_t>(1, triangles / kTrianglesPerStrand)),
        per_face_((strands_ + 19) / 20),
        columns_(static_cast<std::size_t>(std::ceil(std::sqrt(double(per_face_))))),
        radius_(radius),
        length_(length),
        width_(width),
        seed_(seed) {}
  std::size_t triangle_count() const override { return strands_ * kTrianglesPerStrand; }
  std::size_t vertex_count() const override { return strands_ * kVerticesPerStrand; }
  glm::vec3 position(std::uint64_t id) const override {
    const std::size_t s = id / kVerticesPerStrand;
    const std::uint32_t ring = static_cast<std::uint32_t>(id % kVerticesPerStrand) / kSides;
    const std::uint32_t side = static_cast<std::uint32_t>(id % kSides);
    // A strand's 15 vertices come one after another and share its frame: made once a strand
    // (a thread's last), and each side's cosine and sine once (the same float calls).
    thread_local StrandFrame last;
    if (last.instance != instance_ || last.strand != s) last = frame(s);
    static const std::array<std::array<float, 2>, kSides> around = [] {
      std::array<std::array<float, 2>, kSides> table{};
      for (std::uint32_t side = 0; side < kSides; ++side) {
        const float angle = 2.0f * 3.14159265f * float(side) / kSides;
        table[side] = {std::cos(angle), std::sin(angle)};
      }
      return table;
    }();
    const float along = float(ring) / kSegments;
    const glm::vec3 center = last.normal * (radius_ + length_ * along) + last.sway * (length_ * along * along);
    const float ring_width = width_ * (1.0f - 0.7f * along);
    return center + (last.tangent * around[side][0] + last.bitangent * around[side][1]) * ring_width;
  }
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    for (std::size_t t = first; t < first + count; ++t) {
      const std::uint64_t strand = t / kTrianglesPerStrand;
      const auto local = static_cast<std::uint32_t>(t % kTrianglesPerStrand);
      const std::uint32_t ring = local / (2 * kSides), side = local % (2 * kSides) / 2;
      const std::uint64_t base = strand * kVerticesPerStrand + ring * kSides;
      const std::uint64_t a = base + side, b = base + (side + 1) % kSides;
      std::uint64_t* corner = out + 3 * (t - first);
      corner[0] = a;
      corner[1] = local % 2 == 0 ? b : b + kSides;
      corner[2] = local % 2 == 0 ? b + kSides : a + kSides;
    }
  }

 private:
  struct StrandFrame {
    std::uint64_t instance = 0;  // 0: none
    std::size_t strand = 0;
    glm::vec3 normal, tangent, bitangent, sway;
  };
  StrandFrame frame(std::size_t s) const {
    const UnitPair jitter = unit_pair(random_bits(std::uint32_t(s), seed_, 0, RandomPurpose::scene_generation));
    const UnitPair bend = unit_pair(random_bits(std::uint32_t(s), seed_, 1, RandomPurpose::scene_generation));
    // Row r of the face's columns x columns cells maps to a band parallel to the face's
    // edge BC (the square-root parametrization keeps the spread uniform).
    const std::size_t k = s % per_face_;
    const float x = (float(k / columns_) + jitter.first) / float(columns_);
    const float y = (float(k % columns_) + jitter.second) / float(columns_);
    const Icosahedron& ico = icosahedron();
    const glm::uvec3& face = ico.faces[s / per_face_];
    const float root = std::sqrt(std::min(x, 1.0f));
    const glm::vec3 normal = glm::normalize(ico.corners[face.x] * (1.0f - root) + ico.corners[face.y] * (root * (1.0f - y)) +
                                            ico.corners[face.z] * (root * y));
    const glm::vec3 tangent = glm::normalize(glm::cross(normal, std::fabs(normal.y) < 0.9f ? glm::vec3(0, 1, 0)
                                                                                          : glm::vec3(1, 0, 0)));
    const glm::vec3 bitangent = glm::cross(normal, tangent);
    const glm::vec3 sway = tangent * (bend.first - 0.5f) + bitangent * (bend.second - 0.5f);
    return StrandFrame{instance_, s, normal, tangent, bitangent, sway};
  }

  std::size_t strands_, per_face_, columns_;
  float radius_, length_, width_;
  std::uint32_t seed_;
  // Names this shape in threads' cached frames (an address may be reused by a later shape).
  inline static std::atomic<std::uint64_t> instances_{0};
  std::uint64_t instance_ = ++instances_;
};

// A mesh small enough to be listed: quads and the stadium's box.
class ListedShape final : public ShapeGenerator {
 public:
  explicit ListedShape(TriangleMesh mesh) : mesh_(std::move(mesh)) {}
  std::size_t triangle_count() const override { return mesh_.triangle_count(); }
  std::size_t vertex_count() const override { return mesh_.vertex_count(); }
  glm::vec3 position(std::uint64_t id) const override { return mesh_.positions[id]; }
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    for (std::size_t t = first; t < first + count; ++t) {
      for (int k = 0; k < 3; ++k) out[3 * (t - first) + k] = mesh_.triangles[t][k];
    }
  }

 private:
  TriangleMesh mesh_;
};

// A box facing inward, each face a lattice of nearly square cells. A vertex is keyed by its
// lattice point (21 bits per axis), so the faces meeting at an edge share it.
class RoomShellShape final : public ShapeGenerator {
 public:
  RoomShellShape(const glm::vec3& lower, const glm::vec3& upper, std::size_t triangles) : lower_(lower), extent_(upper - lower) {
    // Each face of cells h x h is two triangles per cell: 4 (xy + yz + zx) / h^2 in all.
    const double face_area = double(extent_.x) * extent_.y + double(extent_.y) * extent_.z + double(extent_.z) * extent_.x;
    const double cell = std::sqrt(4.0 * face_area / double(std::max<std::size_t>(triangles, 12)));
    for (int axis = 0; axis < 3; ++axis) {
      cells_[axis] = static_cast<std::uint32_t>(std::clamp(std::round(double(extent_[axis]) / cell), 1.0, double(kMaxCells)));
    }
    std::size_t start = 0;
    for (int face = 0; face < 6; ++face) {
      face_start_[face] = start;
      const int axis = face / 2;
      start += 2 * std::size_t(cells_[(axis + 1) % 3]) * cells_[(axis + 2) % 3];
    }
    face_start_[6] = start;
  }
  std::size_t triangle_count() const override { return face_start_[6]; }
  std::size_t vertex_count() const override { return 0; }  // sparse: lattice points
  std::size_t distinct_vertices() const override {  // the lattice's points minus its interior ones
    const glm::u64vec3 c(cells_);
    return (c.x + 1) * (c.y + 1) * (c.z + 1) - (c.x - 1) * (c.y - 1) * (c.z - 1);
  }
  glm::vec3 position(std::uint64_t key) const override {
    const glm::uvec3 point(key >> 42, (key >> 21) & kMaxCells, key & kMaxCells);
    return lower_ + extent_ * glm::vec3(point) / glm::vec3(cells_);
  }
  // Faces in the order -x, +x, -y, +y, -z, +z: -x is material 0, +x material 1, the rest 2.
  std::uint32_t material(std::size_t triangle) const override {
    const int face = this->face(triangle);
    return face < 2 ? std::uint32_t(face) : 2u;
  }
  std::uint32_t material_count() const override { return 3; }
  std::vector<std::size_t> part_starts() const override { return {face_start_, face_start_ + 6}; }
  void corners(std::size_t first, std::size_t count, std::uint64_t* out) const override {
    for (std::size_t t = first; t < first + count; ++t) {
      const int face = this->face(t), axis = face / 2, side = face % 2;
      const int u_axis = (axis + 1) % 3, v_axis = (axis + 2) % 3;
      const std::size_t cell = (t - face_start_[face]) / 2;
      const auto i = static_cast<std::uint32_t>(cell / cells_[v_axis]);
      const auto j = static_cast<std::uint32_t>(cell % cells_[v_axis]);
      const auto key = [&](std::uint32_t di, std::uint32_t dj) {
        glm::uvec3 point;
        point[axis] = side * cells_[axis];
        point[u_axis] = i + di;
        point[v_axis] = j + dj;
        return std::uint64_t(point.x) << 42 | std::uint64_t(point.y) << 21 | point.z;
      };
      const std::uint64_t v00 = key(0, 0), v10 = key(1, 0), v11 = key(1, 1), v01 = key(0, 1);
      // (u, v, axis) is right-handed, so this winding faces +axis: inward on the lower
      // side, flipped on the upper.
      const bool second = (t - face_start_[face]) % 2 == 1;
      std::uint64_t* corner = out + 3 * (t - first);
      corner[0] = v00;
      if (side == 0) {
        corner[1] = second ? v11 : v10;
        corner[2] = second ? v01 : v11;
      } else {
        corner[1] = second ? v01 : v11;
        corner[2] = second ? v11 : v10;
      }
    }
  }

 private:
  static constexpr std::uint32_t kMaxCells = (1u << 21) - 1;
  int face(std::size_t triangle) const {
    int face = 0;
    while (triangle >= face_start_[face + 1]) ++face;
    return face;
  }
  glm::vec3 lower_, extent_;
  glm::uvec3 cells_;
  std::size_t face_start_[7];
};

TriangleMesh quad_mesh(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v) {
  TriangleMesh quad;
  quad.positions = {corner, corner + u, corner + u + v, corner + v};
  quad.triangles = {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 3)};
  return quad;
}

// The six faces of a box, facing inward, as 12 triangles over 8 shared corners.
TriangleMesh inward_box_mesh(const glm::vec3& lower, const glm::vec3& upper) {
  TriangleMesh box;
  for (int c = 0; c < 8; ++c) {
    box.positions.emplace_back(c & 1 ? upper.x : lower.x, c & 2 ? upper.y : lower.y, c & 4 ? upper.z : lower.z);
  }
  const std::array<std::array<std::uint32_t, 4>, 6> faces = {
      {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}}};
  const glm::vec3 center = (lower + upper) * 0.5f;
  for (const auto& f : faces) {
    glm::uvec3 first(f[0], f[1], f[2]), second(f[0], f[2], f[3]);
    const glm::vec3 a = box.positions[f[0]], b = box.positions[f[1]], c = box.positions[f[2]];
    if (glm::dot(glm::cross(b - a, c - a), center - a) < 0.0f) {  // wound outward: flip to face in
      std::swap(first.y, first.z);
      std::swap(second.y, second.z);
    }
    box.triangles.push_back(first);
    box.triangles.push_back(second);
  }
  return box;
}

}  // namespace

std::unique_ptr<ShapeGenerator> displaced_sphere_shape(std::size_t triangles, const glm::vec3& center, float radius,
                                                       std::uint32_t seed) {
  return std::make_unique<SphereShape>(triangles, center, radius, seed);
}
std::unique_ptr<ShapeGenerator> smooth_sphere_shape(std::size_t triangles, const glm::vec3& center, float radius,
                                                    bool inward) {
  return std::make_unique<SphereShape>(triangles, center, radius, std::nullopt, inward);
}
std::unique_ptr<ShapeGenerator> soup_shape(std::size_t triangles, std::uint32_t seed) {
  return std::make_unique<SoupShape>(triangles, seed);
}
std::unique_ptr<ShapeGenerator> terrain_shape(std::size_t triangles, float size, float height, std::uint32_t seed) {
  return std::make_unique<TerrainShape>(triangles, size, height, seed);
}
std::unique_ptr<ShapeGenerator> strands_shape(std::size_t triangles, float radius, float length, float width,
                                              std::uint32_t seed) {
  return std::make_unique<StrandsShape>(triangles, radius, length, width, seed);
}
std::unique_ptr<ShapeGenerator> quad_shape(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v) {
  return std::make_unique<ListedShape>(quad_mesh(corner, u, v));
}
std::unique_ptr<ShapeGenerator> inward_box_shape(const glm::vec3& lower, const glm::vec3& upper) {
  return std::make_unique<ListedShape>(inward_box_mesh(lower, upper));
}
std::unique_ptr<ShapeGenerator> room_shell_shape(const glm::vec3& lower, const glm::vec3& upper, std::size_t triangles) {
  return std::make_unique<RoomShellShape>(lower, upper, triangles);
}

TriangleMesh make_quad(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v) { return quad_mesh(corner, u, v); }

}  // namespace wavetrace
