// Bounds and validation of the indexed triangle mesh.
#include "wavetrace/scene/triangle_mesh.hpp"

#include <cmath>
#include <fmt/format.h>

#include <glm/geometric.hpp>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

namespace wavetrace {

float Bounds3::diagonal() const { return empty() ? 0.0f : glm::length(extent()); }

Bounds3 TriangleMesh::bounds() const {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, positions.size(), 1 << 14), Bounds3{},
      [&](const tbb::blocked_range<std::size_t>& range, Bounds3 bounds) {
        for (std::size_t i = range.begin(); i != range.end(); ++i) bounds.extend(positions[i]);
        return bounds;
      },
      [](Bounds3 a, const Bounds3& b) {
        a.extend(b);
        return a;
      });
}

std::size_t TriangleMesh::bytes() const {
  return positions.size() * sizeof(glm::vec3) + triangles.size() * sizeof(glm::uvec3) +
         material_of_triangle.size() * sizeof(std::uint32_t);
}

namespace {

bool is_degenerate(const TriangleMesh& mesh, const glm::uvec3& triangle) {
  if (triangle.x == triangle.y || triangle.y == triangle.z || triangle.x == triangle.z) return true;
  // Double precision: a sliver whose float cross product underflows is still a triangle.
  const glm::dvec3 a(mesh.positions[triangle.x]);
  const glm::dvec3 b(mesh.positions[triangle.y]);
  const glm::dvec3 c(mesh.positions[triangle.z]);
  const glm::dvec3 normal = glm::cross(b - a, c - a);
  return normal.x == 0.0 && normal.y == 0.0 && normal.z == 0.0;
}

}  // namespace

void validate_bounds(const Bounds3& bounds, std::string_view source) {
  if (bounds.empty()) throw SceneError(fmt::format("{}: the scene has no triangles", source));
  for (const glm::vec3& p : {bounds.lower, bounds.upper}) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(p[axis]) || std::fabs(p[axis]) > kMaxCoordinateMagnitude) {
        throw SceneError(fmt::format("{}: the scene's bounds reach ({}, {}, {}), not finite or beyond {:g}", source,
                                     p.x, p.y, p.z, kMaxCoordinateMagnitude));
      }
    }
  }
}

MeshCleanup validate_and_clean(TriangleMesh& mesh, std::string_view source, std::vector<std::size_t>* object_starts) {
  if (mesh.triangles.empty()) throw SceneError(fmt::format("{}: the mesh has no triangles", source));
  for (std::size_t i = 0; i < mesh.positions.size(); ++i) {
    const glm::vec3& p = mesh.positions[i];
    for (int axis = 0; axis < 3; ++axis) {
      if (!std::isfinite(p[axis])) {
        throw SceneError(fmt::format("{}: vertex {} has a non-finite coordinate ({}, {}, {})", source, i,
                                     p.x, p.y, p.z));
      }
      if (std::fabs(p[axis]) > kMaxCoordinateMagnitude) {
        throw SceneError(fmt::format("{}: vertex {} has a coordinate beyond {:g} ({}, {}, {})", source, i,
                                     kMaxCoordinateMagnitude, p.x, p.y, p.z));
      }
    }
  }
  const std::size_t vertex_count = mesh.positions.size();
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const glm::uvec3& triangle = mesh.triangles[t];
    for (int corner = 0; corner < 3; ++corner) {
      if (triangle[corner] >= vertex_count) {
        throw SceneError(fmt::format("{}: triangle {} references vertex {} but there are only {} vertices",
                                     source, t, triangle[corner], vertex_count));
      }
    }
  }
  if (!mesh.material_of_triangle.empty() && mesh.material_of_triangle.size() != mesh.triangles.size()) {
    throw SceneError(fmt::format("{}: {} material indices for {} triangles", source,
                                 mesh.material_of_triangle.size(), mesh.triangles.size()));
  }

  MeshCleanup cleanup;
  std::size_t kept = 0;
  std::size_t next_start = 0;  // the first of object_starts not yet moved
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    if (object_starts != nullptr) {
      for (; next_start < object_starts->size() && (*object_starts)[next_start] <= t; ++next_start) {
        (*object_starts)[next_start] = kept;
      }
    }
    if (is_degenerate(mesh, mesh.triangles[t])) {
      ++cleanup.degenerate_dropped;
      continue;
    }
    mesh.triangles[kept] = mesh.triangles[t];
    if (!mesh.material_of_triangle.empty()) mesh.material_of_triangle[kept] = mesh.material_of_triangle[t];
    ++kept;
  }
  mesh.triangles.resize(kept);
  if (!mesh.material_of_triangle.empty()) mesh.material_of_triangle.resize(kept);
  if (object_starts != nullptr) {
    for (; next_start < object_starts->size(); ++next_start) (*object_starts)[next_start] = kept;
  }
  if (mesh.triangles.empty()) {
    throw SceneError(fmt::format("{}: all {} triangles are degenerate", source, cleanup.degenerate_dropped));
  }
  mesh.positions.reserve(mesh.positions.size() + 1);
  return cleanup;
}

}  // namespace wavetrace
