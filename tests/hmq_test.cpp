// HMQ: the strip table (507 entries), packed streams, the global grid from bits or epsilon,
// child box quantization, leaf records, agreement with robust Embree within the grid's
// error, watertightness at every q, and option errors.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <set>

#include <glm/geometric.hpp>

#include "wavetrace/accel/hmq/child_pair.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hmq/hmq_accelerator.hpp"
#include "wavetrace/accel/hmq/hmq_format.hpp"
#include "wavetrace/accel/hmq/leaf_codec.hpp"
#include "wavetrace/accel/hmq/packed_stream.hpp"
#include "wavetrace/accel/hmq/strip_table.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/image_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/config.hpp"
#include "accel_agreement.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/world.hpp"

namespace wavetrace {
namespace {

using namespace hmq;

TEST(HmqStripTable, HasThePapers507EntriesEachAPartitionWithConsistentSlots) {
  const StripTable& table = StripTable::instance();
  EXPECT_EQ(table.size(), 507u);  // p(1) + ... + p(14)
  std::set<std::vector<int>> seen;
  for (std::uint32_t i = 0; i < table.size(); ++i) {
    const StripLayoutEntry& e = table.entry(i);
    std::vector<int> parts(e.strip_length.begin(), e.strip_length.begin() + e.strips);
    EXPECT_TRUE(std::is_sorted(parts.rbegin(), parts.rend())) << "entry " << i << ": longest strip first";
    int total = 0, slots = 0;
    for (const int part : parts) total += part, slots += part + 2;
    EXPECT_EQ(total, e.triangles);
    EXPECT_EQ(slots, e.slots);
    EXPECT_TRUE(seen.insert(parts).second) << "entry " << i << " repeats a layout";
    for (std::uint32_t k = 0; k < e.triangles; ++k) EXPECT_LE(e.first_slot[k] + 2u, e.slots);
  }
  // STRIP3x1_TRIx2: five triangles at slots {0, 1, 2, 5, 8} (the paper's example).
  const std::uint32_t lengths[] = {1, 3, 1};
  const StripLayoutEntry& example = table.entry(table.find(lengths));
  ASSERT_EQ(example.triangles, 5);
  const std::vector<int> first(example.first_slot.begin(), example.first_slot.begin() + 5);
  EXPECT_EQ(first, (std::vector<int>{0, 1, 2, 5, 8}));
  EXPECT_TRUE(example.flipped[1]);
  EXPECT_FALSE(example.flipped[2]);
  const std::uint32_t too_many[] = {10, 5};
  EXPECT_THROW(table.find(too_many), std::invalid_argument);
}

// Streams laid end to end from any bit: each value read back at every width, from every
// starting bit within a byte, with the bits a stream takes exactly its values' bits.
TEST(HmqPackedStream, RoundTripsEveryWidthFromEveryStartingBit) {
  std::mt19937 random(7);
  for (std::uint32_t lead = 0; lead < 8; ++lead) {
    for (std::uint32_t bits = 0; bits <= 32; ++bits) {
      for (const std::uint32_t count : {1u, 5u, 42u}) {
        std::vector<std::uint32_t> values(count);
        for (auto& v : values) v = static_cast<std::uint32_t>(random() & ((std::uint64_t{1} << bits) - 1));
        LargeArray<std::byte> out;
        BitWriter writer(out);
        writer.append(0x5au & ((1u << lead) - 1), lead);  // a value before the stream, so that it starts at bit `lead`
        writer.append_stream(values, bits);
        writer.append(1, 1);  // and one after, which the stream's last value must not reach
        EXPECT_EQ(writer.written_bits(), lead + stream_bits(bits, count) + 1);
        writer.finish();
        EXPECT_EQ(out.size(), (lead + stream_bits(bits, count) + 1 + 7) / 8) << bits << " bits";
        out.resize(out.size() + 8);
        std::vector<std::uint32_t> back(count);
        read_stream(out.data(), lead, bits, count, back.data());
        EXPECT_EQ(back, values) << bits << " bits, " << count << " values from bit " << lead;
        EXPECT_EQ(read_value(out.data(), lead + stream_bits(bits, count), 1), 1u) << bits << " bits";
      }
    }
  }
}

#if WAVETRACE_AVX2
// The eight-lane reader every leaf decode uses, value for value against the scalar one, at
// every width it takes, from starting bits within and past the first byte, and at counts that
// end inside, at and past a block of eight.
TEST(HmqPackedStream, LaneReaderReadsWhatTheScalarReaderReads) {
  std::mt19937 random(11);
  for (const std::uint32_t lead : {0u, 3u, 7u, 45u}) {
    for (std::uint32_t bits = 1; bits <= kLaneStreamBits; ++bits) {
      for (const std::uint32_t count : {1u, 7u, 8u, 9u, 16u, 42u, 64u}) {
        std::vector<std::uint32_t> values(count);
        for (auto& v : values) v = static_cast<std::uint32_t>(random() & ((std::uint64_t{1} << bits) - 1));
        LargeArray<std::byte> out;
        BitWriter writer(out);
        for (std::uint32_t b = 0; b < lead; ++b) writer.append(1, 1);  // ones before the stream
        writer.append_stream(values, bits);
        writer.finish();
        out.resize(out.size() + 8);
        for (std::uint32_t first = 0; first < count; first += 8) {
          alignas(32) std::uint32_t lanes[8];
          _mm256_store_si256(reinterpret_cast<__m256i*>(lanes), read_stream_lanes(out.data(), lead, bits, first, count));
          for (std::uint32_t lane = 0; lane < 8; ++lane) {
            const std::uint32_t expected = first + lane < count ? values[first + lane] : 0u;
            EXPECT_EQ(lanes[lane], expected) << bits << " bits, value " << first + lane << " of " << count;
          }
        }
      }
    }
  }
}
#endif

TEST(HmqGlobalGrid, FromBitsOrEpsilonBoundsTheVertexError) {
  const Bounds3 bounds{{-1.0f, -2.0f, 0.0f}, {3.0f, 2.0f, 0.5f}};
  const GlobalGrid sixteen = grid_from_bits(bounds, 16);
  std::mt19937 random(3);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 10000; ++i) {
    const glm::vec3 p = bounds.lower + bounds.extent() * glm::vec3(unit(random), unit(random), unit(random));
    const glm::vec3 snapped = sixteen.point(sixteen.snap(p));
    EXPECT_LE(glm::length(snapped - p), sixteen.max_vertex_error * 1.0001);
  }
  const GlobalGrid bound = grid_from_epsilon(bounds, 1e-3);
  EXPECT_LE(bound.max_vertex_error, 1e-3 * 1.0001);
  EXPECT_GT(bound.max_vertex_error, 0.5e-3);
  EXPECT_EQ(bound.bits.x, 12u);  // 4 / (2e-3 / sqrt(3)) = 3464 cells: 12 bits hold 4095
  EXPECT_THROW(grid_from_epsilon(bounds, 1e-12), std::invalid_argument);
  EXPECT_THROW(grid_from_epsilon(bounds, -1.0), std::invalid_argument);
  EXPECT_THROW(grid_from_bits(bounds, 25), std::invalid_argument);
}

TEST(HmqNodes, QuantizedChildBoxesContainTheChildAndDecodeAsEncoded) {
  std::mt19937 random(11);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    const Box parent{{unit(random), unit(random), unit(random)},
                     {1.0f + 100.0f * unit(random), 2.0f + unit(random), 1.0f + 1e-3f * unit(random)}};
    Bounds3 child;
    for (int corner = 0; corner < 2; ++corner) {
      child.extend(parent.lower + (parent.upper - parent.lower) * glm::vec3(unit(random), unit(random), unit(random)));
    }
    std::uint32_t bits = 0;
    for (int axis = 0; axis < 3; ++axis) {
      // The encoder's rule, restated: largest q whose plane still holds the child.
      const float step = (parent.upper[axis] - parent.lower[axis]) * 0.0625f;
      std::uint32_t low = 15, high = 15;
      while (low > 0 && parent.lower[axis] + float(low) * step > child.lower[axis]) --low;
      while (high > 0 && parent.upper[axis] - float(high) * step < child.upper[axis]) --high;
      bits |= low << (4 * axis) | high << (12 + 4 * axis);
    }
    const Box decoded = decode_child_box(parent, bits);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_LE(decoded.lower[axis], child.lower[axis]);
      EXPECT_GE(decoded.upper[axis], child.upper[axis]);
      EXPECT_LE(decoded.upper[axis] - decoded.lower[axis],
                child.upper[axis] - child.lower[axis] + 2.0f * (parent.upper[axis] - parent.lower[axis]) / 16.0f * 1.001f);
    }
  }
}

TEST(HmqNodes, PairedDecodeAndBoxTestAreBitIdenticalToTheScalarOnes) {
  // Including rays along a box's faces (zero direction components: NaN slabs), rays through
  // a box's edge and origins inside the parent.
  std::mt19937 random(12);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<std::uint32_t> word(0, (1u << 24) - 1);
  for (int i = 0; i < 20000; ++i) {
    const glm::vec3 corner(unit(random), unit(random), unit(random));
    const Box parent{corner, corner + glm::vec3(1.0f + unit(random), 0.5f + unit(random), 1.5f + unit(random))};
    const std::uint32_t first = word(random), second = word(random);
    glm::vec3 direction(unit(random), unit(random), unit(random));
    glm::vec3 origin = parent.lower + (parent.upper - parent.lower) * glm::vec3(1.5f) * glm::vec3(unit(random), unit(random), unit(random));
    if (i % 4 == 1) direction[i % 3] = 0.0f;
    if (i % 4 == 2) {  // on a decoded face plane of the first child
      direction[i % 3] = 0.0f;
      origin[i % 3] = decode_child_box(parent, first).lower[i % 3];
    }
    if (i % 4 == 3) {  // at an edge of the first child, where entry and exit meet (the far scale)
      const Box box = decode_child_box(parent, first);
      const glm::vec3 edge(box.lower.x, box.upper.y, 0.5f * (box.lower.z + box.upper.z));
      origin = edge - glm::vec3(2.0f, -1.0f - unit(random), 0.5f * unit(random));
      direction = edge - origin;
    }
    const BoxRay ray = make_box_ray(origin, direction);
    const float tmin = i % 3 == 0 ? 0.0f : 0.25f, tmax = i % 5 == 0 ? 0.5f : 1e30f;
    const ChildPair pair = decode_and_intersect_children(parent, first, second, ray, tmin, tmax);
    for (int k = 0; k < 2; ++k) {
      const Box box = decode_child_box(parent, k == 0 ? first : second);
      for (int axis = 0; axis < 3; ++axis) {
        ASSERT_EQ(pair.box[k].lower[axis], box.lower[axis]);
        ASSERT_EQ(pair.box[k].upper[axis], box.upper[axis]);
      }
      ASSERT_EQ(pair.distance[k], intersect_box(ray, box.lower, box.upper, tmin, tmax)) << i << " child " << k;
    }
  }
}

// A leaf's box is re-snapped at every visit, in lanes: the lines GlobalGrid's scalar rounding
// gives, inside the grid, far outside it, at infinities and at NaN (a crafted world file's box).
TEST(HmqLeaf, SnappingABoxOutwardGivesTheScalarLinesEvenForCraftedBoxes) {
  const GlobalGrid grid = grid_from_bits(Bounds3{glm::vec3(-3.0f, 0.5f, 10.0f), glm::vec3(7.0f, 2.0f, 11.0f)}, 16);
  std::mt19937 random(5);
  std::uniform_real_distribution<float> coordinate(-20.0f, 20.0f);
  std::vector<float> values = {0.0f, -3.0f, 7.0f, 1e30f, -1e30f, std::numeric_limits<float>::infinity(),
                               -std::numeric_limits<float>::infinity(), std::numeric_limits<float>::quiet_NaN()};
  for (int i = 0; i < 200; ++i) values.push_back(coordinate(random));
  for (std::size_t i = 0; i < values.size(); ++i) {
    const Box box{glm::vec3(values[i], values[(i + 1) % values.size()], values[(i + 2) % values.size()]),
                  glm::vec3(values[(i + 3) % values.size()], values[(i + 4) % values.size()], values[(i + 5) % values.size()])};
    const GridBox snapped = snap_outward(grid, box);
    for (int axis = 0; axis < 3; ++axis) {
      EXPECT_EQ(snapped.lower[axis], grid.floor_line(box.lower[axis], axis)) << "box " << i << " axis " << axis;
      EXPECT_EQ(snapped.upper[axis], grid.ceil_line(box.upper[axis], axis)) << "box " << i << " axis " << axis;
    }
  }
}

TEST(HmqLeaf, RecordDecodesToTheSnappedVerticesIdsAndCorners) {
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  const GlobalGrid grid = grid_from_bits(scene.mesh.bounds(), 12);
  QuantizedMesh quantized{&scene.mesh, {}};
  for (const glm::vec3& p : scene.mesh.positions) quantized.lines.push_back(grid.snap(p));
  for (const std::uint32_t size : {1u, 4u, 8u, 14u}) {
    std::vector<std::uint32_t> triangles;
    for (std::uint32_t t = 100; t < 100 + size; ++t) triangles.push_back(t);
    Box box{glm::vec3(std::numeric_limits<float>::infinity()), glm::vec3(-std::numeric_limits<float>::infinity())};
    for (const std::uint32_t t : triangles) {
      for (int k = 0; k < 3; ++k) {
        const glm::vec3 p = grid.point(quantized.lines[scene.mesh.triangles[t][k]]);
        box.lower = glm::min(box.lower, p);
        box.upper = glm::max(box.upper, p);
      }
    }
    const GridBox grid_box = snap_outward(grid, box);
    LargeArray<std::byte> record;
    encode_leaf(quantized, triangles, grid_box, record);
    const std::size_t record_bytes = record.size();
    record.resize(record.size() + 8);
    EXPECT_EQ(record_bytes, leaf_record_bytes(record.data()));
    DecodedLeaf leaf;
    decode_leaf(record.data(), grid, grid_box, leaf);
    ASSERT_EQ(leaf.layout->triangles, size);
    std::multiset<std::uint32_t> ids;
    for (std::uint32_t k = 0; k < size; ++k) {
      const std::uint32_t id = leaf.triangle_id(k);
      ids.insert(id);
      const glm::uvec3& corners = scene.mesh.triangles[id];
      const std::uint32_t first = leaf.layout->first_slot[k];
      const std::uint32_t code = leaf.corner_code(k);
      EXPECT_EQ(leaf.slot_position(first + code / 3), grid.point(quantized.lines[corners.y])) << "triangle " << k;
      EXPECT_EQ(leaf.slot_position(first + code % 3), grid.point(quantized.lines[corners.z])) << "triangle " << k;
    }
    EXPECT_EQ(ids, std::multiset<std::uint32_t>(triangles.begin(), triangles.end()));
  }
}


class HmqAgreesWithEmbree : public ::testing::TestWithParam<std::string> {};

TEST_P(HmqAgreesWithEmbree, ExactlyOnTheSurfaceItRepresentsAndWithinItsErrorOnTheMesh) {
  const Scene scene = load_scene({GetParam(), 0});
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(scene.mesh, robust);
  const float diagonal = scene.mesh.bounds().diagonal();
  for (const std::uint32_t leaf_size : {4u, 8u, 12u}) {
    HmqOptions options;
    options.leaf_size = leaf_size;
    options.top_fraction = leaf_size == 4 ? 0.0 : 0.05;
    const auto hmq = make_hmq_accelerator(scene.mesh, options);
    // Against robust Embree on the snapped mesh: the same surface, so the same answers.
    const TriangleMesh snapped = *hmq->represented_mesh(scene.mesh);
    const auto snapped_reference = make_accelerator(snapped, robust);
    Scene snapped_scene = scene;
    snapped_scene.mesh = snapped;
    for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
      const testing::Agreement result =
          testing::compare_on_rays(snapped_scene, *snapped_reference, *hmq, kind, 8000, 1e-4f * diagonal, 0.05f);
      const std::string label = "leaf " + std::to_string(leaf_size) + " " + to_string(kind);
      EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays)) << label;
      EXPECT_LE(double(result.far_t), 1e-4 * double(result.rays)) << label;
      EXPECT_EQ(result.far_uv, 0u) << label;
      if (kind == RaySetKind::primary) {
        EXPECT_GT(result.same_primitive, result.rays / 50) << label;
      }
    }
    // Against the mesh itself, from the camera: vertices moved by ~1e-5 of the scene at q = 16
    // change an answer only on silhouettes (a grazing ray that now hits or misses a triangle
    // finds its hit far away).
    const testing::Agreement original =
        testing::compare_on_rays(scene, *reference, *hmq, RaySetKind::primary, 8000, 1e-3f * diagonal, 0.05f);
    EXPECT_LE(double(original.hit_differs), 1e-3 * double(original.rays)) << "leaf " << leaf_size;
    EXPECT_LE(double(original.far_t), 3e-3 * double(original.rays)) << "leaf " << leaf_size;
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, HmqAgreesWithEmbree,
                         ::testing::ValuesIn(testing::agreement_scenes("builtin:soup:20k")),
                         testing::agreement_scene_label);

TEST(Hmq, NoRayEscapesClosedMeshesAtAnyGridResolution) {
  // From points inside the surface it represents (the leak bench asks represented_mesh).
  for (const char* source : {"builtin:sphere:100k", "builtin:room:50k"}) {
    const Scene scene = make_builtin_scene(source);
    const LeakReport report = run_leak_bench(scene,
                                             {parse_accelerator_spec("hmq:bits=8", Config{}),
                                              parse_accelerator_spec("hmq:bits=12", Config{}),
                                              parse_accelerator_spec("hmq:bits=16:leaf_size=4", Config{})},
                                             100000, 0);
    ASSERT_EQ(report.results.size(), 3u);
    for (const LeakResult& result : report.results) EXPECT_EQ(result.escaped, 0u) << source << " " << result.label;
  }
}

TEST(Hmq, MemoryIsItsPartsAndFarBelowTheBaseline) {
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  const auto hmq = make_hmq_accelerator(scene.mesh, HmqOptions{});
  std::size_t span_bytes = 0;
  for (const auto& span : hmq->memory_spans()) span_bytes += span.size();
  EXPECT_EQ(hmq->memory().total(), span_bytes);
  const auto bvh = make_bvh_accelerator(scene.mesh, BvhOptions{});
  EXPECT_LT(hmq->memory().total() * 4, bvh->memory().total());
  HmqOptions coarse;
  coarse.bits = 10;
  EXPECT_LT(make_hmq_accelerator(scene.mesh, coarse)->memory().total(), hmq->memory().total());
  EXPECT_NE(hmq->build_notes().find("grid 16x16x16 bits"), std::string::npos) << hmq->build_notes();
}

TEST(Hmq, HitPointsStayWithinThePromisedErrorOfTheMesh) {
  const Scene scene = make_builtin_scene("builtin:sphere:20k");
  AccelBenchRequest request;
  request.accelerators = {parse_accelerator_spec("hmq:bits=8", Config{}), parse_accelerator_spec("hmq:bits=16", Config{}),
                          parse_accelerator_spec("bvh", Config{})};
  request.count = 20000;
  request.repeats = 1;
  const AccelBenchReport report = run_accel_bench(scene, request);
  ASSERT_EQ(report.results.size(), 3u);
  for (const std::uint32_t index : {0u, 1u}) {
    const AccelBenchResult& result = report.results[index];
    const double promised = grid_from_bits(scene.mesh.bounds(), index == 0 ? 8 : 16).max_vertex_error;
    ASSERT_TRUE(result.surface_error_max && result.vertex_error_max) << result.label;
    EXPECT_LE(*result.vertex_error_max, promised) << result.label;
    EXPECT_LE(*result.surface_error_max, promised * 1.05) << result.label;  // plus origin + t d in float
    EXPECT_GT(*result.surface_error_max, promised * 0.1) << result.label;   // it does move the surface
  }
  EXPECT_FALSE(report.results[2].surface_error_max) << "bvh is exact: nothing to report";
}

TEST(Hmq, ImagesApproachTheReferenceAsTheGridRefines) {
  Config config;
  config.set_value("scene.source", std::string("builtin:sphere:20k"));
  config.set("render.width=64");
  config.set("render.height=48");
  config.set("render.spp=2");
  std::vector<AcceleratorSpec> accelerators;
  for (const char* text : {"embree:mode=robust", "bvh", "hmq:bits=6", "hmq:bits=16"}) {
    accelerators.push_back(parse_accelerator_spec(text, config));
  }
  const ImageBenchReport report = run_image_bench(config, accelerators);
  ASSERT_EQ(report.results.size(), 4u);
  EXPECT_EQ(report.results[0].rmse, 0.0);
  EXPECT_LT(report.results[1].relative_rmse, 1e-3) << "the same surface, watertight both";
  EXPECT_GT(report.results[2].rmse, report.results[3].rmse);
  EXPECT_GT(report.results[2].relative_rmse, 1e-3) << "64 lines per axis visibly move the sphere";
  EXPECT_LT(report.results[3].relative_rmse, 1e-2);
  EXPECT_LT(report.results[3].bytes_per_triangle, report.results[1].bytes_per_triangle / 3);
}

TEST(Hmq, BadOptionsAreClearErrors) {
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  HmqOptions options;
  options.leaf_size = 15;
  EXPECT_THROW(make_hmq_accelerator(scene.mesh, options), std::invalid_argument);
  options = {};
  options.bits = 0;
  EXPECT_THROW(make_hmq_accelerator(scene.mesh, options), std::invalid_argument);
  options = {};
  options.epsilon = 1e-3;
  options.bits = 12;
  EXPECT_THROW(make_hmq_accelerator(scene.mesh, options), std::invalid_argument);
  options = {};
  options.top_fraction = 1.5;
  EXPECT_THROW(make_hmq_accelerator(scene.mesh, options), std::invalid_argument);
  EXPECT_THROW(parse_accelerator_spec("hmq:bits=12:epsilon=0.001", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("hmq:leaf_size=20", Config{}), ConfigError);
  EXPECT_THROW(make_hmq_accelerator(TriangleMesh{}, HmqOptions{}), std::invalid_argument);
  options = {};
  options.epsilon = 1e-4;
  const auto bounded = make_hmq_accelerator(scene.mesh, options);
  EXPECT_NE(bounded->build_notes().find("vertex error <= "), std::string::npos);
}

// Shadow rays end just short of a light sample. Sampled on the exact emitter, a quantized
// scene's samples lie behind the emitter as HMQ represents it (room's light hangs 0.01 under
// the ceiling; 8 bits a side move it 0.004), which then shadows most of its own light.
TEST(HmqRender, LightsAreSampledOnTheSurfaceHmqRepresents) {
  const Scene room = make_builtin_scene("builtin:room:20k");
  AcceleratorOptions options;
  options.type = "hmq";
  options.hmq.bits = 8;
  const auto hmq = build_world_accelerator(room, options);
  const LightSampler exact(room);
  const LightSampler represented = represented_lights(room, *hmq);
  ASSERT_EQ(represented.count(), exact.count());
  for (std::size_t i = 0; i < exact.count(); ++i) {
    EXPECT_EQ(represented.triangles()[i].corner, hmq->represented_point(exact.triangles()[i].corner));
  }
  const auto occluded_share = [&](const LightSampler& lights) {
    constexpr std::size_t kRays = 1000;
    RayBatch rays(kRays);
    HitBatch hits(kRays);
    const glm::vec3 origin(0.0f, 1.5f, 0.0f);  // the room's middle, in the light's open view
    for (std::size_t i = 0; i < kRays; ++i) {
      const LightSample sample = lights.sample((float(i) + 0.5f) / kRays, float((i * 37) % kRays) / kRays,
                                               float((i * 91) % kRays) / kRays);
      const glm::vec3 to_light = sample.point - origin;
      const float distance = glm::length(to_light);
      rays.set_geometry(i, origin, to_light / distance, 0.0f, distance * (1.0f - 1e-4f));
      rays.flags[i] = ray_flags::alive;
    }
    rays.count = kRays;
    hmq->intersect_any(rays, hits, rays.all());
    std::size_t occluded = 0;
    for (std::size_t i = 0; i < kRays; ++i) occluded += hits.primitive[i] != kInvalidPrimitive;
    return double(occluded) / kRays;
  };
  EXPECT_LT(occluded_share(represented), 0.01);
  EXPECT_GT(occluded_share(exact), 0.5) << "the case this guards no longer arises: pick a coarser grid";
}

}  // namespace
}  // namespace wavetrace
