// Topology census on small hand-made meshes with known answers.
#include <gtest/gtest.h>

#include "wavetrace/scene/mesh_report.hpp"

namespace wavetrace {
namespace {

TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return mesh;
}

TEST(MeshReport, TetrahedronIsClosed) {
  const MeshReport report = analyze_mesh(tetrahedron());
  EXPECT_EQ(report.edges, 6u);
  EXPECT_EQ(report.boundary_edges, 0u);
  EXPECT_EQ(report.non_manifold_edges, 0u);
  EXPECT_EQ(report.connected_components, 1u);
  EXPECT_TRUE(report.closed());
  EXPECT_EQ(report.bounds.upper, glm::vec3(1.0f));
}

TEST(MeshReport, OpenAndDisconnectedPiecesAreCounted) {
  TriangleMesh mesh = tetrahedron();
  mesh.triangles.pop_back();  // open the tetrahedron: three boundary edges
  mesh.positions.insert(mesh.positions.end(), {{5, 0, 0}, {6, 0, 0}, {5, 1, 0}});
  mesh.triangles.push_back({4, 5, 6});  // a separate triangle
  const MeshReport report = analyze_mesh(mesh);
  EXPECT_EQ(report.boundary_edges, 6u);
  EXPECT_EQ(report.connected_components, 2u);
  EXPECT_FALSE(report.closed());
}

TEST(MeshReport, FinIsNonManifoldAndDegeneratesAreSeen) {
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {2, 0, 0}};
  mesh.triangles = {{0, 1, 2}, {1, 0, 3}, {0, 1, 4}, {0, 1, 5}};  // the last is a zero-area sliver
  const MeshReport report = analyze_mesh(mesh);
  EXPECT_EQ(report.non_manifold_edges, 1u);
  EXPECT_EQ(report.degenerate_triangles, 1u);
}

}  // namespace
}  // namespace wavetrace
