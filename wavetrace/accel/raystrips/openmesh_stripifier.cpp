// OpenMesh's StripifierT on a TriMesh copy of a sub-mesh, its strips mapped back to the
// mesh's triangles (its swaps become zero-area strip triangles).
#include <algorithm>
#include <stdexcept>
#include <unordered_map>

#include <OpenMesh/Core/IO/MeshIO.hh>
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#include <OpenMesh/Core/System/omstream.hh>
#include <OpenMesh/Tools/Utils/StripifierT.hh>

#include "wavetrace/accel/raystrips/stripify.hpp"

namespace wavetrace {
namespace {

using OpenMeshTriangles = OpenMesh::TriMesh_ArrayKernelT<>;

// OpenMesh reports what its kernel refuses on its own log streams; ours are counts (the
// notes), so its logs are off before the first sub-mesh.
void silence_openmesh_logs() {
  static const bool silenced = [] {
    omlog().disable();
    omout().disable();
    omerr().disable();
    return true;
  }();
  (void)silenced;
}

std::uint64_t sorted_triple_key(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t vertex_count) {
  if (a > b) std::swap(a, b);
  if (b > c) std::swap(b, c);
  if (a > b) std::swap(a, b);
  return (std::uint64_t(a) * vertex_count + b) * vertex_count + c;
}

TriangleStrip single_triangle_strip(const TriangleMesh& mesh, std::uint32_t triangle) {
  const glm::uvec3& corners = mesh.triangles[triangle];
  return {{corners.x, corners.y, corners.z}, {triangle}};
}

}  // namespace

std::vector<TriangleStrip> stripify_openmesh(const TriangleMesh& mesh, std::span<const std::uint32_t> triangles,
                                             std::uint32_t max_triangles) {
  if (max_triangles < 1) throw std::invalid_argument("a strip needs room for one triangle");
  silence_openmesh_logs();  // refused (non-manifold) faces become strips of one, counted in the notes
  // Local vertex numbering: the sub-mesh is small, the mesh may not be.
  std::vector<std::uint32_t> local_to_mesh;
  std::unordered_map<std::uint32_t, std::uint32_t> mesh_to_local;
  OpenMeshTriangles kernel;
  std::vector<OpenMeshTriangles::VertexHandle> handles;
  auto local_vertex = [&](std::uint32_t vertex) {
    const auto [it, inserted] = mesh_to_local.try_emplace(vertex, static_cast<std::uint32_t>(local_to_mesh.size()));
    if (inserted) {
      local_to_mesh.push_back(vertex);
      const glm::vec3& p = mesh.positions[vertex];
      handles.push_back(kernel.add_vertex({p.x, p.y, p.z}));
    }
    return handles[it->second];
  };

  std::vector<TriangleStrip> strips;
  std::vector<std::uint32_t> face_triangle;  // OpenMesh face index -> mesh triangle
  for (const std::uint32_t triangle : triangles) {
    const glm::uvec3& corners = mesh.triangles[triangle];
    const auto a = local_vertex(corners.x), b = local_vertex(corners.y), c = local_vertex(corners.z);
    if (a == b || b == c || c == a || !kernel.add_face(a, b, c).is_valid()) {
      strips.push_back(single_triangle_strip(mesh, triangle));  // degenerate or non-manifold here
    } else {
      face_triangle.push_back(triangle);
    }
  }

  std::unordered_map<std::uint64_t, std::uint32_t> triangle_of_corners;
  const auto local_count = static_cast<std::uint32_t>(local_to_mesh.size());
  for (const auto face : kernel.faces()) {
    std::uint32_t corner[3], k = 0;
    for (const auto vertex : kernel.fv_range(face)) corner[k++] = static_cast<std::uint32_t>(vertex.idx());
    triangle_of_corners.emplace(sorted_triple_key(corner[0], corner[1], corner[2], local_count),
                                face_triangle[face.idx()]);
  }

  std::vector<bool> covered(face_triangle.size(), false);
  std::unordered_map<std::uint32_t, std::uint32_t> face_of_triangle;
  for (std::uint32_t f = 0; f < face_triangle.size(); ++f) face_of_triangle.emplace(face_triangle[f], f);
  OpenMesh::StripifierT<OpenMeshTriangles> stripifier(kernel);
  stripifier.stripify();
  for (auto it = stripifier.begin(); it != stripifier.end(); ++it) {
    const auto& indices = *it;
    if (indices.size() < 3) continue;
    TriangleStrip strip;
    for (const auto index : indices) strip.vertices.push_back(local_to_mesh[index]);
    for (std::size_t k = 0; k + 2 < indices.size(); ++k) {
      const std::uint32_t a = indices[k], b = indices[k + 1], c = indices[k + 2];
      if (a == b || b == c || c == a) {
        strip.triangles.push_back(kNoTriangle);  // a swap: zero area, never hit
        continue;
      }
      const auto found = triangle_of_corners.find(sorted_triple_key(a, b, c, local_count));
      if (found == triangle_of_corners.end()) {
        throw std::logic_error("OpenMesh's stripifier produced a triangle that is not in the mesh");
      }
      strip.triangles.push_back(found->second);
      covered[face_of_triangle.at(found->second)] = true;
    }
    strips.push_back(std::move(strip));
  }
  for (std::uint32_t f = 0; f < face_triangle.size(); ++f) {
    if (!covered[f]) strips.push_back(single_triangle_strip(mesh, face_triangle[f]));
  }

  return cut_long_strips(std::move(strips), max_triangles);
}

}  // namespace wavetrace
