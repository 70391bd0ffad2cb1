// Mesh files: real meshes from data/, every supported format, and malformed input.
#include <array>
#include <cstdint>
#include <limits>

#include <gtest/gtest.h>

#include "wavetrace/scene/mesh_io.hpp"
#include "wavetrace/scene/mesh_report.hpp"
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
  expect_load_error(write_temp_file("nan.stl", binary_stl({0, 0, 0, nan, 0, 0, 0, 1, 0})),
                    "triangle 0 (byte 84): corner 1 has a non-finite coordinate");
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
  expect_load_error(write_temp_file("nan.obj", "v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n"),
                    "line 2: vertex 2 x coordinate 'nan' is not a finite number");
}

TEST(MeshIo, HugeCoordinateIsAnError) {
  expect_load_error(write_temp_file("huge.obj", "v 0 0 0\nv 1e30 0 0\nv 0 1 0\nf 1 2 3\n"), "beyond");
}

TEST(MeshIo, EmptyMeshIsAnError) {
  expect_load_error(write_temp_file("empty.off", "OFF\n3 0 0\n0 0 0\n1 0 0\n0 1 0\n"), "no triangles");
  expect_load_error(data_path("b9.ply"), "no triangles");  // a real point cloud
}

TEST(MeshIo, DegenerateTrianglesAreDroppedAndCounted) {
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

// The message for `contents` written as `name`, which must fail to load.
std::string load_error(const std::string& name, const std::string& contents) {
  const std::string path = write_temp_file(name, contents);
  try {
    load_mesh_file(path);
  } catch (const SceneError& error) {
    return error.what();
  }
  ADD_FAILURE() << name << " loaded";
  return {};
}

TEST(MeshIo, EveryMalformedFieldIsNamedWithItsFileAndLine) {
  struct Case {
    const char* name;
    const char* contents;
    const char* message;  // after "PATH line "
  };
  const Case cases[] = {
      {"word.off", "OFF\n3 1 0\n0 0 0\n1 zero 0\n0 1 0\n3 0 1 2\n", "4: vertex 1 y coordinate 'zero' is not a number"},
      {"inf.off", "OFF\n3 1 0\n0 0 0\n1 0 inf\n0 1 0\n3 0 1 2\n", "4: vertex 1 z coordinate 'inf' is not a finite number"},
      {"overflow.off", "OFF\n3 1 0\n0 0 0\n1e39 0 0\n0 1 0\n3 0 1 2\n", "4: vertex 1 x coordinate '1e39' is beyond a float's range"},
      {"range.off", "OFF\n3 1 0\n0 0 0\n1e400 0 0\n0 1 0\n3 0 1 2\n", "4: vertex 1 x coordinate '1e400' is out of range"},
      {"missing.off", "OFF\n3 1 0\n0 0 0\n1 0\n0 1 0\n3 0 1 2\n", "4: vertex 1 has 2 coordinates (3 needed)"},
      {"index_word.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 one 2\n", "6: face 0 corner 1 'one' is not an integer"},
      {"index_float.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1.5 2\n", "6: face 0 corner 1 '1.5' is not an integer"},
      {"short_face.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n", "6: face 0 has 3 corners but the line lists 2"},
      {"negative_count.off", "OFF\n-3 1 0\n", "2: the vertex count -3 is out of range"},
      {"truncated.off", "OFF\n3 1 0\n0 0 0\n1 0 0\n", "4: the file ends after 2 of its 3 vertices"},
      {"huge_count.off", "OFF\n99999999999999999999 1 0\n", "2: the vertex count '99999999999999999999' is out of range"},
      {"word.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 x\n", "4: face 1 corner 3 vertex index 'x' is not an integer"},
      {"zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n", "4: face 1 corner 1 has vertex index 0 (OBJ counts from 1)"},
      {"ahead.obj", "v 0 0 0\nv 1 0 0\nf 1 2 3\nv 0 1 0\n", "3: face 1 references vertex 3 but 2 vertices are defined before it"},
      {"word.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 O 0\n",
       "5: facet 0 vertex 1 y coordinate 'O' is not a number"},
      {"quad.stl", "solid s\nfacet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 1 1 0\nvertex 0 1 0\n",
       "7: facet 0 has more than 3 vertices"},
      {"word.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                   "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 nan\n0 1 0\n3 0 1 2\n",
       "11: vertex 1 z coordinate 'nan' is not a finite number"},
      {"extra.ply", "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
                    "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2 7\n",
       "13: face 0 has 5 fields, more than its properties give"},
      {"header.ply", "ply\nformat ascii 1.0\nelement vertex -1\n", "PLY header line 3: the element count -1 is out of range"},
  };
  for (const Case& c : cases) {
    const std::string first = load_error(c.name, c.contents);
    EXPECT_NE(first.find(c.message), std::string::npos) << c.name << ": " << first;
    EXPECT_NE(first.find(c.name), std::string::npos) << "the message names the file: " << first;
    EXPECT_EQ(load_error(c.name, c.contents), first) << "the same message on every run";
  }
}

TEST(MeshIo, ReadsCommentsColoursAndPolygonsAsCgalWritesThem) {
  // Comments before the keyword and between records, colours after the fields: CGAL's own
  // files, which OpenMesh's reader refused or misread.
  const LoadedMesh colors = load_mesh_file(data_path("mesh_with_colors.off"));
  EXPECT_EQ(colors.mesh.triangle_count(), 6u);
  const LoadedMesh cube = load_mesh_file(data_path("cube_poly.off"));
  EXPECT_EQ(cube.mesh.triangle_count(), 12u);
  EXPECT_EQ(cube.polygons_triangulated, 5u);
  EXPECT_TRUE(analyze_mesh(cube.mesh).closed());
}

TEST(MeshIo, ObjNegativeIndicesCountBackFromTheLastVertex) {
  const LoadedMesh loaded =
      load_mesh_file(write_temp_file("relative.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3/1 -2/2/2 -1//3\nv 1 1 0\nf 2 4 -2\n"));
  ASSERT_EQ(loaded.mesh.triangle_count(), 2u);
  EXPECT_EQ(loaded.mesh.triangles[0], glm::uvec3(0, 1, 2));
  EXPECT_EQ(loaded.mesh.triangles[1], glm::uvec3(1, 3, 2));
}

TEST(MeshIo, AsciiAndBinaryPlyAndStlReadTheSameMesh) {
  const std::string ascii_ply = write_temp_file(
      "tetra_ascii.ply",
      "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\nproperty float z\n"
      "property uchar red\nelement face 4\nproperty list uchar int vertex_indices\nend_header\n"
      "0 0 0 1\n1 0 0 2\n0 1 0 3\n0 0 1 4\n3 0 2 1\n3 0 1 3\n3 0 3 2\n3 1 2 3\n");
  const LoadedMesh from_ply = load_mesh_file(ascii_ply);
  EXPECT_EQ(from_ply.mesh.triangle_count(), 4u);
  EXPECT_TRUE(analyze_mesh(from_ply.mesh).closed());
  // The same tetrahedron as ASCII STL, its shared corners welded back (-0 is +0).
  const LoadedMesh from_stl = load_mesh_file(write_temp_file(
      "tetra_ascii.stl",
      "solid t\n"
      "facet normal 0 0 -1\nouter loop\nvertex 0 0 0\nvertex 0 1 0\nvertex 1 0 0\nendloop\nendfacet\n"
      "facet normal 0 -1 0\nouter loop\nvertex 0 0 0\nvertex 1 0 0\nvertex 0 0 1\nendloop\nendfacet\n"
      "facet normal -1 0 0\nouter loop\nvertex -0 0 0\nvertex 0 0 1\nvertex 0 1 0\nendloop\nendfacet\n"
      "facet normal 1 1 1\nouter loop\nvertex 1 0 0\nvertex 0 1 0\nvertex 0 0 1\nendloop\nendfacet\n"
      "endsolid t\n"));
  EXPECT_EQ(from_stl.mesh.vertex_count(), 4u);
  EXPECT_TRUE(analyze_mesh(from_stl.mesh).closed());
  EXPECT_DOUBLE_EQ(testing::signed_volume(from_stl.mesh), testing::signed_volume(from_ply.mesh));
  EXPECT_GT(testing::signed_volume(from_ply.mesh), 0.0);
}

TEST(MeshIo, NeitherBinaryNorAsciiStlIsNamed) {
  expect_load_error(write_temp_file("short.stl", "not a mesh"), "not an STL file (10 bytes");
}

}  // namespace
}  // namespace wavetrace
