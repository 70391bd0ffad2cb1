// Object transforms composed in double precision and applied in parallel.
#include "wavetrace/scene/object_transform.hpp"

#include <cmath>
#include <utility>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/mat3x3.hpp>
#include <tbb/parallel_for.h>

namespace wavetrace {
namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

glm::dmat3 rotation(const glm::vec3& degrees) {
  const glm::dvec3 radians = glm::radians(glm::dvec3(degrees));
  const double cx = std::cos(radians.x), sx = std::sin(radians.x);
  const double cy = std::cos(radians.y), sy = std::sin(radians.y);
  const double cz = std::cos(radians.z), sz = std::sin(radians.z);
  // Column-major, as GLM stores them.
  const glm::dmat3 about_x(1, 0, 0, 0, cx, sx, 0, -sx, cx);
  const glm::dmat3 about_y(cy, 0, -sy, 0, 1, 0, sy, 0, cy);
  const glm::dmat3 about_z(cz, sz, 0, -sz, cz, 0, 0, 0, 1);
  return about_z * about_y * about_x;
}

}  // namespace

void validate_transform(const ObjectTransform& transform, std::string_view what) {
  if (!finite(transform.scale) || transform.scale.x == 0.0f || transform.scale.y == 0.0f ||
      transform.scale.z == 0.0f) {
    throw SceneError(fmt::format("{}: scale ({}, {}, {}) is degenerate: each component must be finite and non-zero",
                                 what, transform.scale.x, transform.scale.y, transform.scale.z));
  }
  if (!finite(transform.rotate_degrees)) throw SceneError(fmt::format("{}: rotate must be finite", what));
  if (!finite(transform.translate)) throw SceneError(fmt::format("{}: translate must be finite", what));
  if (transform.fit && !(std::isfinite(*transform.fit) && *transform.fit > 0.0f)) {
    throw SceneError(fmt::format("{}: fit = {} must be a positive size", what, *transform.fit));
  }
}

void apply_transform(TriangleMesh& mesh, const ObjectTransform& transform, std::string_view what) {
  validate_transform(transform, what);
  glm::dvec3 center(0.0), translate(transform.translate);
  double fit_scale = 1.0;
  if (transform.fit) {
    const Bounds3 bounds = mesh.bounds();
    const glm::vec3 extent = bounds.extent();
    const double largest = std::max({extent.x, extent.y, extent.z});
    if (bounds.empty() || !(largest > 0.0)) {
      throw SceneError(fmt::format("{}: cannot fit a mesh with no extent to size {}", what, *transform.fit));
    }
    center = glm::dvec3(bounds.center());
    fit_scale = double(*transform.fit) / largest;
  }
  const glm::dmat3 linear = rotation(transform.rotate_degrees) *
                            glm::dmat3(glm::dvec3(transform.scale.x, 0, 0) * fit_scale,
                                       glm::dvec3(0, transform.scale.y, 0) * fit_scale,
                                       glm::dvec3(0, 0, transform.scale.z) * fit_scale);
  tbb::parallel_for(std::size_t{0}, mesh.positions.size(), [&](std::size_t v) {
    mesh.positions[v] = glm::vec3(linear * (glm::dvec3(mesh.positions[v]) - center) + translate);
  });
  if (glm::determinant(linear) < 0.0) {
    for (glm::uvec3& triangle : mesh.triangles) std::swap(triangle.y, triangle.z);
  }
}

}  // namespace wavetrace
