// Damaged and crafted world files: every problem refused on load with the file and the
// section named, flipped bytes refused or harmless, and leaf records that stay in range
// whatever their bytes say.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <random>

#include <fmt/format.h>

#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "world_file_support.hpp"

namespace wavetrace {
namespace {

using namespace world_testing;  // and its fs, Header and TableEntry

class DamagedWorld : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = temp_path("damaged.wtw");
    good_ = temp_path("good.wtw");
    build_and_save({"accel.type=hmq", "build.chunk_triangles=8192"}, good_);
    bytes_ = read_all(good_);
  }
  void TearDown() override {
    fs::remove(path_);
    fs::remove(good_);
  }
  std::string path_, good_, bytes_;
};

TEST_F(DamagedWorld, EachProblemIsNamedWithTheFile) {
  const auto expect_error = [&](const std::string& contents, const std::string& problem) {
    write_all(path_, contents);
    const std::string error = open_error(path_);
    EXPECT_NE(error.find(path_), std::string::npos) << error;
    EXPECT_NE(error.find(problem), std::string::npos) << "expected '" << problem << "' in: " << error;
  };
  expect_error(bytes_.substr(0, 40), "truncated");
  expect_error(bytes_.substr(0, bytes_.size() - 4096), "truncated");
  expect_error(std::string(bytes_.size(), '\0'), "incomplete");
  std::string magic = bytes_;
  magic[0] = 'X';
  expect_error(magic, "not a wavetrace world file");
  std::string data = bytes_;
  Resealer probe(good_);
  data[probe.entry("accel/chunk.0/hmq.blocks").offset + 100] ^= 0x10;
  expect_error(data, "'accel/chunk.0/hmq.blocks' checksum mismatch");
  std::string table = bytes_;
  table[probe.header.table_offset + 70] ^= 0x01;
  expect_error(table, "table checksum mismatch");

  Resealer version(good_);
  version.header.version = 7;
  version.seal(path_);
  EXPECT_NE(open_error(path_).find("container version 7"), std::string::npos) << open_error(path_);

  Resealer accel_version(good_);
  SavedKind kind{};
  std::memcpy(&kind, accel_version.data("accel/chunk.0/kind"), sizeof(kind));
  kind.version = 99;
  std::memcpy(accel_version.data("accel/chunk.0/kind"), &kind, sizeof(kind));
  accel_version.seal(path_);
  EXPECT_NE(open_error(path_).find("'hmq' format version 99"), std::string::npos) << open_error(path_);

  Resealer outside(good_);
  outside.entry("accel/chunk.0/hmq.blocks").size = std::uint64_t{1} << 40;
  outside.seal(path_);
  EXPECT_NE(open_error(path_).find("lies outside the file"), std::string::npos) << open_error(path_);
}

// Chunks are checked in parallel; of two damaged ones the lower is named, on every load.
TEST_F(DamagedWorld, OfTwoDamagedChunksTheLowerIsNamedEveryTime) {
  Resealer two(good_);
  for (const auto& [chunk, version] : {std::pair{1, 98u}, std::pair{2, 99u}}) {
    const std::string name = fmt::format("accel/chunk.{}/kind", chunk);
    SavedKind kind{};
    std::memcpy(&kind, two.data(name), sizeof(kind));
    kind.version = version;
    std::memcpy(two.data(name), &kind, sizeof(kind));
  }
  two.seal(path_);
  for (int load = 0; load < 4; ++load) {
    const std::string error = open_error(path_);
    EXPECT_NE(error.find("chunk.1/"), std::string::npos) << error;
    EXPECT_NE(error.find("'hmq' format version 98"), std::string::npos) << error;
  }
}

TEST_F(DamagedWorld, FlippedBytesAnywhereAreRefusedOrHarmless) {
  const std::vector<float> expected = render_loaded({"accel.type=hmq"}, good_);
  std::mt19937_64 random(20261201);
  std::size_t refused = 0, harmless = 0;
  for (int trial = 0; trial < 300; ++trial) {
    std::string damaged = bytes_;
    const std::size_t at = random() % damaged.size();
    damaged[at] = static_cast<char>(damaged[at] ^ static_cast<char>(1 + random() % 255));
    write_all(path_, damaged);
    try {
      // A flip in the zero padding between sections touches no checked byte: the world
      // must then load and render exactly as before.
      EXPECT_TRUE(render_loaded({"accel.type=hmq"}, path_) == expected) << "flip at byte " << at;
      ++harmless;
    } catch (const SectionFileError& error) {
      EXPECT_NE(std::string(error.what()).find(path_), std::string::npos);
      ++refused;
    }
  }
  EXPECT_GT(refused, 0u);
  EXPECT_EQ(refused + harmless, 300u);
}

// The world-file fuzz target's findings, each a file whose checksums were re-sealed after a
// change: before its structure was checked on load, each was a crash or a hang at the first
// ray. Now each is an error naming the file and the section.
struct CraftedCase {
  std::string name;  // the test's
  std::vector<std::string> settings;
  std::string section;                      // under accel/
  std::function<void(char* data)> damage;  // what the crafted file changes in it
  std::string problem;                      // expected in the error
};

void PrintTo(const CraftedCase& c, std::ostream* out) { *out << c.name; }

class CraftedWorld : public ::testing::TestWithParam<CraftedCase> {};

template <typename T>
void poke(char* at, T value) {
  std::memcpy(at, &value, sizeof value);
}
template <typename T>
T peek(const char* at) {
  T value;
  std::memcpy(&value, at, sizeof value);
  return value;
}

TEST_P(CraftedWorld, IsRefusedOnLoadNamingTheSection) {
  const CraftedCase& c = GetParam();
  const std::string good = temp_path("crafted_good.wtw"), crafted = temp_path("crafted.wtw");
  build_and_save(c.settings, good);
  Resealer world(good);
  c.damage(world.data("accel/" + c.section));
  world.seal(crafted);
  const std::string error = open_error(crafted);
  EXPECT_NE(error.find(crafted), std::string::npos) << error;
  EXPECT_NE(error.find("'accel/" + c.section + "'"), std::string::npos) << error;
  EXPECT_NE(error.find(c.problem), std::string::npos) << "expected '" << c.problem << "' in: " << error;
  fs::remove(good);
  fs::remove(crafted);
}

// The quantized 8-wide root's first inner child made itself and its leaves past 2^30: the same
// damage for HMQ's and Ray-Strips' wide tops, which share the node.
void point_wide_node_past_its_arrays(char* node) {
  poke<std::uint32_t>(node + 48, 0);        // child_base
  poke<std::uint32_t>(node + 52, 1u << 30);  // leaf_base
}

// The first leaf record (hmq_format.hpp's bits) made plain strips of 63 vertices, as many as
// any layout has slots, so that no other check fails first, and given a 32-bit id base of
// all ones: every triangle it names lies past the mesh.
void set_first_leaf_id_base_past_every_triangle(char* record) {
  std::uint64_t header = peek<std::uint64_t>(record);
  header &= ~(std::uint64_t{1} << 9);                          // plain strips
  header |= std::uint64_t{63} << 10;                           // vertex count
  header |= std::uint64_t{31} << 36 | ~std::uint64_t{0} << 41;  // the base 32 bits wide, its first 23 ones
  poke<std::uint64_t>(record, header);
  poke<std::uint8_t>(record + 8, 0xff);                                         // the next 8
  poke<std::uint8_t>(record + 9, std::uint8_t(peek<std::uint8_t>(record + 9) | 1u));  // and the last
}

// Offsets from the formats' comments: BvhNode first at 24 (bvh_node.hpp), WideBvhNode child[0]
// at 192 and count[0] at 224 (wide_bvh_node.hpp), TriangleBlock slot[0] at 144
// (triangle_block.hpp), QuantizedWideNode child_base at 48 and
// leaf_base at 52 (quantized_wide_node.hpp), an HMQ block's node_slots at 0 (hmq_format.hpp),
// a strip's triangle count at 0 (ray_strip_format.hpp).
INSTANTIATE_TEST_SUITE_P(
    FuzzFindings, CraftedWorld,
    ::testing::Values(
        CraftedCase{"BvhChildBeforeItsParent", {"accel.type=bvh"}, "bvh.nodes", [](char* d) { poke<std::uint32_t>(d + 24, 0); },
                    "node 0 names child 0, which does not lie after it"},
        CraftedCase{"WideBvhChildPastTheNodes", {"accel.type=bvh", "accel.bvh.width=8"}, "bvh8.nodes",
                    [](char* d) {
                      poke<std::uint32_t>(d + 192, 1u << 30);
                      poke<std::uint8_t>(d + 224, 0);
                    },
                    "which does not lie after it"},
        CraftedCase{"WideBvhLeafPastItsBlocks", {"accel.type=bvh", "accel.bvh.width=8"}, "bvh8.nodes",
                    [](char* d) {
                      for (char* node = d;; node += 256) {  // the first leaf lane: count != 0
                        for (int lane = 0; lane < 8; ++lane) {
                          if (d[224 + (node - d) + lane] != 0) return poke<std::uint32_t>(node + 192 + 4 * lane, 1u << 30);
                        }
                      }
                    },
                    "triangle blocks"},
        CraftedCase{"TriangleBlockOfAMissingTriangle", {"accel.type=bvh", "accel.bvh.width=8"}, "bvh8.triangle_blocks",
                    [](char* d) { poke<std::uint32_t>(d + 144, 1u << 30); }, "names a triangle that does not exist"},
        CraftedCase{"ChunkedTopChildBeforeItsParent", {"accel.type=bvh", "build.chunk_triangles=4096"}, "chunked.top",
                    [](char* d) { poke<std::uint32_t>(d + 24, 0); }, "does not lie after it"},
        CraftedCase{"HmqBlockWithoutNodes", {"accel.type=hmq"}, "hmq.blocks", [](char* d) { poke<std::uint8_t>(d, 0); },
                    "block at word 0: has 0 node and"},
        CraftedCase{"WideHmqChildAndLeafPastTheirArrays", {"accel.type=hmq", "accel.hmq.width=8"}, "hmq8.nodes",
                    point_wide_node_past_its_arrays,
                    "node 0"},
        CraftedCase{"WideHmqLeafOfAStripLayoutPastTheTable", {"accel.type=hmq", "accel.hmq.width=8"}, "hmq8.leaves",
                    [](char* d) { poke<std::uint16_t>(d, std::uint16_t(peek<std::uint16_t>(d) | 511u)); },
                    "has a leaf of strip table entry 511"},
        CraftedCase{"WideHmqLeafOfAMissingTriangle", {"accel.type=hmq", "accel.hmq.width=8"}, "hmq8.leaves",
                    set_first_leaf_id_base_past_every_triangle, "has a leaf naming a triangle that does not exist"},
        CraftedCase{"WideHmqTogetherChildBeforeItsParent",
                    {"accel.type=hmq", "accel.hmq.width=8", "accel.hmq.leaves_beside_nodes=true"}, "hmq8.tree",
                    point_wide_node_past_its_arrays, "node at unit 0 names child 0"},
        CraftedCase{"LeafOfMoreStripsThanFollowIt", {"accel.type=raystrips"}, "raystrips.nodes",
                    [](char* d) {
                      for (char* node = d;; node += 32) {  // the first leaf: count with bit 31
                        std::uint32_t count;
                        std::memcpy(&count, node + 28, 4);
                        if (count & 0x80000000u) return poke<std::uint32_t>(node + 28, 0xffffffffu);
                      }
                    },
                    "has a leaf of more strips than follow it"},
        CraftedCase{"StripOfNoTriangles", {"accel.type=raystrips"}, "raystrips.strips", [](char* d) { poke<std::uint16_t>(d, 0); },
                    "the strip at byte 0 has no triangles"},
        CraftedCase{"StripOfIndexWidthsThatDoNotExist", {"accel.type=raystrips"}, "raystrips.strips",
                    [](char* d) { poke<std::uint8_t>(d + 2, 0x05); },  // 16-bit and 8-bit indices at once
                    "the strip at byte 0 has index or record widths this version does not know"},
        CraftedCase{"WideRayStripsChildAndLeafPastTheirArrays", {"accel.type=raystrips", "accel.raystrips.width=8"}, "raystrips.wide_nodes",
                    point_wide_node_past_its_arrays,
                    "node 0"}),
    [](const ::testing::TestParamInfo<CraftedCase>& info) { return info.param.name; });

TEST(CraftedLeaves, GridLinesAndStripCornersStayInRangeForAnyInput) {
  // A crafted box decoded to NaN or far outside the grid: the line conversion is defined;
  // a box inside the grid gets the lines it always got.
  const GlobalGrid grid = grid_from_bits(Bounds3{glm::vec3(0.0f), glm::vec3(1.0f)}, 8);
  EXPECT_EQ(grid.floor_line(std::numeric_limits<float>::quiet_NaN(), 0), -(1 << 30));
  EXPECT_EQ(grid.ceil_line(1e30f, 1), 1 << 30);
  EXPECT_EQ(grid.floor_line(0.5f, 2), int(std::floor((0.5f - grid.origin.z) * grid.inverse_cell.z)));
  // A corner code of two equal corners (a strip's repeat, or a crafted record) reads corners
  // of the triangle, not past them (AddressSanitizer, in the sanitizer build, would report
  // the read past the array); a code of two different corners gives the triangle's plane.
  const glm::vec3 corners[3] = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (std::uint32_t code = 0; code < 8; ++code) {
    HitBatch hits(1);
    hits.set_hit(0, 1.0f, 0, 0.25f, 0.25f);
    set_surface_from_strip(hits, 0, corners, code);
    if (code / 3 != code % 3) {
      EXPECT_FLOAT_EQ(std::fabs(hits.normal_z[0]), 1.0f) << code;
    }
  }
}

}  // namespace
}  // namespace wavetrace
