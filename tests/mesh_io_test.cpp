// Mesh files: real meshes from data/, every supported format, and malformed input.
#include <array>
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "scene/mesh_io.hpp"
#include "scene/mesh_report.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

using testing::data_path;
using testing::write_temp_file;

// Expects load_mesh_file to throw SceneError whose message contains `fragment`.
void expect_load_error(const std::string& path, const std::string& fragment) {
  try {
    load_mesh_file(path);
    FAIL() << "no error for " << path;
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find(fragment), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << "message must name the file";
  }
}

TEST(MeshIo, ReadsScannedOffMeshFromData) {
  const LoadedMesh bunny = load_mesh_file(data_path("bunny00.off"));
  EXPECT_EQ(bunny.mesh.triangle_count(), 75408u);
  EXPECT_EQ(bunny.mesh.vertex_count(), 37706u);
  EXPECT_TRUE(analyze_mesh(bunny.mesh).closed());
}

TEST(MeshIo, ReadsPlyAndStlFromData) {
  const LoadedMesh ply = load_mesh_file(data_path("sphere.ply"));
  const LoadedMesh stl = load_mesh_file(data_path("sphere.stl"));
  EXPECT_EQ(ply.mesh.triangle_count(), 320u);
  EXPECT_EQ(stl.mesh.triangle_count(), 320u);
  // STL stores triangles without sharing; the reader merges equal positions back.
  EXPECT_EQ(stl.mesh.vertex_count(), ply.mesh.vertex_count());
}

TEST(MeshIo, ReadsObjAndFansPolygons) {
  const std::string path = write_temp_file("quad_and_triangle.obj",
                                           "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n"
                                           "f 1 2 3 4\nf 2 5 3\n");
  const LoadedMesh loaded = load_mesh_file(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 3u);
  EXPECT_EQ(loaded.polygons_triangulated, 1u);
  EXPECT_EQ(loaded.mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(loaded.mesh.triangles[1], glm::uvec3(0, 2, 3));
}

TEST(MeshIo, KeepsNonManifoldFaces) {
  // Three triangles on one edge: OpenMesh's own kernel would drop the third.
  const std::string path = write_temp_file("fin.off", "OFF\n5 3 0\n0 0 0\n1 0 0\n0 1 0\n0 -1 0\n0 0 1\n"
                                                      "3 0 1 2\n3 1 0 3\n3 0 1 4\n");
  const LoadedMesh loaded = load_mesh_file(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 3u);
  EXPECT_EQ(analyze_mesh(loaded.mesh).non_manifold_edges, 1u);
}

TEST(MeshIo, MissingFileIsAnError) { expect_load_error("/nonexistent/mesh.off", "no such mesh file"); }

TEST(MeshIo, UnsupportedExtensionIsAnError) {
  expect_load_error(write_temp_file("mesh.xyz", "1 2 3\n"), "unsupported mesh format");
}

TEST(MeshIo, GarbageIsAnError) {
  expect_load_error(write_temp_file("garbage.off", "this is not a mesh\n\x01\x02\x03"), "");
}

TEST(MeshIo, OutOfRangeIndexIsAnError) {
  expect_load_error(write_temp_file("bad_index.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 7\n"), "vertex 7");
}

// A binary STL holding one triangle with the given corner coordinates.
std::string binary_stl(const std::array<float, 9>& corners) {
  std::string bytes(80, ' ');
  const std::uint32_t count = 1;
  bytes.append(reinterpret_cast<const char*>(&count), 4);
  const float normal[3] = {0, 0, 1};
  bytes.append(reinterpret_cast<const char*>(normal), 12);
  bytes.append(reinterpret_cast<const char*>(corners.data()), 36);
  bytes.append(2, '\0');
  return bytes;
}

TEST(MeshIo, NanCoordinateIsAnError) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  // OpenMesh's STL reader merges vertices by position; a NaN compares equal to a real
  // vertex there, so the face collapses and is dropped before it reaches us: still an error.
  expect_load_error(write_temp_file("nan.stl", binary_stl({0, 0, 0, nan, 0, 0, 0, 1, 0})), "");
  TriangleMesh mesh;
  mesh.positions = {{0, 0, 0}, {nan, 0, 0}, {0, 1, 0}};
  mesh.triangles = {{0, 1, 2}};
  try {
    validate_and_clean(mesh, "in-memory");
    FAIL();
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find("vertex 1 has a non-finite coordinate"), std::string::npos);
  }
  const float inf = std::numeric_limits<float>::infinity();
  expect_load_error(write_temp_file("inf.stl", binary_stl({0, 0, 0, 1, 0, 0, 0, inf, 0})), "non-finite");
  // Text readers cannot parse "nan": the vertex is lost and the face's index is out of range.
  expect_load_error(write_temp_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"), "vertex");
}

TEST(MeshIo, HugeCoordinateIsAnError) {
  expect_load_error(write_temp_file("huge.obj", "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n"), "beyond");
}

TEST(MeshIo, EmptyMeshIsAnError) {
  expect_load_error(write_temp_file("empty.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "no triangles");
  expect_load_error(data_path("b9.ply"), "no triangles");  // a real point cloud
}

TEST(MeshIo, DegenerateTrianglesAreDroppedAndCounted) {
  // OFF keeps faces as written (OpenMesh's OBJ reader already drops repeated corners).
  const std::string path = write_temp_file("degenerate.off",
                                           "OFF\n4 3 0\n0 0 0\n1 0 0\n0 1 0\n2 0 0\n"
                                           "3 0 1 2\n3 0 1 3\n3 0 0 2\n");  // collinear, repeated vertex
  const LoadedMesh loaded = load_mesh_file(path);
  EXPECT_EQ(loaded.mesh.triangle_count(), 1u);
  EXPECT_EQ(loaded.cleanup.degenerate_dropped, 2u);
}

TEST(MeshIo, AllDegenerateIsAnError) {
  expect_load_error(write_temp_file("all_degenerate.obj", "v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n"), "degenerate");
}

}  // namespace
}  // namespace wavetrace
