// Procedural shapes the builtin scenes are composed of; deterministic and built in parallel.
// Triangle counts are met as closely as each shape's structure allows.
#pragma once

#include <cstddef>
#include <cstdint>
#include <memory>

#include <glm/vec3.hpp>

#include "wavetrace/scene/shape_generator.hpp"
#include "wavetrace/scene/triangle_mesh.hpp"

namespace wavetrace {

// A parallelogram from `corner` with edges u and v, facing along cross(u, v).
TriangleMesh make_quad(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v);

// The shapes as generators of any triangle range (shape_generator.hpp; generate_mesh makes a
// whole one). A closed, fractally displaced icosphere: 20 n^2 triangles for the n nearest
// `triangles`, radius about `radius` (displaced by up to 12%), centred at `center`.
std::unique_ptr<ShapeGenerator> displaced_sphere_shape(std::size_t triangles, const glm::vec3& center, float radius,
                                                       std::uint32_t seed);
// The same icosphere undisplaced: every vertex at `radius` from `center`, triangles wound
// counter-clockwise seen from outside (the glass of a caustic scene), or from inside when
// `inward` (a furnace's walls).
std::unique_ptr<ShapeGenerator> smooth_sphere_shape(std::size_t triangles, const glm::vec3& center, float radius,
                                                    bool inward = false);
// The unit sphere's triangles (centred at the origin), each with three vertices of its own.
std::unique_ptr<ShapeGenerator> soup_shape(std::size_t triangles, std::uint32_t seed);
// A fractal heightfield of size x size around the origin, heights within about +-height.
std::unique_ptr<ShapeGenerator> terrain_shape(std::size_t triangles, float size, float height, std::uint32_t seed);
// Thin open tubes of triangular cross-section growing from a sphere of `radius` at the origin.
std::unique_ptr<ShapeGenerator> strands_shape(std::size_t triangles, float radius, float length, float width,
                                              std::uint32_t seed);
std::unique_ptr<ShapeGenerator> quad_shape(const glm::vec3& corner, const glm::vec3& u, const glm::vec3& v);
// The six faces of a box facing inward: 12 triangles over 8 shared corners.
std::unique_ptr<ShapeGenerator> inward_box_shape(const glm::vec3& lower, const glm::vec3& upper);
// A box facing inward, each face tessellated into a lattice of nearly square cells with
// vertices shared across face edges: closed and manifold, with about `triangles` triangles.
// Its per-triangle material is the face: 0 for -x, 1 for +x, 2 for every other face.
std::unique_ptr<ShapeGenerator> room_shell_shape(const glm::vec3& lower, const glm::vec3& upper, std::size_t triangles);

}  // namespace wavetrace
