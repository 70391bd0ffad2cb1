// Binary PLY: what export writes, the streaming reader reads back to the bit, in any order
// of ranges; the reader takes big-endian files, doubles, polygons and extra properties, and
// names the problem in a bad file.
#include <gtest/gtest.h>

#include <bit>
#include <cstring>
#include <limits>

#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/ply_file.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / "wavetrace_ply_tests";
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

void expect_same_triangles(const TriangleMesh& whole, std::size_t first, const TriangleMesh& part) {
  for (std::size_t t = 0; t < part.triangle_count(); ++t) {
    for (int k = 0; k < 3; ++k) {
      ASSERT_EQ(part.positions[part.triangles[t][k]], whole.positions[whole.triangles[first + t][k]])
          << "triangle " << first + t;
    }
  }
}

TEST(PlyFile, ExportReadsBackToTheBitInAnyOrderOfRanges) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const std::string path = temp_path("room.ply");
  SceneRequest request{"builtin:room:20k", 0};
  request.streamed = true;
  const Scene streamed = load_scene(request);
  write_binary_ply(*streamed.stream, path, 3000);  // pieces, written from the generators
  ASSERT_TRUE(is_binary_ply(path));
  const PlyTriangleSource source(path);
  ASSERT_EQ(source.triangle_count(), scene.triangle_count);
  EXPECT_EQ(source.bounds().lower, scene.bounds.lower);
  EXPECT_EQ(source.bounds().upper, scene.bounds.upper);
  const std::size_t n = source.triangle_count();
  for (const std::size_t first : {std::size_t{0}, n / 3, n / 5, n - 10}) {  // backwards too
    const std::size_t count = std::min<std::size_t>(4000, n - first);
    const TriangleMesh part = source.extract(first, count);
    ASSERT_EQ(part.triangle_count(), count);
    expect_same_triangles(scene.mesh, first, part);
  }
  // Loaded whole (not streamed) it is the same mesh; streamed, the scene keeps the reader.
  const Scene loaded = load_scene({path, 0});
  EXPECT_FALSE(loaded.streamed());
  expect_same_triangles(scene.mesh, 0, loaded.mesh);
  SceneRequest stream_request{path, 0};
  stream_request.streamed = true;
  const Scene stream = load_scene(stream_request);
  ASSERT_TRUE(stream.streamed());
  EXPECT_EQ(stream.triangle_count, scene.triangle_count);
  EXPECT_FALSE(is_binary_ply(testing::data_path("sphere.ply"))) << "ASCII PLY goes to the text reader (ply_text_reader.cpp)";
}

// A little builder of binary PLY bytes.
struct PlyBytes {
  std::string header;
  std::string data;
  bool big_endian = false;
  template <typename T>
  void put(T value) {
    char raw[sizeof(T)];
    std::memcpy(raw, &value, sizeof(T));
    if (big_endian) std::reverse(raw, raw + sizeof(T));
    data.append(raw, sizeof(T));
  }
  std::string write(const std::string& name) const { return testing::write_temp_file(name, header + data); }
};

TEST(PlyFile, ReadsBigEndianDoublesPolygonsAndSkipsOtherProperties) {
  PlyBytes ply;
  ply.big_endian = true;
  ply.header =
      "ply\nformat binary_big_endian 1.0\ncomment a test\nelement material 2\nproperty uchar red\nproperty float shine\n"
      "element vertex 5\nproperty double z\nproperty uchar flag\nproperty double x\nproperty double y\n"
      "element face 3\nproperty ushort group\nproperty list uint int vertex_indices\nproperty float quality\nend_header\n";
  for (int m = 0; m < 2; ++m) {
    ply.put<std::uint8_t>(7);
    ply.put<float>(0.5f);
  }
  const double points[5][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {2, 2, 0.25}};
  for (const auto& p : points) {
    ply.put<double>(p[2]);
    ply.put<std::uint8_t>(1);
    ply.put<double>(p[0]);
    ply.put<double>(p[1]);
  }
  // A quad (two triangles), a triangle with a repeated corner (dropped), a triangle.
  const std::vector<std::vector<int>> faces = {{0, 1, 2, 3}, {0, 0, 4}, {1, 4, 2}};
  for (const auto& face : faces) {
    ply.put<std::uint16_t>(3);
    ply.put<std::uint32_t>(static_cast<std::uint32_t>(face.size()));
    for (const int index : face) ply.put<std::int32_t>(index);
    ply.put<float>(1.0f);
  }
  const PlyTriangleSource source(ply.write("big.ply"));
  EXPECT_EQ(source.triangle_count(), 3u);
  EXPECT_EQ(source.polygons_triangulated(), 1u);
  EXPECT_EQ(source.degenerate_dropped(), 1u);
  const TriangleMesh mesh = source.extract(0, 3);
  const auto corner = [&](std::size_t t, int k) { return mesh.positions[mesh.triangles[t][k]]; };
  EXPECT_EQ(corner(0, 0), glm::vec3(0, 0, 0));
  EXPECT_EQ(corner(0, 1), glm::vec3(1, 0, 0));
  EXPECT_EQ(corner(0, 2), glm::vec3(1, 1, 0));
  EXPECT_EQ(corner(1, 2), glm::vec3(0, 1, 0));
  EXPECT_EQ(corner(2, 1), glm::vec3(2, 2, 0.25f));
  EXPECT_EQ(source.extract(2, 1).positions.size(), 3u) << "a range holds only its own vertices";
}

void expect_bad(const std::string& name, const std::string& contents, const std::string& message) {
  const std::string path = testing::write_temp_file(name, contents);
  try {
    PlyTriangleSource source(path);
    FAIL() << name << ": no error";
  } catch (const SceneError& error) {
    EXPECT_NE(std::string(error.what()).find(message), std::string::npos) << error.what();
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos) << error.what();
  }
}

TEST(PlyFile, BadFilesNameTheProblem) {
  const std::string head = "ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty float x\nproperty float y\n"
                           "property float z\nelement face 1\nproperty list uchar int vertex_indices\nend_header\n";
  PlyBytes good;
  good.header = head;
  for (int v = 0; v < 3; ++v) {
    good.put<float>(float(v == 1));
    good.put<float>(float(v == 2));
    good.put<float>(0.0f);
  }
  good.put<std::uint8_t>(3);
  for (int k = 0; k < 3; ++k) good.put<std::int32_t>(k);
  EXPECT_EQ(PlyTriangleSource(good.write("good.ply")).triangle_count(), 1u);

  expect_bad("truncated.ply", good.header + good.data.substr(0, good.data.size() - 5), "truncated");
  std::string out_of_range = good.header + good.data;
  const std::int32_t far = 7;
  std::memcpy(out_of_range.data() + out_of_range.size() - 4, &far, 4);
  expect_bad("index.ply", out_of_range, "face 0 references vertex 7");
  std::string nan = good.header + good.data;
  const float not_a_number = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(nan.data() + good.header.size(), &not_a_number, 4);
  expect_bad("nan.ply", nan, "vertex 0 has a coordinate that is not finite");
  std::string no_z = head;
  no_z.replace(no_z.find("property float z\n"), 17, "property float w\n");
  expect_bad("noz.ply", no_z + good.data, "need one 'z' property");
  expect_bad("words.ply", "ply\nformat binary_little_endian 1.0\nelement vertex x\nend_header\n", "header line 3");
  expect_bad("noend.ply", "ply\nformat binary_little_endian 1.0\nelement vertex 3\n", "no end_header");
}

}  // namespace
}  // namespace wavetrace
