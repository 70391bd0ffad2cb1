// The chunked world: chunks cut at object borders, and a world of chunks that answers as
// the monolithic build does (against robust Embree), keeps HMQ's grid global, and reads
// only its own memory when probed.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <sstream>
#include <thread>

#include <tbb/task_arena.h>

#include <limits>

#include "wavetrace/accel/chunked/chunked_accelerator.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/memory/simulated_pager.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/plan_render.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_setup.hpp"
#include "wavetrace/pipeline/tracing_arena.hpp"
#include "accel_agreement.hpp"
#include "accel_options.hpp"

namespace wavetrace {
namespace {

TEST(PlanChunks, ObjectsSplitEvenlyAndNeverShareAChunk) {
  const std::vector<std::size_t> starts = {0, 10, 12, 40, 140};
  const std::vector<ChunkRange> chunks = plan_chunks(starts, 150, 30);
  // [0,10), [10,12) and [12,40) whole; [40,140) in 4 runs of 25; [140,150) whole.
  const std::vector<std::pair<std::size_t, std::size_t>> expected = {{0, 10}, {10, 2}, {12, 28}, {40, 25}, {65, 25},
                                                                     {90, 25}, {115, 25}, {140, 10}};
  ASSERT_EQ(chunks.size(), expected.size());
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    EXPECT_EQ(chunks[c].first, expected[c].first) << c;
    EXPECT_EQ(chunks[c].count, expected[c].second) << c;
  }
  std::size_t covered = 0;
  for (const ChunkRange& chunk : plan_chunks(std::vector<std::size_t>{0}, 1000003, 1024)) {
    EXPECT_EQ(chunk.first, covered);
    EXPECT_LE(chunk.count, 1024u);
    covered += chunk.count;
  }
  EXPECT_EQ(covered, 1000003u);
}

// `type` is an accelerator name, optionally followed by settings: "hmq accel.hmq.width=8".
AcceleratorOptions options_for(const std::string& type, std::size_t chunk_triangles) {
  return testing::options_for(type + " build.chunk_triangles=" + std::to_string(chunk_triangles));
}

class ChunkedWorld : public ::testing::TestWithParam<std::string> {};

TEST_P(ChunkedWorld, AnswersAsTheMonolithicBuildDoes) {
  const Scene scene = make_builtin_scene("builtin:room:100k");
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(scene.mesh, robust);
  const auto whole = build_world_accelerator(scene, options_for(GetParam(), std::size_t{1} << 24));
  const auto chunked = build_world_accelerator(scene, options_for(GetParam(), 8192));
  EXPECT_NE(chunked->build_notes().find("chunks of up to"), std::string::npos) << chunked->build_notes();
  EXPECT_EQ(whole->build_notes().find("chunks of up to"), std::string::npos);
  // Bytes: the same structures cut smaller, plus a top BVH.
  const double ratio = double(chunked->memory().total()) / double(whole->memory().total());
  EXPECT_NEAR(ratio, 1.0, 0.05) << "chunked " << chunked->memory().total() << " whole " << whole->memory().total();
  const float diagonal = scene.bounds.diagonal();
  // hmq answers for the surface it represents; bvh and raystrips for the mesh.
  const TriangleMesh represented = whole->represented_mesh(scene.mesh).value_or(scene.mesh);
  Scene represented_scene = scene;
  represented_scene.mesh = represented;
  const auto represented_reference = make_accelerator(represented, robust);
  for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::diffuse, RaySetKind::shadow, RaySetKind::random}) {
    for (const bool packets : {false, true}) {
      if (packets && kind != RaySetKind::primary) continue;
      const std::string label = to_string(kind) + (packets ? " packets" : "");
      for (const Accelerator* tested : {whole.get(), chunked.get()}) {
        const testing::Agreement result = testing::compare_on_rays(represented_scene, *represented_reference, *tested,
                                                                   kind, 20000, 1e-5f * diagonal, 1e-3f, packets);
        EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays)) << label;
        EXPECT_LE(double(result.far_t), 1e-4 * double(result.rays)) << label;
        if (kind != RaySetKind::shadow) {
          EXPECT_GT(result.same_primitive, result.rays * 9 / 10) << label;
        }
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Types, ChunkedWorld,
                         ::testing::Values("hmq", "raystrips", "bvh", "hmq accel.hmq.width=8",
                                           "raystrips accel.raystrips.width=8"),
                         [](const ::testing::TestParamInfo<std::string>& info) {
                           std::string name = info.param.substr(0, info.param.find(' '));
                           return info.param.find("width=8") != std::string::npos ? name + "_wide" : name;
                         });

TEST(ChunkedWorld, HmqChunksShareOneGlobalGrid) {
  // Every chunk snaps to the scene's grid: a vertex on a chunk border decodes alike in both
  // chunks, so the represented surface is the monolithic build's, vertex for vertex.
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  const auto whole = build_world_accelerator(scene, options_for("hmq", std::size_t{1} << 24));
  const auto chunked = build_world_accelerator(scene, options_for("hmq", 4096));
  EXPECT_EQ(chunked->represented_mesh(scene.mesh)->positions, whole->represented_mesh(scene.mesh)->positions);
}

// Unprobed, a world of up to a thousand chunks lists a ray's chunks by testing their boxes in
// lanes (more than 16 chunks: each block of 16's box first); probed, by walking the top BVH
// (whose nodes the probe reads): the hits must agree.
TEST(ChunkedWorld, ProbedAnswersAsUnprobedAndReadsOnlyItsWorld) {
  const Scene scene = make_builtin_scene("builtin:room:50k");
  for (const std::size_t chunk_triangles : {4096, 1024}) {
    const auto chunked = build_world_accelerator(scene, options_for("hmq", chunk_triangles));
    ASSERT_TRUE(chunked->probed());
    const std::size_t chunk_count = std::stoul(chunked->build_notes());
    EXPECT_GT(chunk_count, chunk_triangles == 1024 ? 32u : 8u);  // one block of lanes, and several
    EXPECT_LE(chunk_count, 1024u);
    const RaySet rays = make_ray_set(RaySetKind::diffuse, scene, *chunked, 4000);
    const auto plain = trace_ray_set(*chunked, rays);
    SimulatedPager pager(chunked->memory_spans(), 16384, MemoryBudget{}, io_preset("nvme"));
    TracingArena arena(1);
    std::vector<std::unique_ptr<HitBatch>> probed;
    arena.execute([&] { probed = trace_ray_set_probed(*chunked, rays, MemoryObservers{&pager, nullptr}); });
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        ASSERT_EQ(plain[b]->primitive[i], probed[b]->primitive[i]) << chunk_triangles;
        ASSERT_EQ(plain[b]->t[i], probed[b]->t[i]) << chunk_triangles;
      }
    }
    EXPECT_GT(pager.counters(0).accesses, 4000u);
    EXPECT_EQ(pager.outside_accesses(), 0u);
  }
}

// A scene kept whole (as it is when a proxy is wanted) is cut where the same scene streamed
// is: its objects' starts survive the assembly and the dropping of degenerate triangles.
TEST(ChunkedWorld, AWholeSceneIsCutWhereItsStreamIs) {
  const Scene whole = make_builtin_scene("builtin:room:20000", false);
  const Scene streamed = make_builtin_scene("builtin:room:20000", true);
  ASSERT_TRUE(streamed.streamed());
  EXPECT_GT(whole.object_starts.size(), 5u);
  EXPECT_EQ(whole.object_starts, streamed.stream->object_starts());
  const std::vector<ChunkRange> from_whole =
      plan_chunks(MeshTriangleSource(whole.mesh, whole.object_starts).object_starts(), whole.triangle_count, 2048);
  const std::vector<ChunkRange> from_stream =
      plan_chunks(streamed.stream->object_starts(), streamed.triangle_count, 2048);
  ASSERT_EQ(from_whole.size(), from_stream.size());
  for (std::size_t c = 0; c < from_whole.size(); ++c) {
    EXPECT_EQ(from_whole[c].first, from_stream[c].first) << c;
    EXPECT_EQ(from_whole[c].count, from_stream[c].count) << c;
  }

  TriangleMesh mesh;
  mesh.positions = {glm::vec3(0, 0, 0), glm::vec3(1, 0, 0), glm::vec3(0, 1, 0), glm::vec3(0, 0, 1)};
  // Triangles 1 and 4 are degenerate (a repeated corner); objects start at 0, 2 and 4.
  mesh.triangles = {{0, 1, 2}, {0, 0, 1}, {0, 1, 3}, {0, 2, 3}, {1, 1, 2}, {1, 2, 3}};
  std::vector<std::size_t> starts = {0, 2, 4};
  validate_and_clean(mesh, "test mesh", &starts);
  EXPECT_EQ(mesh.triangles.size(), 4u);
  EXPECT_EQ(starts, (std::vector<std::size_t>{0, 1, 3}));
}

// A chunked build's chunks keep copies of their meshes, so a type that reads its mesh in place
// (bvh) streams its scene when it will be chunked, and keeps it whole when it will not; the
// structure traces the same either way.
TEST(ChunkedWorld, ABvhBuiltInChunksStreamsItsScene) {
  const auto loaded = [](std::int64_t chunk_triangles) {
    Config config;
    config.set("scene.source=builtin:room:20000");
    config.set("accel.type=bvh");
    config.set("accel.bvh.width=8");
    config.set("build.chunk_triangles=" + std::to_string(chunk_triangles));
    const RenderPlan plan = plan_render(config);
    SceneForWorld world = load_scene_for_world(plan, /*keep_mesh=*/false);
    auto accelerator = build_world_accelerator(world.scene, world.accelerator.options);
    return std::make_pair(std::move(world), std::move(accelerator));
  };
  const auto [chunked_world, chunked] = loaded(4096);
  const auto [whole_world, whole] = loaded(1 << 20);
  EXPECT_TRUE(chunked_world.scene.streamed());
  EXPECT_FALSE(whole_world.scene.streamed());
  const RaySet rays = make_ray_set(RaySetKind::diffuse, whole_world.scene, *whole, 4000);
  const auto from_whole = trace_ray_set(*whole, rays);
  const auto from_chunks = trace_ray_set(*chunked, rays);
  std::size_t hits = 0;
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
      ASSERT_EQ(from_whole[b]->primitive[i], from_chunks[b]->primitive[i]);
      hits += from_whole[b]->is_hit(i);
    }
  }
  EXPECT_GT(hits, 1000u);

  // A mesh file's name says nothing of its size, however short or with a colon in it: the
  // file's own error, not one about a builtin's count.
  for (const char* missing : {"x.ply", "no:such:mesh.ply"}) {
    Config config;
    config.set(std::string("scene.source=") + missing);
    config.set("accel.type=bvh");
    const RenderPlan plan = plan_render(config);
    try {
      load_scene_for_world(plan, /*keep_mesh=*/false);
      ADD_FAILURE() << missing << " loaded";
    } catch (const SceneError& error) {
      EXPECT_NE(std::string(error.what()).find(missing), std::string::npos) << error.what();
    }
  }
}

// build.chunks_at_once caps the chunks in flight: each build lingers so that two threads
// would overlap, and the most seen at once must stay within the cap.
TEST(ChunkedWorld, ChunksAtOnceCapsTheBuildsInFlight) {
  const Scene scene = make_builtin_scene("builtin:sphere:20000");
  const MeshTriangleSource source(scene.mesh);
  for (const std::size_t cap : {std::size_t{1}, std::size_t{2}}) {
    std::atomic<int> in_flight{0}, most{0};
    const auto build = [&](const TriangleMesh& mesh) {
      const int now = ++in_flight;
      for (int seen = most.load(); now > seen && !most.compare_exchange_weak(seen, now);) {
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      auto accelerator = make_accelerator(mesh, AcceleratorOptions{});
      --in_flight;
      return accelerator;
    };
    tbb::task_arena arena(4);
    arena.execute([&] { make_chunked_accelerator(source, 2048, build, false, nullptr, cap); });
    EXPECT_EQ(std::size_t(most.load()), cap) << "at most " << cap << " chunks at once, and that many when allowed";
  }
  Config config;
  EXPECT_THROW(config.set("build.chunks_at_once=-1"), ConfigError);
  config.set("build.chunks_at_once=1");
}

// A source that claims more triangles than hits can name, without holding any.
class HugeSource final : public TriangleSource {
 public:
  std::size_t triangle_count() const override { return std::size_t{5} << 30; }
  Bounds3 bounds() const override { return {glm::vec3(0.0f), glm::vec3(1.0f)}; }
  std::vector<std::size_t> object_starts() const override { return {0}; }
  TriangleMesh extract(std::size_t, std::size_t) const override { throw std::logic_error("must not be reached"); }
};

TEST(ChunkedWorld, LimitsAreClearErrors) {
  const auto build = [](const TriangleMesh& mesh) { return make_accelerator(mesh, AcceleratorOptions{}); };
  try {
    make_chunked_accelerator(HugeSource{}, 1 << 24, build, false);
    FAIL() << "5G triangles cannot be named by 32-bit hit ids";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("32-bit ids"), std::string::npos) << error.what();
  }
  const Scene scene = make_builtin_scene("builtin:sphere:2000");
  const MeshTriangleSource source(scene.mesh);
  EXPECT_THROW(make_chunked_accelerator(source, 100, build, false), std::invalid_argument);
  Config config;
  try {
    config.set("build.chunk_triangles=12");
    FAIL() << "a chunk of 12 triangles is out of range";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("build.chunk_triangles"), std::string::npos) << error.what();
  }
}

}  // namespace
}  // namespace wavetrace
