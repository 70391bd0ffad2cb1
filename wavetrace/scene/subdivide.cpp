// Loop subdivision through OpenMesh's uniform LoopT subdivider.
#include "wavetrace/scene/subdivide.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <set>
#include <vector>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>
#include <fmt/format.h>

#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/memory/process_memory.hpp"

namespace wavetrace {
namespace {

// Puts a subdivided surface's triangles in the Z-order of their centroids. OpenMesh's Loop
// step keeps each parent face as one child and appends the other three at the end, so after
// two steps a face's neighbours are numbered anywhere in the mesh; the order of a generated
// mesh is ours to choose, and one where neighbours are numbered alike is what compact
// structures that store triangle numbers per leaf need (HMQ's leaf ids: bunny00 subdivided
// twice, 3.1 bytes a triangle of ids and corners in OpenMesh's order).
void order_triangles_along_z_curve(TriangleMesh& mesh) {
  Bounds3 bounds;
  for (const glm::vec3& p : mesh.positions) bounds.extend(p);
  if (bounds.empty()) return;
  constexpr float kCells = 1024.0f;  // 10 bits an axis
  const glm::vec3 extent = glm::max(bounds.upper - bounds.lower, glm::vec3(std::numeric_limits<float>::min()));
  const glm::vec3 scale = kCells / extent;
  // A coordinate that is not finite (none passes the loaders' checks) falls in cell 0.
  const auto cell = [&](const glm::vec3& centroid, int axis) -> std::uint64_t {
    const float at = (centroid[axis] - bounds.lower[axis]) * scale[axis];
    return at > 0.0f ? std::uint64_t(std::min(at, kCells - 1.0f)) : 0u;
  };
  std::vector<std::uint64_t> key(mesh.triangle_count());
  for (std::size_t t = 0; t < key.size(); ++t) {
    const glm::uvec3& tri = mesh.triangles[t];
    const glm::vec3 centroid = (mesh.positions[tri.x] + mesh.positions[tri.y] + mesh.positions[tri.z]) / 3.0f;
    key[t] = morton3d_encode(cell(centroid, 0), cell(centroid, 1), cell(centroid, 2));
  }
  std::vector<std::uint32_t> order(key.size());
  std::iota(order.begin(), order.end(), 0u);
  std::sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {  // ties in the old order
    return key[a] != key[b] ? key[a] < key[b] : a < b;
  });
  std::vector<glm::uvec3> triangles(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) triangles[i] = mesh.triangles[order[i]];
  mesh.triangles = std::move(triangles);
}

// One surface, its materials ignored.
SubdivisionResult subdivide_surface(const TriangleMesh& mesh, int levels) {
  using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;
  SubdivisionResult result;
  OpenMeshTriangles kernel;
  kernel.reserve(mesh.vertex_count(), mesh.triangle_count() * 3 / 2, mesh.triangle_count());
  std::vector<OpenMeshTriangles::VertexHandle> handles;
  handles.reserve(mesh.vertex_count());
  for (const glm::vec3& p : mesh.positions) handles.push_back(kernel.add_vertex({p.x, p.y, p.z}));
  for (const glm::uvec3& triangle : mesh.triangles) {
    if (!kernel.add_face(handles[triangle.x], handles[triangle.y], handles[triangle.z]).is_valid()) {
      ++result.non_manifold_faces_dropped;
    }
  }
  // Unused vertices have no neighbours for Loop's averaging; remove them first.
  kernel.request_vertex_status();
  kernel.request_edge_status();
  kernel.request_face_status();
  kernel.delete_isolated_vertices();
  kernel.garbage_collection();
  kernel.release_vertex_status();
  kernel.release_edge_status();
  kernel.release_face_status();

  OpenMesh::Subdivider::Uniform::LoopT<OpenMeshTriangles> loop;
  loop.attach(kernel);
  loop(static_cast<std::size_t>(levels));
  loop.detach();

  result.mesh.positions.reserve(kernel.n_vertices() + 1);
  for (const auto vertex : kernel.vertices()) {
    const auto& p = kernel.point(vertex);
    result.mesh.positions.emplace_back(p[0], p[1], p[2]);
  }
  result.mesh.triangles.reserve(kernel.n_faces());
  for (const auto face : kernel.faces()) {
    glm::uvec3 triangle;
    int corner = 0;
    for (const auto vertex : kernel.fv_range(face)) triangle[corner++] = static_cast<std::uint32_t>(vertex.idx());
    result.mesh.triangles.push_back(triangle);
  }
  order_triangles_along_z_curve(result.mesh);
  return result;
}

// The triangles of one material, with only the vertices they use.
TriangleMesh triangles_of_material(const TriangleMesh& mesh, std::uint32_t material) {
  TriangleMesh part;
  std::vector<std::uint32_t> new_index(mesh.vertex_count(), std::numeric_limits<std::uint32_t>::max());
  for (std::size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (mesh.material(t) != material) continue;
    glm::uvec3 triangle;
    for (int corner = 0; corner < 3; ++corner) {
      std::uint32_t& index = new_index[mesh.triangles[t][corner]];
      if (index == std::numeric_limits<std::uint32_t>::max()) {
        index = static_cast<std::uint32_t>(part.positions.size());
        part.positions.push_back(mesh.positions[mesh.triangles[t][corner]]);
      }
      triangle[corner] = index;
    }
    part.triangles.push_back(triangle);
  }
  return part;
}

// Refuses, before anything is allocated, a subdivision whose result cannot be held: OpenMesh
// numbers its half-edges (three per triangle) with 32-bit ints, and the result needs at least
// kSubdividedBytesPerTriangle a triangle (subdivide.hpp).

void check_subdivision_fits(const TriangleMesh& mesh, int levels) {
  const double triangles = double(mesh.triangle_count()) * std::pow(4.0, levels);
  constexpr double kMostTriangles = double(std::numeric_limits<std::int32_t>::max()) / 3.0;
  if (triangles > kMostTriangles) {
    throw SceneError(fmt::format("subdividing {} triangles {} times makes {:.3g} triangles; OpenMesh's 32-bit handles "
                                 "hold at most {:.3g} (three half-edges each): subdivide fewer times",
                                 mesh.triangle_count(), levels, triangles, kMostTriangles));
  }
  const std::size_t available = available_memory_bytes();
  if (available > 0 && triangles * kSubdividedBytesPerTriangle > double(available)) {
    throw SceneError(fmt::format("subdividing {} triangles {} times makes {:.3g} triangles: at least {:.1f} GB, but "
                                 "{:.1f} GB of memory is available; subdivide fewer times",
                                 mesh.triangle_count(), levels, triangles,
                                 triangles * kSubdividedBytesPerTriangle * 1e-9, double(available) * 1e-9));
  }
}

}  // namespace

SubdivisionResult loop_subdivide(const TriangleMesh& mesh, int levels) {
  if (levels <= 0) return SubdivisionResult{mesh, 0};
  check_subdivision_fits(mesh, levels);
  const std::set<std::uint32_t> materials(mesh.material_of_triangle.begin(), mesh.material_of_triangle.end());
  if (materials.size() <= 1) {
    SubdivisionResult result = subdivide_surface(mesh, levels);
    if (!materials.empty()) result.mesh.material_of_triangle.assign(result.mesh.triangle_count(), *materials.begin());
    return result;
  }
  // Material boundaries become open boundaries, which Loop's boundary rules subdivide from
  // the boundary curve alone, so both sides of a seam between two materials still meet.
  // Where three or more materials meet at a vertex the curves differ and a crack may open.
  SubdivisionResult result;
  for (std::uint32_t material : materials) {
    SubdivisionResult part = subdivide_surface(triangles_of_material(mesh, material), levels);
    result.non_manifold_faces_dropped += part.non_manifold_faces_dropped;
    const auto offset = static_cast<std::uint32_t>(result.mesh.positions.size());
    result.mesh.positions.insert(result.mesh.positions.end(), part.mesh.positions.begin(), part.mesh.positions.end());
    for (const glm::uvec3& triangle : part.mesh.triangles) result.mesh.triangles.push_back(triangle + offset);
    result.mesh.material_of_triangle.resize(result.mesh.triangle_count(), material);
  }
  result.mesh.positions.reserve(result.mesh.positions.size() + 1);
  return result;
}

}  // namespace wavetrace
