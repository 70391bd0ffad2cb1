// Loop subdivision through OpenMesh's uniform LoopT subdivider.
#include "scene/subdivide.hpp"

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Tools/Subdivider/Uniform/LoopT.hh>

namespace wavetrace {

SubdivisionResult loop_subdivide(const TriangleMesh& mesh, int levels) {
  using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;
  SubdivisionResult result;
  if (levels <= 0) {
    result.mesh = mesh;
    return result;
  }
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
  if (!mesh.material_of_triangle.empty()) {
    result.mesh.material_of_triangle.assign(result.mesh.triangles.size(), mesh.material_of_triangle.front());
  }
  return result;
}

}  // namespace wavetrace
