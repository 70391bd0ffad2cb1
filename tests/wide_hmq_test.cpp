// hmq:width=8: the very hits of the binary layout (the same snapped triangles, and node boxes
// that never lose one), on the scenes where methods fail too; closed meshes do not leak;
// memory, the collapse, and bad options.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <string>

#include "wavetrace/accel/hmq/hmq_accelerator.hpp"
#include "wavetrace/accel/bvh/quantized_wide_node.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/memory/read_tally.hpp"
#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "accel_agreement.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {


HmqOptions hmq_options(std::uint32_t width, std::uint32_t leaf_size, std::uint32_t bits) {
  HmqOptions options;
  options.width = width;
  options.leaf_size = leaf_size;
  options.bits = bits;
  return options;
}

std::string scene_label(const ::testing::TestParamInfo<std::string>& info) {
  static const std::vector<std::string> names = {"sphere", "soup", "terrain", "stadium", "fur", "bunny"};
  return names[info.index];
}

class WideHmqMatchesBinary : public ::testing::TestWithParam<std::string> {};

// Both layouts hold the same leaves over the same grid, so every ray must find the same
// nearest surface. A child box quantized too tightly would lose hits here; one decoded
// differently from the encoder, too. Distances agree to float rounding: where snapping makes
// two triangles coincide (stadium, fur, bits = 10), the layouts' different visiting orders
// may meet either one first, at distances a few ulps apart.
TEST_P(WideHmqMatchesBinary, SameHitsAndDistancesOnEveryRayKind) {
  const Scene scene = load_scene({GetParam(), 0});
  const float tolerance = 1e-6f * scene.mesh.bounds().diagonal();
  for (const std::uint32_t leaf_size : {1u, 8u, 14u}) {
    for (const std::uint32_t bits : {10u, 16u}) {
      const auto binary = make_hmq_accelerator(scene.mesh, hmq_options(2, leaf_size, bits));
      const auto wide = make_hmq_accelerator(scene.mesh, hmq_options(8, leaf_size, bits));
      ASSERT_EQ(wide->name(), "hmq8");
      for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::diffuse, RaySetKind::shadow, RaySetKind::random}) {
        const testing::Agreement result = testing::compare_on_rays(scene, *binary, *wide, kind, 4000, tolerance, 1e-4f);
        const std::string label = to_string(kind) + " leaf_size " + std::to_string(leaf_size) + " bits " + std::to_string(bits);
        EXPECT_EQ(result.hit_differs, 0u) << label;
        EXPECT_EQ(result.far_t, 0u) << label;
        EXPECT_EQ(result.far_uv, 0u) << label;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, WideHmqMatchesBinary,
                         ::testing::Values("builtin:sphere:50k", "builtin:soup:20k", "builtin:terrain:30k",
                                           "builtin:stadium:2000", "builtin:fur:30k",
                                           std::string(WAVETRACE_DATA_DIR) + "/bunny00.off"),
                         scene_label);

TEST(WideHmq, PacketsAnswerExactlyAsSingleRays) {
  for (const char* source : {"builtin:sphere:30k", "builtin:room:50k", "builtin:fur:20k"}) {
    const Scene scene = make_builtin_scene(source);
    const auto wide = make_hmq_accelerator(scene.mesh, hmq_options(8, 8, 16));
    const RaySet rays = make_ray_set(RaySetKind::primary, scene, *wide, 20000);
    const auto single = trace_ray_set(*wide, rays, false);
    const auto packets = trace_ray_set(*wide, rays, true);
    std::size_t hits = 0;
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(single[b]->t[i], packets[b]->t[i]) << source;
        if (std::string(source) != "builtin:fur:20k") {  // coincident strands may tie in another order
          ASSERT_EQ(single[b]->primitive[i], packets[b]->primitive[i]) << source;
          ASSERT_EQ(single[b]->u[i], packets[b]->u[i]) << source;
        }
        hits += single[b]->is_hit(i);
      }
    }
    EXPECT_GT(hits, 1000u) << source;
  }
}

// The walks keep the leaves they decoded last for the next ray (DecodedLeafCache), but a probed
// walk, which the pagers and the read counts follow, must still read every record it tests:
// the same ray 64 times reads 64 times what it reads once, and hits as it does unprobed.
TEST(WideHmq, ProbedWalksReadEveryLeafTheyTestWhatEverTheyDecodedBefore) {
  const Scene scene = make_builtin_scene("builtin:sphere:20k");
  for (const std::uint32_t width : {2u, 8u}) {
    const auto accel = make_hmq_accelerator(scene.mesh, hmq_options(width, 8, 16));
    const auto count_reads = [&](std::size_t copies) {
      RayBatch rays(copies);
      HitBatch probed(copies), plain(copies);
      rays.count = copies;
      for (std::size_t i = 0; i < copies; ++i) {
        rays.set_geometry(i, {0.1f, 0.2f, 3.0f}, {0.0f, 0.0f, -1.0f}, 0.0f, std::numeric_limits<float>::infinity());
        rays.flags[i] = ray_flags::alive;
        rays.kind[i] = RayKind::camera;
      }
      ReadTally tally(accel->memory_spans(), 1);
      RecordingProbe probe(MemoryObservers{nullptr, nullptr, nullptr, &tally}, 0, 0);
      const RayRange all{0, std::uint32_t(copies)};
      accel->intersect_closest_probed(rays, probed, all, probe);
      accel->intersect_closest(rays, plain, all);
      for (std::size_t i = 0; i < copies; ++i) {
        EXPECT_TRUE(plain.is_hit(i));
        EXPECT_EQ(probed.t[i], plain.t[i]);
        EXPECT_EQ(probed.primitive[i], plain.primitive[i]);
      }
      std::uint64_t reads = 0;
      for (const std::uint64_t array_reads : tally.totals()) reads += array_reads;
      return reads;
    };
    const std::uint64_t once = count_reads(1);
    EXPECT_GT(once, 0u) << width;
    EXPECT_EQ(count_reads(64), 64 * once) << width;
  }
}

TEST(WideHmq, NoRayEscapesClosedMeshes) {
  for (const char* source : {"builtin:sphere:100k", "builtin:room:50k"}) {
    const Scene scene = make_builtin_scene(source);
    const LeakReport report = run_leak_bench(scene,
                                             {parse_accelerator_spec("hmq:width=8:bits=8", Config{}),
                                              parse_accelerator_spec("hmq:width=8", Config{}),
                                              parse_accelerator_spec("hmq:width=8:leaf_size=2", Config{})},
                                             100000, 0);
    ASSERT_EQ(report.results.size(), 3u);
    for (const LeakResult& result : report.results) EXPECT_EQ(result.escaped, 0u) << source << " " << result.label;
  }
}

TEST(WideHmq, FewerBytesThanBinaryHmqAndFullNodes) {
  const Scene scene = make_builtin_scene("builtin:room:100k");
  const auto binary = make_hmq_accelerator(scene.mesh, hmq_options(2, 8, 16));
  const auto wide = make_hmq_accelerator(scene.mesh, hmq_options(8, 8, 16));
  std::size_t span_bytes = 0;
  for (const auto& span : wide->memory_spans()) span_bytes += span.size();
  EXPECT_EQ(wide->memory().total(), span_bytes);
  EXPECT_LT(wide->memory().total(), binary->memory().total());
  // The surface-area cut fills nodes (greedy collapsing left 4.0 children a node on room:1M).
  const std::string notes = wide->build_notes();
  const auto at = notes.find("children each");
  ASSERT_NE(at, std::string::npos) << notes;
  const double children = std::stod(notes.substr(notes.rfind('(', at) + 1));
  EXPECT_GT(children, 5.5) << notes;
  EXPECT_LE(children, 8.0) << notes;
}

// Levels below the root of each node of a wide tree, by walking it from the root.
std::vector<std::uint32_t> node_levels(std::span<const QuantizedWideNode> nodes) {
  std::vector<std::uint32_t> level(nodes.size(), 0), pending = {0};
  while (!pending.empty()) {
    const std::uint32_t n = pending.back();
    pending.pop_back();
    for (int slot = 0, inner = 0; slot < QuantizedWideNode::kWidth; ++slot) {
      if (nodes[n].meta[slot] != QuantizedWideNode::kInnerMeta) continue;
      const std::uint32_t child = nodes[n].child_base + inner++;
      level[child] = level[n] + 1;
      pending.push_back(child);
    }
  }
  return level;
}

// The node order and the leaves' place change where bytes lie, never what a ray meets: the
// same hits bit for bit, saved and loaded too; apart, the same leaf bytes, breadth first lays
// levels in order and van Emde Boas the top half of the levels before anything below them;
// together, one array a few percent larger than the two.
TEST(WideHmq, NodeLayoutsMoveNodesAndChangeNoHit) {
  const Scene scene = make_builtin_scene("builtin:room:60k");
  HmqOptions options = hmq_options(8, 8, 16);
  EXPECT_EQ(options.layout, NodeLayout::van_emde_boas);  // the default
  options.layout = NodeLayout::depth_first;
  const auto depth_first = make_hmq_accelerator(scene.mesh, options);
  const RaySet rays = make_ray_set(RaySetKind::diffuse, scene, *depth_first, 20000);
  const auto expected = trace_ray_set(*depth_first, rays, false);
  const auto nodes_of = [](const Accelerator& accel) {
    const std::span<const std::byte> bytes = accel.memory_spans()[0];
    return std::span(reinterpret_cast<const QuantizedWideNode*>(bytes.data()), bytes.size() / sizeof(QuantizedWideNode));
  };
  const std::span<const QuantizedWideNode> reference = nodes_of(*depth_first);
  ASSERT_GT(reference.size(), 200u);
  const auto same_hits = [&](const Accelerator& moved, const std::string& label) {
    const auto hits = trace_ray_set(moved, rays, false);
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(hits[b]->t[i], expected[b]->t[i]) << label;
        ASSERT_EQ(hits[b]->primitive[i], expected[b]->primitive[i]) << label;
        ASSERT_EQ(hits[b]->u[i], expected[b]->u[i]) << label;
        ASSERT_EQ(hits[b]->v[i], expected[b]->v[i]) << label;
      }
    }
  };
  for (const NodeLayout layout : {NodeLayout::depth_first, NodeLayout::van_emde_boas}) {
    options.layout = layout;
    options.leaves_beside_nodes = true;
    const auto together = make_hmq_accelerator(scene.mesh, options);
    const std::string label = to_string(layout) + " together";
    ASSERT_EQ(together->memory_spans().size(), 1u) << label;
    EXPECT_EQ(together->memory().total(), together->memory_spans()[0].size()) << label;
    EXPECT_GT(together->memory().total(), depth_first->memory().total()) << label;
    EXPECT_LT(together->memory().total(), depth_first->memory().total() * 1.05) << label;
    const auto counts = [](const std::string& notes) { return notes.substr(0, notes.find("; bytes/tri")); };
    EXPECT_EQ(counts(together->build_notes()), counts(depth_first->build_notes())) << label;
    same_hits(*together, label);
    const std::string path = testing::write_temp_file("wide_hmq_together.wtw", "");
    {
      SectionWriter out(path);
      together->save(out, "world/");
      out.finish();
    }
    SectionLoader in(SectionFile::open(path), "world/");
    const auto loaded = load_accelerator(in);
    EXPECT_EQ(loaded->memory().total(), together->memory().total()) << label;
    EXPECT_EQ(loaded->build_notes(), together->build_notes()) << label;
    same_hits(*loaded, label + " loaded");
  }
  options.leaves_beside_nodes = false;
  for (const NodeLayout layout : {NodeLayout::breadth_first, NodeLayout::van_emde_boas}) {
    options.layout = layout;
    const auto moved = make_hmq_accelerator(scene.mesh, options);
    const std::span<const QuantizedWideNode> nodes = nodes_of(*moved);
    ASSERT_EQ(nodes.size(), reference.size());
    EXPECT_NE(std::memcmp(nodes.data(), reference.data(), nodes.size_bytes()), 0) << to_string(layout);
    const auto leaves = moved->memory_spans()[1], reference_leaves = depth_first->memory_spans()[1];
    ASSERT_EQ(leaves.size(), reference_leaves.size());
    EXPECT_EQ(std::memcmp(leaves.data(), reference_leaves.data(), leaves.size()), 0) << to_string(layout);
    same_hits(*moved, to_string(layout));
    const std::vector<std::uint32_t> level = node_levels(nodes);
    const std::uint32_t height = *std::max_element(level.begin(), level.end()) + 1;
    ASSERT_GE(height, 4u);
    if (layout == NodeLayout::breadth_first) {
      EXPECT_TRUE(std::is_sorted(level.begin(), level.end()));
    } else {
      const std::uint32_t top = height / 2;
      const auto top_nodes = std::size_t(std::count_if(level.begin(), level.end(), [&](std::uint32_t l) { return l < top; }));
      for (std::size_t n = 0; n < nodes.size(); ++n) EXPECT_EQ(level[n] < top, n < top_nodes) << n;
    }
  }
}

TEST(WideHmq, DecodedChildOfAFullStepIsTheFrame) {
  QuantizedWideNode node{};
  Bounds3 frame;
  frame.lower = {-1.0f, 2.0f, 0.0f};
  frame.upper = {3.0f, 2.0f, 1e-3f};  // one flat axis
  node.upper(0)[3] = 255;
  node.lower(2)[3] = 255;
  const Bounds3 child = decode_wide_child(node, 3, frame);
  EXPECT_EQ(child.lower.x, -1.0f);
  EXPECT_NEAR(child.upper.x, -1.0f, 1e-6f);
  EXPECT_EQ(child.lower.y, 2.0f);
  EXPECT_EQ(child.upper.y, 2.0f);
  EXPECT_NEAR(child.lower.z, 1e-3f, 1e-9f);
  EXPECT_EQ(child.upper.z, 1e-3f);
}

// Leaves of 14 for width 8 unless asked otherwise (the binary layout keeps the paper's 8): the
// same surface in a sixth fewer bytes. A triangle may sit in another strip with its corners in
// another order, so a distance may differ in its last bits.
TEST(WideHmq, LeavesOfFourteenByDefault) {
  HmqOptions options;
  EXPECT_EQ(options.leaf_triangles(), 8u);
  options.width = 8;
  EXPECT_EQ(options.leaf_triangles(), 14u);
  options.leaf_size = 6;
  EXPECT_EQ(options.leaf_triangles(), 6u);

  const Scene scene = make_builtin_scene("builtin:sphere:30k");
  const AcceleratorSpec spec = parse_accelerator_spec("hmq:width=8", Config{});
  const AcceleratorSpec eight = parse_accelerator_spec("hmq:width=8:leaf_size=8", Config{});
  const auto by_default = make_hmq_accelerator(scene.mesh, spec.options.hmq);
  const auto of_eight = make_hmq_accelerator(scene.mesh, eight.options.hmq);
  EXPECT_LT(by_default->memory().total(), of_eight->memory().total());
  const RaySet rays = make_ray_set(RaySetKind::diffuse, scene, *of_eight, 5000);
  const auto a = trace_ray_set(*by_default, rays, false);
  const auto b = trace_ray_set(*of_eight, rays, false);
  std::size_t same_triangle = 0, total = 0;
  for (std::size_t k = 0; k < rays.batches.size(); ++k) {
    for (std::size_t i = 0; i < rays.batches[k]->count; ++i, ++total) {
      ASSERT_EQ(a[k]->is_hit(i), b[k]->is_hit(i));
      if (a[k]->is_hit(i)) ASSERT_NEAR(a[k]->t[i], b[k]->t[i], 1e-5f * b[k]->t[i]);
      same_triangle += a[k]->primitive[i] == b[k]->primitive[i];
    }
  }
  EXPECT_GE(double(same_triangle), 0.999 * double(total));
}

TEST(WideHmq, BadWidthIsAClearError) {
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  EXPECT_THROW(make_hmq_accelerator(scene.mesh, hmq_options(4, 8, 16)), std::invalid_argument);
  Config config;
  config.set("accel.hmq.width=4");
  EXPECT_THROW(accelerator_options(config), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("hmq:width=16", Config{}), ConfigError);
  // A float top share for the layout that has none is refused, not ignored.
  EXPECT_THROW(parse_accelerator_spec("hmq:width=8:top_fraction=0.1", Config{}), ConfigError);
  EXPECT_NO_THROW(parse_accelerator_spec("hmq:width=8:leaf_size=12", Config{}));
  // So is a node order for the binary layout, whose nodes sit in blocks.
  EXPECT_THROW(parse_accelerator_spec("hmq:layout=veb", Config{}), ConfigError);
  EXPECT_THROW(parse_accelerator_spec("hmq:width=8:layout=spiral", Config{}), ConfigError);
  EXPECT_EQ(parse_accelerator_spec("hmq:width=8:layout=veb", Config{}).options.hmq.layout, NodeLayout::van_emde_boas);
  EXPECT_THROW(parse_accelerator_spec("hmq:leaves_beside_nodes=true", Config{}), ConfigError);
  EXPECT_TRUE(parse_accelerator_spec("hmq:width=8:leaves_beside_nodes=true", Config{}).options.hmq.leaves_beside_nodes);
}

}  // namespace
}  // namespace wavetrace
