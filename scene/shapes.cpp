// Procedural shapes the builtin scenes are composed of. The sphere is an icosahedron whose
// faces are split into n x n triangle lattices with globally shared vertices, so it is closed.
#include "scene/shapes.hpp"

#include <array>
#include <cmath>
#include <map>
#include <unordered_map>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>
#include <tbb/parallel_for.h>

#include "kernels/random.hpp"
#include "kernels/sampling.hpp"
#include "scene/noise.hpp"

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
    std::uint32_t local = static_cast<std::uint32_t>(id % interior_per_face());
    std::uint32_t i = 1;
    while (local >= n_ - 1 - i) {
      local -= n_ - 1 - i;
      ++i;
    }
    const std::uint32_t j = local + 1;
    const glm::uvec3& corners = ico.faces[face];
    const glm::vec3 a = ico.corners[corners.x], b = ico.corners[corners.y], c = ico.corners[corners.z];
    return glm::normalize(a + (b - a) * (float(i) / n_) + (c - a) * (float(j) / n_));
  }

 private:
  std::size_t interior_per_face() const { return n_ < 3 ? 0 : std::size_t(n_ - 1) * (n_ - 2) / 2; }
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

}  // namespace

// An axis-aligned quad from corner with edges u and v; front face along cross(u, v).
TriangleMesh make_quad(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v) {
  TriangleMesh quad;
  quad.positions = {corner, corner + u, corner + u + v, corner + v};
  quad.triangles = {glm::uvec3(0, 1, 2), glm::uvec3(0, 2, 3)};
  return quad;
}

// The six faces of a box, facing inward, as 12 triangles over 8 shared corners.
TriangleMesh make_inward_box(const glm::vec3& lower, const glm::vec3& upper) {
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

TriangleMesh make_terrain(std::size_t triangles, float size, float height, std::uint32_t seed) {
  const auto cells = static_cast<std::uint32_t>(std::max(1.0, std::round(std::sqrt(double(triangles) / 2.0))));
  const std::uint32_t row = cells + 1;
  TriangleMesh mesh;
  mesh.positions.resize(std::size_t(row) * row);
  tbb::parallel_for(std::uint32_t{0}, row, [&](std::uint32_t z) {
    for (std::uint32_t x = 0; x < row; ++x) {
      const float fx = float(x) / cells, fz = float(z) / cells;
      const glm::vec3 ground((fx - 0.5f) * size, 0.0f, (fz - 0.5f) * size);
      const float y = height * fractal_noise(glm::vec3(fx * 4.0f, 0.37f, fz * 4.0f), 8, seed);
      mesh.positions[std::size_t(z) * row + x] = ground + glm::vec3(0.0f, y, 0.0f);
    }
  });
  mesh.triangles.resize(std::size_t(cells) * cells * 2);
  tbb::parallel_for(std::uint32_t{0}, cells, [&](std::uint32_t z) {
    for (std::uint32_t x = 0; x < cells; ++x) {
      const std::uint32_t v00 = z * row + x, v10 = v00 + 1, v01 = v00 + row, v11 = v01 + 1;
      const std::size_t t = (std::size_t(z) * cells + x) * 2;
      mesh.triangles[t] = glm::uvec3(v00, v01, v11);  // counter-clockwise seen from +y
      mesh.triangles[t + 1] = glm::uvec3(v00, v11, v10);
    }
  });
  return mesh;
}

// Thin open tubes of triangular cross-section growing from a sphere of radius `radius`.
TriangleMesh make_strands(std::size_t triangles, float radius, float length, float width, std::uint32_t seed) {
  constexpr std::uint32_t kSegments = 4, kSides = 3, kRings = kSegments + 1;
  constexpr std::uint32_t kTrianglesPerStrand = kSegments * kSides * 2;
  const std::size_t strands = std::max<std::size_t>(1, triangles / kTrianglesPerStrand);
  TriangleMesh mesh;
  mesh.positions.resize(strands * kRings * kSides);
  mesh.triangles.resize(strands * kTrianglesPerStrand);
  tbb::parallel_for(std::size_t{0}, strands, [&](std::size_t s) {
    const UnitPair root = unit_pair(random_bits(std::uint32_t(s), seed, 0, RandomPurpose::scene_generation));
    const UnitPair bend = unit_pair(random_bits(std::uint32_t(s), seed, 1, RandomPurpose::scene_generation));
    const glm::vec3 normal = uniform_sphere(root.first, root.second);
    const glm::vec3 tangent = glm::normalize(glm::cross(normal, std::fabs(normal.y) < 0.9f ? glm::vec3(0, 1, 0)
                                                                                          : glm::vec3(1, 0, 0)));
    const glm::vec3 bitangent = glm::cross(normal, tangent);
    const glm::vec3 sway = tangent * (bend.first - 0.5f) + bitangent * (bend.second - 0.5f);
    const std::size_t first_vertex = s * kRings * kSides;
    for (std::uint32_t ring = 0; ring < kRings; ++ring) {
      const float along = float(ring) / kSegments;
      const glm::vec3 center = normal * (radius + length * along) + sway * (length * along * along);
      const float ring_width = width * (1.0f - 0.7f * along);
      for (std::uint32_t side = 0; side < kSides; ++side) {
        const float angle = 2.0f * 3.14159265f * float(side) / kSides;
        mesh.positions[first_vertex + ring * kSides + side] =
            center + (tangent * std::cos(angle) + bitangent * std::sin(angle)) * ring_width;
      }
    }
    std::size_t t = s * kTrianglesPerStrand;
    for (std::uint32_t ring = 0; ring < kSegments; ++ring) {
      for (std::uint32_t side = 0; side < kSides; ++side) {
        const auto a = static_cast<std::uint32_t>(first_vertex + ring * kSides + side);
        const auto b = static_cast<std::uint32_t>(first_vertex + ring * kSides + (side + 1) % kSides);
        mesh.triangles[t++] = glm::uvec3(a, b, b + kSides);
        mesh.triangles[t++] = glm::uvec3(a, b + kSides, a + kSides);
      }
    }
  });
  return mesh;
}

TriangleMesh make_displaced_sphere(std::size_t triangles, const glm::vec3& center, float radius,
                                   std::uint32_t seed) {
  const IcosphereLattice lattice(icosphere_frequency(triangles));
  const std::uint32_t n = icosphere_frequency(triangles);
  TriangleMesh mesh;
  mesh.positions.resize(lattice.vertex_count());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lattice.vertex_count(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t id = range.begin(); id != range.end(); ++id) {
                        const glm::vec3 direction = lattice.direction(id);
                        const float displacement =
                            kDisplacementAmplitude *
                            fractal_noise(direction * kDisplacementFrequency, kDisplacementOctaves, seed);
                        mesh.positions[id] = center + direction * (radius * (1.0f + displacement));
                      }
                    });
  mesh.triangles.resize(lattice.triangle_count());
  tbb::parallel_for(std::uint32_t{0}, 20u * n, [&](std::uint32_t face_row) {
    const std::uint32_t face = face_row / n, i = face_row % n;
    // Row i of face f: n-i "up" triangles and n-i-1 "down" triangles, in a fixed order.
    std::size_t t = std::size_t(face) * n * n + std::size_t(i) * (2 * n - i);
    for (std::uint32_t j = 0; i + j < n; ++j) {
      mesh.triangles[t++] = glm::uvec3(lattice.vertex(face, i, j), lattice.vertex(face, i + 1, j),
                                       lattice.vertex(face, i, j + 1));
      if (i + j + 1 < n) {
        mesh.triangles[t++] = glm::uvec3(lattice.vertex(face, i + 1, j), lattice.vertex(face, i + 1, j + 1),
                                         lattice.vertex(face, i, j + 1));
      }
    }
  });
  return mesh;
}

TriangleMesh make_room_shell(const glm::vec3& lower, const glm::vec3& upper, std::size_t triangles) {
  const glm::vec3 extent = upper - lower;
  // Each face of cells h x h is two triangles per cell: 4 (xy + yz + zx) / h^2 in all.
  const double face_area = double(extent.x) * extent.y + double(extent.y) * extent.z + double(extent.z) * extent.x;
  const double cell = std::sqrt(4.0 * face_area / double(std::max<std::size_t>(triangles, 12)));
  glm::uvec3 cells;
  for (int axis = 0; axis < 3; ++axis) {
    cells[axis] = static_cast<std::uint32_t>(std::max(1.0, std::round(double(extent[axis]) / cell)));
  }
  // Vertices are named by their lattice point, so the faces meeting at an edge share them.
  std::unordered_map<std::uint64_t, std::uint32_t> vertex_of_point;
  TriangleMesh shell;
  const auto vertex = [&](glm::uvec3 point) {
    const std::uint64_t key = (std::uint64_t(point.x) << 42) | (std::uint64_t(point.y) << 21) | point.z;
    const auto [slot, inserted] = vertex_of_point.emplace(key, static_cast<std::uint32_t>(shell.positions.size()));
    if (inserted) shell.positions.push_back(lower + extent * glm::vec3(point) / glm::vec3(cells));
    return slot->second;
  };
  for (int axis = 0; axis < 3; ++axis) {
    const int first = (axis + 1) % 3, second = (axis + 2) % 3;
    for (std::uint32_t side = 0; side < 2; ++side) {
      const std::uint32_t material = axis == 0 ? side : 2;
      for (std::uint32_t i = 0; i < cells[first]; ++i) {
        for (std::uint32_t j = 0; j < cells[second]; ++j) {
          const auto corner = [&](std::uint32_t di, std::uint32_t dj) {
            glm::uvec3 point;
            point[axis] = side * cells[axis];
            point[first] = i + di;
            point[second] = j + dj;
            return vertex(point);
          };
          const std::uint32_t v00 = corner(0, 0), v10 = corner(1, 0), v11 = corner(1, 1), v01 = corner(0, 1);
          // (first, second, axis) is right-handed, so this winding faces +axis: inward on the
          // lower side, flipped on the upper.
          if (side == 0) {
            shell.triangles.emplace_back(v00, v10, v11);
            shell.triangles.emplace_back(v00, v11, v01);
          } else {
            shell.triangles.emplace_back(v00, v11, v10);
            shell.triangles.emplace_back(v00, v01, v11);
          }
          shell.material_of_triangle.push_back(material);
          shell.material_of_triangle.push_back(material);
        }
      }
    }
  }
  return shell;
}

TriangleMesh translated(TriangleMesh mesh, const glm::vec3& offset) {
  tbb::parallel_for(std::size_t{0}, mesh.positions.size(), [&](std::size_t v) { mesh.positions[v] += offset; });
  return mesh;
}

}  // namespace wavetrace
