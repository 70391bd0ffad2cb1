// Saved worlds: the section container's checks, images from a world file bit-identical to a
// fresh build for every accelerator (Embree and the grids rebuilt from saved geometry), real
// paging that changes no pixel, copies on huge pages, and the build, render and info commands.
// Damaged and crafted files: damaged_world_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <random>

#include <fmt/format.h>
#include <xxhash.h>
#include <nlohmann/json.hpp>

#include "wavetrace/accel/registry.hpp"
#include "wavetrace/accel/hmq/global_grid.hpp"
#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/section_archive.hpp"
#include "wavetrace/memory/section_file.hpp"
#include "wavetrace/memory/section_writer.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/scene/lights.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/setup/world_file.hpp"
#include "test_support.hpp"
#include "world_file_support.hpp"

namespace wavetrace {
namespace {

using namespace world_testing;  // and its fs, Header and TableEntry

// A writer works in an unnamed file and renames at finish(): a failed save leaves no file and
// keeps the world that was there, and a process with that world mapped keeps reading it
// while it is replaced.
TEST(SectionFile, AWriterReplacesTheFileOnlyWhenItFinishes) {
  const std::string path = temp_path("replaced.bin");
  const auto others_beside = [&] {
    std::size_t count = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(path).parent_path())) {
      count += entry.path().filename().string().starts_with("replaced.bin.");
    }
    return count;
  };
  const auto write = [&](std::uint64_t value, bool finish) {
    SectionWriter out(path);
    EXPECT_TRUE(out.unnamed());  // the test directory's file system has O_TMPFILE
    out.add_value("a/value", value);
    EXPECT_EQ(others_beside(), 0u);
    if (finish) out.finish();
  };
  write(1, true);
  const auto mapped = SectionFile::open(path);
  write(2, false);
  EXPECT_EQ(others_beside(), 0u);
  EXPECT_EQ(SectionFile::open(path)->value<std::uint64_t>("a/value"), 1u);
  write(3, true);
  EXPECT_EQ(others_beside(), 0u);
  EXPECT_EQ(SectionFile::open(path)->value<std::uint64_t>("a/value"), 3u);
  EXPECT_EQ(mapped->value<std::uint64_t>("a/value"), 1u);
  // A directory in the way is an error at once, not at the end of a build.
  EXPECT_THROW(SectionWriter(fs::path(path).parent_path().string()), std::runtime_error);
}

TEST(SectionFile, ArraysComeBackInPlaceAndChecked) {
  const std::string path = temp_path("sections.bin");
  const std::vector<std::uint32_t> numbers = {1, 2, 3, 5, 8, 13};
  const std::vector<double> reals = {0.5, -2.25};
  {
    SectionWriter out(path);
    out.add_array("b/numbers", std::span<const std::uint32_t>(numbers));
    out.add_array("a/reals", std::span<const double>(reals));
    out.add_value("c/one", std::uint64_t{42});
    out.finish();
  }
  EXPECT_EQ(fs::file_size(path) % 4096, 0u);
  const auto file = SectionFile::open(path);
  const std::span<const std::uint32_t> back = file->array<std::uint32_t>("b/numbers");
  EXPECT_EQ(std::vector<std::uint32_t>(back.begin(), back.end()), numbers);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(back.data()) % 4096, 0u);  // aligned for use in place
  EXPECT_EQ(file->value<std::uint64_t>("c/one"), 42u);
  EXPECT_THROW(file->array<std::uint64_t>("b/numbers"), SectionFileError);  // 4-byte elements
  EXPECT_THROW(file->value<double>("a/reals"), SectionFileError);          // two values, not one
  try {
    file->bytes("d/missing");
    FAIL();
  } catch (const SectionFileError& error) {
    EXPECT_NE(std::string(error.what()).find(path), std::string::npos);
    EXPECT_NE(std::string(error.what()).find("'d/missing' is missing"), std::string::npos);
  }
}


class WorldRoundTrip : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(WorldRoundTrip, ImageIsBitIdenticalToTheFreshBuild) {
  const std::string path = temp_path("roundtrip.wtw");
  const std::vector<float> fresh = build_and_save(GetParam(), path);
  const std::vector<float> loaded = render_loaded(GetParam(), path);
  ASSERT_EQ(loaded.size(), fresh.size());
  EXPECT_TRUE(loaded == fresh);
  const std::unique_ptr<LoadedWorld> held = load_world(path);
  const LoadedWorld& world = *held;
  EXPECT_EQ(world.scene.triangle_count, room().triangle_count);
  EXPECT_EQ(world.rebuilt, !saves_structure(world.type)) << world.type;
  EXPECT_GT(world.accelerator->memory().total(), 0u);
  fs::remove(path);
}

INSTANTIATE_TEST_SUITE_P(
    EveryAccelerator, WorldRoundTrip,
    ::testing::Values(std::vector<std::string>{"accel.type=hmq"}, std::vector<std::string>{"accel.type=raystrips"},
                      std::vector<std::string>{"accel.type=bvh"},
                      std::vector<std::string>{"accel.type=bvh", "accel.bvh.width=8", "accel.bvh.triangle_order=leaf"},
                      std::vector<std::string>{"accel.type=bvh", "accel.bvh.triangle_order=morton"},
                      std::vector<std::string>{"accel.type=embree"}, std::vector<std::string>{"accel.type=grid"},
                      std::vector<std::string>{"accel.type=mlgrid"}, std::vector<std::string>{"accel.type=arraygrid"},
                      std::vector<std::string>{"accel.type=hmq", "build.chunk_triangles=4096"},
                      std::vector<std::string>{"accel.type=raystrips", "build.chunk_triangles=4096"},
                      std::vector<std::string>{"accel.type=bvh", "build.chunk_triangles=4096"}));

// Reads happen outside the pool's lock, several at once: any number of threads gets the same
// image, and every thread that waited for a page is counted.
TEST(WorldFile, RealPagingChangesNoPixelAndCountsItsReadsOnTwoAndEightThreads) {
  const std::string path = temp_path("paged.wtw");
  const std::vector<std::string> build = {"accel.type=hmq", "build.chunk_triangles=4096"};
  const std::vector<float> fresh = build_and_save(build, path);
  for (const char* threads : {"render.threads=2", "render.threads=8"}) {
  std::vector<std::string> paged = build;
  for (const char* s : {"memory.backing=file", "memory.budget=5%", "memory.page_bytes=4096", threads,
                        "memory.simulate_beside_file=true"}) {
    paged.emplace_back(s);
  }
  const Config config = small_render(paged);
  const RenderPlan plan = plan_render(config);
  const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
  const LoadedWorld& loaded = *world;
  ASSERT_NE(loaded.file->pager(), nullptr);
  EXPECT_LT(loaded.file->pager()->budget_bytes(), loaded.file->file_bytes() / 10);
  const RenderOutput output = render_image(plan, World{loaded.scene, *loaded.accelerator, *loaded.lights, nullptr,
                                                       loaded.file->pager()},
                                           resolve_camera(plan.camera, loaded.scene));
  EXPECT_TRUE(output.image == fresh);
  bool counted = false;
  for (const StageStats& stage : output.run.stages) {
    if (stage.name != "trace") continue;
    ASSERT_TRUE(stage.disk.has_value());
    ASSERT_TRUE(stage.pager.has_value());
    EXPECT_GT(stage.disk->counters.faults, 0u);
    EXPECT_EQ(stage.disk->counters.bytes_read, stage.disk->counters.faults * 4096);
    EXPECT_GT(stage.disk->counters.read_seconds, 0.0);
    EXPECT_GE(stage.disk->counters.wait_seconds, stage.disk->counters.read_seconds * 0.5) << threads;
    EXPECT_GE(stage.disk->reads_in_flight_max, 1u);
    // The simulated pager, asked to run beside, saw the same reads: the real faults are near
    // its count. Not equal: the real pool evicts in groups and keeps LRU order loosely. On
    // this tiny pool of 4 KiB pages the real pager read 0.89-0.92 of the simulated count in 20
    // runs on an idle machine, and 0.77 with other tests running beside (threads descheduled
    // in turn interleave their rays' reads less, which the looser order rewards more).
    const double simulated = double(stage.pager->counters.faults);
    EXPECT_GE(double(stage.disk->counters.faults), 0.6 * simulated) << threads;
    EXPECT_LE(double(stage.disk->counters.faults), 1.25 * simulated) << threads;
    counted = true;
  }
  EXPECT_TRUE(counted) << threads;
  }
  fs::remove(path);
}

// The megakernel pages a world file as the wavefront does: one path at a time, the same image.
TEST(WorldFile, OnePathAtATimePagesTheFileToo) {
  const std::string path = temp_path("paged_paths.wtw");
  const std::vector<std::string> build = {"accel.type=hmq", "accel.hmq.width=8", "build.chunk_triangles=4096"};
  const std::vector<float> fresh = build_and_save(build, path);
  std::vector<std::string> paged = build;
  for (const char* s : {"memory.backing=file", "memory.budget=5%", "memory.page_bytes=4096", "render.threads=2",
                        "pipeline.mode=megakernel"}) {
    paged.emplace_back(s);
  }
  const RenderPlan plan = plan_render(small_render(paged));
  const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
  const LoadedWorld& loaded = *world;
  ASSERT_NE(loaded.file->pager(), nullptr);
  const RenderOutput output = render_image(plan, World{loaded.scene, *loaded.accelerator, *loaded.lights, nullptr,
                                                       loaded.file->pager()},
                                           resolve_camera(plan.camera, loaded.scene));
  EXPECT_TRUE(output.image == fresh);
  ASSERT_EQ(output.run.stages.size(), 2u);
  const StageStats& walks = output.run.stages[1];
  EXPECT_EQ(walks.name, "trace");
  ASSERT_TRUE(walks.disk.has_value());
  EXPECT_GT(walks.disk->counters.faults, 0u);
  EXPECT_EQ(walks.disk->counters.bytes_read, walks.disk->counters.faults * 4096);
  // Windows of a worker's 1,000 consecutive rays count the distinct pages they touched.
  EXPECT_GT(walks.disk->ray_windows.windows, 0u);
  EXPECT_GT(walks.disk->pages_per_window(), 1.0);
  fs::remove(path);
}

// A paged walk announces what it reads, so that pages come in by the probe's touch, not by a
// fault in the read: only a leaf record that ends on the next page is read there before the
// probe hears of its end. With pages larger than the OS's, this needs the pager's pages
// where the probes count them (the file's range on a page boundary): numbered apart, 8-18%
// of the reads faulted.
TEST(WorldFile, APagedWalkAnnouncesItsReads) {
  const std::string path = temp_path("announced.wtw");
  std::vector<std::string> build = {"accel.type=hmq", "accel.hmq.width=8", "accel.hmq.leaves_beside_nodes=true",
                                    "render.width=96", "render.height=72", "render.max_depth=3"};
  const std::vector<float> fresh = build_and_save(build, path);
  for (const char* page_bytes : {"memory.page_bytes=16384", "memory.page_bytes=65536"}) {
    std::vector<std::string> paged = build;
    // One thread: with more, a page may be evicted by another between its announcement and
    // the read, which faults too (in a pool of two pages, often).
    for (const char* s : {"memory.backing=file", "memory.budget=60%", "render.threads=1", page_bytes}) {
      paged.emplace_back(s);
    }
    const RenderPlan plan = plan_render(small_render(paged));
    const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
    ASSERT_NE(world->file->pager(), nullptr);
    const RenderOutput output = render_image(
        plan, World{world->scene, *world->accelerator, *world->lights, nullptr, world->file->pager()},
        resolve_camera(plan.camera, world->scene));
    EXPECT_TRUE(output.image == fresh) << page_bytes;
    const auto trace = std::find_if(output.run.stages.begin(), output.run.stages.end(),
                                    [](const StageStats& stage) { return stage.name == "trace"; });
    ASSERT_NE(trace, output.run.stages.end());
    ASSERT_TRUE(trace->disk.has_value());
    const DiskCounters& reads = trace->disk->counters;
    EXPECT_GT(reads.faults, 20u) << page_bytes;
    EXPECT_LE(double(reads.unannounced), 0.03 * double(reads.faults)) << page_bytes << ": " << reads.unannounced
                                                                       << " of " << reads.faults << " reads faulted";
  }
  fs::remove(path);
}

// Photon mapping paged from a world file: the same image as in core, and the photon pass's
// reads reported apart, a part of the whole render's that the camera pass's trace reports.
TEST(WorldFile, PagedPhotonMappingReportsThePhotonPassReadsApart) {
  const std::string path = temp_path("photons_paged.wtw");
  std::vector<std::string> settings = {"accel.type=hmq", "build.chunk_triangles=4096", "render.integrator=photon",
                                       "photon.count=20000", "photon.gather_rays=2", "render.max_depth=3"};
  const std::vector<float> in_core = build_and_save(settings, path);
  for (const char* s : {"memory.backing=file", "memory.budget=5%", "memory.page_bytes=4096"}) settings.emplace_back(s);
  const RenderPlan plan = plan_render(small_render(settings));
  const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
  const RenderOutput output = render_image(
      plan, World{world->scene, *world->accelerator, *world->lights, nullptr, world->file->pager()},
      resolve_camera(plan.camera, world->scene));
  EXPECT_TRUE(output.image == in_core);
  ASSERT_TRUE(output.photons.has_value());
  ASSERT_TRUE(output.photons->disk.has_value());
  const DiskCounters& photon_pass = *output.photons->disk;
  EXPECT_GT(photon_pass.faults, 0u);
  EXPECT_EQ(photon_pass.bytes_read, photon_pass.faults * 4096);
  std::uint64_t whole_render = 0;
  for (const StageStats& stage : output.run.stages) {
    if (stage.name == "trace") whole_render = stage.disk->counters.faults;
  }
  EXPECT_GT(whole_render, photon_pass.faults);  // the camera pass read pages too
  fs::remove(path);
}

// memory.page_trace: a paged render writes the pages its probes touched, each a page of the
// file, at least one per read from disk that a probe announced.
TEST(WorldFile, APagedRenderWritesItsPageTrace) {
  const std::string path = temp_path("traced.wtw");
  const std::string trace_path = temp_path("traced.pages");
  const std::vector<std::string> build = {"accel.type=hmq", "build.chunk_triangles=4096"};
  build_and_save(build, path);
  std::vector<std::string> paged = build;
  for (const char* s : {"memory.backing=file", "memory.budget=5%", "memory.page_bytes=4096", "render.threads=2"}) {
    paged.emplace_back(s);
  }
  paged.push_back("memory.page_trace=" + trace_path);
  const RenderPlan plan = plan_render(small_render(paged));
  const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
  const RenderOutput output = render_image(
      plan, World{world->scene, *world->accelerator, *world->lights, nullptr, world->file->pager()},
      resolve_camera(plan.camera, world->scene));
  const std::uint64_t pages = world->file->pager()->page_count();
  std::uint64_t faults = 0;
  for (const StageStats& stage : output.run.stages) {
    if (stage.name == "trace") faults = stage.disk->counters.faults;
  }
  std::ifstream in(trace_path, std::ios::binary);
  std::vector<std::uint32_t> touches;
  for (std::uint32_t page; in.read(reinterpret_cast<char*>(&page), sizeof page);) touches.push_back(page);
  EXPECT_GT(faults, 0u);
  EXPECT_GE(touches.size(), faults / 2) << "faults " << faults;  // most reads are announced
  for (const std::uint32_t page : touches) ASSERT_LT(page, pages);
  // Without real paging there is nothing to trace: an error naming the keys.
  try {
    plan_render(small_render({"memory.budget=5%", "memory.page_trace=" + trace_path}));
    FAIL() << "memory.page_trace without memory.backing = file";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("set memory.backing = file"), std::string::npos) << error.what();
  }
  fs::remove(path);
  fs::remove(trace_path);
}

// Trace's look-ahead reads the pages of the sorted batches queued for it before trace gets
// there: the same image with it and without, with one reader ahead and three, on 2 and 8
// threads; its reads are counted as trace's, and a good share of them are used by trace
// before they are evicted.
TEST(WorldFile, TracesLookAheadReadsPagesAheadAndChangesNoPixel) {
  const std::string path = temp_path("look_ahead.wtw");
  const std::vector<std::string> build = {"accel.type=hmq", "accel.hmq.width=8", "build.chunk_triangles=4096",
                                          "reorder.heuristic=hph", "render.width=64", "render.height=48",
                                          "render.spp=2"};
  const std::vector<float> fresh = build_and_save(build, path, true);
  for (const char* look_ahead : {"memory.look_ahead=0", "memory.look_ahead=2", "memory.look_ahead=3"}) {
    for (const char* threads : {"render.threads=2", "render.threads=8"}) {
      std::vector<std::string> paged = build;
      for (const char* s : {"memory.backing=file", "memory.budget=20%", "memory.page_bytes=4096", look_ahead, threads}) {
        paged.emplace_back(s);
      }
      if (std::string(look_ahead).ends_with("3")) paged.emplace_back("memory.look_ahead_threads=3");
      const RenderPlan plan = plan_render(small_render(paged));
      const std::unique_ptr<LoadedWorld> world = load_world(path, world_paging(plan), 2);
      const LoadedWorld& loaded = *world;
      const RenderOutput output = render_image(plan, World{loaded.scene, *loaded.accelerator, *loaded.lights,
                                                           loaded.proxy.get(), loaded.file->pager()},
                                               resolve_camera(plan.camera, loaded.scene));
      EXPECT_TRUE(output.image == fresh) << look_ahead << ", " << threads;
      const auto trace = std::find_if(output.run.stages.begin(), output.run.stages.end(),
                                      [](const StageStats& stage) { return stage.name == "trace"; });
      ASSERT_NE(trace, output.run.stages.end());
      ASSERT_TRUE(trace->disk.has_value());
      const DiskStats& disk = *trace->disk;
      std::uint64_t by_part = 0;
      for (const auto& [part, faults] : disk.faults_by_part) by_part += faults;
      EXPECT_EQ(by_part, disk.counters.faults);
      EXPECT_LE(disk.prefetch_hits, disk.prefetched);
      if (plan.memory.look_ahead_batches == 0) {
        EXPECT_EQ(disk.prefetched, 0u);
        EXPECT_EQ(disk.prefetch_hits, 0u);
      } else {
        EXPECT_GT(disk.prefetched, 0u) << threads;
        EXPECT_LT(disk.prefetched, disk.counters.faults) << threads;
        // Which look-ahead pages are still resident when trace reaches them depends on timing:
        // 40% in the plain build, 17-18% under the sanitizers with TBB held to one worker
        // (Intel Xeon, 2026-12-03). The bound guards against a look-ahead whose pages are not
        // the ones trace reads next.
        EXPECT_GT(disk.prefetch_hits, disk.prefetched / 10) << threads;
      }
    }
  }
  fs::remove(path);
}

// A chunked world written chunk by chunk as it is built (ChunkStream) holds the same
// sections as one saved after its build, all but the build's own timings and peaks, and
// renders the fresh build's image; built so, it refuses to trace (its chunks are freed).
class StreamedWorld : public ::testing::TestWithParam<std::vector<std::string>> {};

TEST_P(StreamedWorld, IsTheSameFileSectionBySectionAndRendersTheFreshImage) {
  const std::string saved_after = temp_path("saved_after.wtw"), streamed = temp_path("streamed.wtw");
  const std::vector<float> fresh = build_and_save(GetParam(), saved_after);
  const Config config = small_render(GetParam());
  const RenderPlan plan = plan_render(config);
  const Scene& scene = room();
  const LightSampler lights(scene);
  {
    SectionWriter out(streamed);
    const ChunkStream stream{out, kWorldAcceleratorPrefix};
    const auto accelerator = build_world_accelerator(scene, plan.accelerator, &stream);
    RayBatch rays(8);
    HitBatch hits(8);
    EXPECT_THROW(accelerator->intersect_closest(rays, hits, RayRange{0, 8}), std::logic_error);
    // Chunk 0 stays (represented_point, build notes); the others went to the file.
    const auto built_in_memory = build_world_accelerator(scene, plan.accelerator);
    EXPECT_EQ(accelerator->memory().total(), built_in_memory->memory().total());
    EXPECT_LT(accelerator->memory_spans().size() * 2, built_in_memory->memory_spans().size());
    SectionWriter elsewhere(temp_path("elsewhere.wtw"));
    EXPECT_THROW(accelerator->save(elsewhere, kWorldAcceleratorPrefix), std::logic_error);
    save_world(out, scene, lights, *accelerator, plan.accelerator.type, nullptr, config, {});
  }
  const auto a = SectionFile::open(saved_after), b = SectionFile::open(streamed);
  ASSERT_EQ(a->sections().size(), b->sections().size());
  std::size_t chunk_sections = 0;
  for (std::size_t s = 0; s < a->sections().size(); ++s) {
    const std::string& name = a->sections()[s].name;
    ASSERT_EQ(name, b->sections()[s].name);
    // The build's seconds and peaks (raystrips' statistics hold its stages' seconds).
    if (name.ends_with("common") || name.ends_with("raystrips.state") || name == "build.notes") continue;
    const auto left = a->bytes(name), right = b->bytes(name);
    EXPECT_TRUE(std::ranges::equal(left, right)) << name;
    chunk_sections += name.starts_with("accel/chunk.");
  }
  EXPECT_GT(chunk_sections, 10u);
  EXPECT_TRUE(render_loaded(GetParam(), streamed) == fresh);
  EXPECT_FALSE(fs::exists(temp_path("elsewhere.wtw")));  // never finished: removed
  fs::remove(saved_after);
  fs::remove(streamed);
}

INSTANTIATE_TEST_SUITE_P(
    ChunkedAccelerators, StreamedWorld,
    ::testing::Values(std::vector<std::string>{"accel.type=hmq", "build.chunk_triangles=4096"},
                      std::vector<std::string>{"accel.type=hmq", "accel.hmq.width=8", "build.chunk_triangles=4096"},
                      std::vector<std::string>{"accel.type=raystrips", "build.chunk_triangles=4096"},
                      std::vector<std::string>{"accel.type=bvh", "build.chunk_triangles=4096"}));

TEST(WorldFile, SavedProxyOrdersRaysAsTheFreshOneDoes) {
  const std::string path = temp_path("proxy.wtw");
  const std::vector<std::string> settings = {"accel.type=hmq", "reorder.heuristic=hph"};
  const std::vector<float> fresh = build_and_save(settings, path, true);
  EXPECT_TRUE(render_loaded(settings, path) == fresh);
  fs::remove(path);
}

// A world is saved with the paper's 2% proxy; rendered in core (proxy.share = auto) its proxy
// is simplified again to the in-core share, judged against the world, and orders the rays
// to the same image. Paged, or asked for no fewer triangles, the saved proxy stays.
TEST(WorldFile, ASavedProxyIsSimplifiedAgainForAnInCoreRender) {
  const std::string path = temp_path("proxy_again.wtw");
  const std::vector<std::string> settings = {"accel.type=hmq", "reorder.heuristic=hph"};
  std::vector<std::string> saved_settings = settings;
  saved_settings.emplace_back("proxy.share=0.02");
  const std::vector<float> fresh = build_and_save(saved_settings, path, true);

  const RenderPlan in_core = plan_render(small_render(settings));
  const std::unique_ptr<LoadedWorld> world = load_world(path, std::nullopt, 2);
  const Proxy* saved = world->proxy.get();
  const std::size_t saved_triangles = saved->report().triangles;
  const float saved_tolerance = saved->surface_tolerance();
  EXPECT_GT(saved_triangles, proxy_target_triangles(0.015, world->scene.triangle_count));
  coarsen_world_proxy(*world, ProxyOptions::kPagedShare, 2);
  EXPECT_EQ(world->proxy.get(), saved);  // already the paged share: kept
  coarsen_world_proxy(*world, in_core.proxy.share, 2);
  const Proxy& coarse = *world->proxy;
  EXPECT_EQ(coarse.report().coarsened_from, saved_triangles);
  EXPECT_LT(coarse.report().triangles * 4, saved_triangles);
  EXPECT_GE(coarse.surface_tolerance(), saved_tolerance);
  EXPECT_GT(coarse.report().quality.hit_overlap, 0.8);
  EXPECT_FALSE(coarse.report().judged_against_saved);
  const std::vector<float> image = render_with(small_render(settings), World{world->scene, *world->accelerator,
                                                                              *world->lights, world->proxy.get()});
  EXPECT_TRUE(image == fresh);

  // A stochastic proxy (the fur's kind) is pruned again, not clustered into blobs.
  saved_settings.emplace_back("proxy.method=stochastic");
  build_and_save(saved_settings, path, true);
  const std::unique_ptr<LoadedWorld> pruned = load_world(path, std::nullopt, 2);
  const std::size_t pruned_saved = pruned->proxy->report().triangles;
  ASSERT_EQ(pruned->proxy->report().method, ProxyMethod::stochastic);
  // Judged as a data-mode rank judges it: by the saved proxy, not the world it does not hold.
  coarsen_world_proxy(*pruned, in_core.proxy.share, 2, ProxyJudge::saved_proxy);
  EXPECT_TRUE(pruned->proxy->report().judged_against_saved);
  EXPECT_GT(pruned->proxy->report().quality.hit_overlap, 0.3);
  EXPECT_EQ(pruned->proxy->report().method, ProxyMethod::stochastic);
  EXPECT_EQ(pruned->proxy->report().coarsened_from, pruned_saved);
  EXPECT_LT(pruned->proxy->report().triangles * 4, pruned_saved);
  fs::remove(path);
}

// memory.backing = copy: the world read into memory of the process's own (on 2 MiB pages where
// the kernel gives them) renders the fresh build's image, hands out the copy and not the file's
// mapping, and checks every section as a mapped load does; a data-parallel rank, which holds
// only the chunks it answers, maps instead and says why.
TEST(WorldFile, ACopiedWorldRendersTheFreshImageFromItsOwnMemory) {
  const std::string path = temp_path("copied.wtw");
  const std::vector<std::string> build = {"accel.type=hmq", "accel.hmq.width=8", "build.chunk_triangles=4096"};
  const std::vector<float> fresh = build_and_save(build, path);
  std::vector<std::string> copied = build;
  copied.emplace_back("memory.backing=copy");
  EXPECT_TRUE(render_loaded(copied, path) == fresh);

  const auto mapped = SectionFile::open(path);
  const auto copy = SectionFile::open(path, std::nullopt, CheckedPages::kept, FileHolding::copied);
  ASSERT_EQ(copy->holding(), FileHolding::copied) << copy->holding_note();
  EXPECT_TRUE(copy->holding_note().empty());
  EXPECT_EQ(mapped->holding(), FileHolding::mapped);
  ASSERT_EQ(copy->sections().size(), mapped->sections().size());
  for (const SectionInfo& section : mapped->sections()) {
    const std::span<const std::byte> a = mapped->bytes(section.name), b = copy->bytes(section.name);
    ASSERT_EQ(a.size(), b.size()) << section.name;
    EXPECT_NE(a.data(), b.data()) << section.name;
    EXPECT_EQ(std::memcmp(a.data(), b.data(), a.size()), 0) << section.name;
    EXPECT_EQ(reinterpret_cast<std::uintptr_t>(b.data()) % 4096, 0u) << section.name;  // aligned as mapped
  }

  const auto rank = SectionFile::open(path, std::nullopt, CheckedPages::given_back, FileHolding::copied);
  EXPECT_EQ(rank->holding(), FileHolding::mapped);
  EXPECT_NE(rank->holding_note().find("data-parallel rank"), std::string::npos) << rank->holding_note();

  std::string damaged = read_all(path);
  Resealer probe(path);
  damaged[probe.entry("accel/chunk.0/hmq8.nodes").offset + 64] ^= 0x20;
  const std::string bad = temp_path("copied_damaged.wtw");
  write_all(bad, damaged);
  try {
    SectionFile::open(bad, std::nullopt, CheckedPages::kept, FileHolding::copied);
    ADD_FAILURE() << "a damaged section was copied without complaint";
  } catch (const SectionFileError& error) {
    EXPECT_NE(std::string(error.what()).find("'accel/chunk.0/hmq8.nodes' checksum mismatch"), std::string::npos)
        << error.what();
  }
  fs::remove(bad);
  fs::remove(path);
}


// proxy.share = auto from the command line: build saves the paper's 2%; a render in core
// simplifies it again to the in-core share and says so, a paged render keeps it.
TEST(WorldFileCli, AutoProxyShareSavesThePapersAndRendersInCoreWithATenth) {
  const std::string world = temp_path("cli_proxy.wtw");
  const auto built =
      testing::run_wavetrace("build builtin:room:20k --accel hmq --proxy --stats " + temp_path("cli_proxy_build.json") +
                             " --out " + world);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  const nlohmann::json build = nlohmann::json::parse(read_all(temp_path("cli_proxy_build.json")));
  const std::size_t saved = build.at("proxy_triangles").get<std::size_t>();
  const double triangles = build.at("scene").at("triangles").get<double>();
  EXPECT_NEAR(double(saved) / triangles, ProxyOptions::kPagedShare, 0.006) << build.dump();
  const auto proxy_of = [&](const std::string& extra) {
    const std::string stats = temp_path("cli_proxy_stats.json");
    fs::remove(stats);
    const auto rendered = testing::run_wavetrace("render " + world + " --size 32x24 --spp 1 --set reorder.heuristic=hph " +
                                                 extra + " --out " + temp_path("cli_proxy.exr") + " --stats " + stats);
    EXPECT_EQ(rendered.exit_code, 0) << rendered.output;
    return nlohmann::json::parse(read_all(stats)).at("proxy");
  };
  const nlohmann::json in_core = proxy_of("");
  EXPECT_EQ(in_core.at("coarsened_from").get<std::size_t>(), saved) << in_core.dump();
  EXPECT_NEAR(in_core.at("triangles").get<double>() / triangles, ProxyOptions::kInCoreShare, 0.002) << in_core.dump();
  const nlohmann::json paged = proxy_of("--set memory.backing=file --set memory.budget=50% --set memory.page_bytes=4096");
  EXPECT_EQ(paged.at("triangles").get<std::size_t>(), saved) << paged.dump();
  EXPECT_TRUE(paged.at("coarsened_from").is_null()) << paged.dump();
  fs::remove(world);
}

// hmq:width=8's walks read a paged world's pages in frames (FilePager::use_frames), chunked
// or not: the in-core image on two threads, every read announced, and the stats say how
// many frames; with memory.page_frames = false, none, and the same image.
TEST(WorldFileCli, PagedWideHmqReadsInFramesTheInCoreImage) {
  for (const char* chunks : {"", " --set build.chunk_triangles=65536"}) {
    const std::string world = temp_path("cli_frames.wtw");
    const auto built = testing::run_wavetrace(std::string("build builtin:room:200k --accel hmq:width=8:leaves_beside_nodes=true") +
                                              chunks + " --out " + world);
    ASSERT_EQ(built.exit_code, 0) << built.output;
    const std::string render = "render " + world + " --size 64x48 --spp 2 --threads 2 --set render.max_depth=3 ";
    const auto in_core = testing::run_wavetrace(render + "--out " + temp_path("cli_frames_core.exr"));
    ASSERT_EQ(in_core.exit_code, 0) << in_core.output;
    for (const char* frames : {"true", "false"}) {
      const std::string stats = temp_path("cli_frames.json");
      const auto paged = testing::run_wavetrace(render + "--set memory.backing=file --set memory.budget=50% "
                                                "--set memory.page_bytes=65536 --set memory.page_frames=" + frames +
                                                " --out " + temp_path("cli_frames_paged.exr") + " --stats " + stats);
      ASSERT_EQ(paged.exit_code, 0) << paged.output;
      EXPECT_EQ(read_all(temp_path("cli_frames_core.exr")), read_all(temp_path("cli_frames_paged.exr"))) << chunks << frames;
      const nlohmann::json report = nlohmann::json::parse(read_all(stats));
      bool traced = false;
      for (const nlohmann::json& stage : report.at("stages")) {
        if (stage["name"] != "trace") continue;
        const nlohmann::json& disk = stage.at("disk");
        EXPECT_EQ(disk.at("frames").get<std::size_t>() > 0, std::string(frames) == "true") << chunks << disk.dump();
        EXPECT_GT(disk.at("faults").get<std::uint64_t>(), 50u) << chunks << disk.dump();
        EXPECT_LE(double(disk.at("unannounced_faults").get<std::uint64_t>()),
                  0.03 * double(disk.at("faults").get<std::uint64_t>())) << chunks << disk.dump();
        traced = true;
      }
      EXPECT_TRUE(traced);
    }
    fs::remove(world);
  }
}

TEST(WorldFileCli, BuildRenderAndInfo) {
  const std::string world = temp_path("cli.wtw");
  const auto built = testing::run_wavetrace("build builtin:room:20k --accel raystrips --out " + world);
  ASSERT_EQ(built.exit_code, 0) << built.output;
  EXPECT_NE(built.output.find("bytes/triangle"), std::string::npos) << built.output;
  const std::string stats = temp_path("cli_stats.json");
  const auto rendered = testing::run_wavetrace("render " + world + " --size 64x48 --spp 1 --out " +
                                               temp_path("cli.exr") + " --set memory.backing=file --set memory.budget=30% "
                                               "--set memory.page_bytes=4096 --stats " + stats);
  ASSERT_EQ(rendered.exit_code, 0) << rendered.output;
  EXPECT_NE(rendered.output.find("real faults"), std::string::npos) << rendered.output;
  // Where the reads go: every trace fault counted to one part of the file, and the distinct
  // pages of each 1,000 consecutive rays.
  const nlohmann::json report = nlohmann::json::parse(read_all(stats));
  for (const nlohmann::json& stage : report.at("stages")) {
    if (stage["name"] != "trace") continue;
    const nlohmann::json& disk = stage.at("disk");
    std::uint64_t by_part = 0;
    for (const auto& [part, faults] : disk.at("faults_by_part").items()) by_part += faults.get<std::uint64_t>();
    EXPECT_EQ(by_part, disk.at("faults").get<std::uint64_t>()) << disk.dump();
    EXPECT_TRUE(disk["faults_by_part"].contains("accel/raystrips.nodes") ||
                disk["faults_by_part"].contains("accel/raystrips.strips"))
        << disk.dump();
    EXPECT_GE(disk.at("pages_per_1000_rays").get<double>(), 1.0) << disk.dump();
  }
  EXPECT_NE(rendered.output.find("distinct pages touched per 1000 consecutive rays"), std::string::npos)
      << rendered.output;
  // Pages placed by a memfd's slots instead (auto takes userfaultfd where the kernel allows):
  // the same image, and the stats say which placed them.
  const std::string memfd_stats = temp_path("cli_stats_memfd.json");
  const auto memfd = testing::run_wavetrace("render " + world + " --size 64x48 --spp 1 --out " + temp_path("cli_memfd.exr") +
                                            " --set memory.backing=file --set memory.budget=30% --set memory.page_bytes=4096 "
                                            "--set memory.page_mapping=memfd --stats " + memfd_stats);
  ASSERT_EQ(memfd.exit_code, 0) << memfd.output;
  EXPECT_EQ(read_all(temp_path("cli.exr")), read_all(temp_path("cli_memfd.exr")));
  for (const auto& [path, mappings] : {std::pair{stats, std::vector<std::string>{"userfaultfd", "memfd"}},
                                       std::pair{memfd_stats, std::vector<std::string>{"memfd"}}}) {
    const nlohmann::json report_of_run = nlohmann::json::parse(read_all(path));
    for (const nlohmann::json& stage : report_of_run.at("stages")) {
      if (stage["name"] != "trace") continue;
      const std::string mapping = stage.at("disk").at("mapping").get<std::string>();
      EXPECT_NE(std::find(mappings.begin(), mappings.end(), mapping), mappings.end()) << path << ": " << mapping;
    }
  }
  const auto bad_mapping = testing::run_wavetrace("render " + world + " --size 8x8 --set memory.backing=file "
                                                  "--set memory.budget=10% --set memory.page_mapping=mmap --out " +
                                                  temp_path("z.exr"));
  EXPECT_EQ(bad_mapping.exit_code, 1);
  EXPECT_NE(bad_mapping.output.find("memory.page_mapping"), std::string::npos) << bad_mapping.output;
  const auto bench = testing::run_wavetrace("bench accel --scene " + world + " --rays diffuse --count 2000 --repeat 1");
  ASSERT_EQ(bench.exit_code, 0) << bench.output;
  EXPECT_NE(bench.output.find("raystrips (world file)"), std::string::npos) << bench.output;
  const auto info = testing::run_wavetrace("info " + world);
  ASSERT_EQ(info.exit_code, 0) << info.output;
  EXPECT_NE(info.output.find("raystrips"), std::string::npos) << info.output;
  write_all(world, read_all(world).substr(0, 10000));
  const auto broken = testing::run_wavetrace("render " + world + " --size 32x24 --out " + temp_path("x.exr"));
  EXPECT_EQ(broken.exit_code, 1);
  EXPECT_NE(broken.output.find(world + ": truncated"), std::string::npos) << broken.output;
  const auto not_world = testing::run_wavetrace("render builtin:room:20k --size 8x8 --set memory.backing=file "
                                                "--set memory.budget=10% --out " + temp_path("y.exr"));
  EXPECT_EQ(not_world.exit_code, 1);
  EXPECT_NE(not_world.output.find("is not one"), std::string::npos) << not_world.output;
  const auto chunked = testing::run_wavetrace("build builtin:room:20k --accel hmq --set build.chunk_triangles=4096 --out " +
                                              world);
  ASSERT_EQ(chunked.exit_code, 0) << chunked.output;
  EXPECT_NE(chunked.output.find("saved in place, each chunk as it was built"), std::string::npos) << chunked.output;
  const auto chunked_render = testing::run_wavetrace("render " + world + " --size 32x24 --out " + temp_path("c.exr"));
  EXPECT_EQ(chunked_render.exit_code, 0) << chunked_render.output;
  const auto copied = testing::run_wavetrace("render " + world + " --size 32x24 --set memory.backing=copy --out " +
                                             temp_path("c2.exr") + " --stats " + stats);
  ASSERT_EQ(copied.exit_code, 0) << copied.output;
  EXPECT_EQ(read_all(temp_path("c.exr")), read_all(temp_path("c2.exr")));
  EXPECT_NE(copied.output.find("world file copied"), std::string::npos) << copied.output;
  EXPECT_EQ(nlohmann::json::parse(read_all(stats)).at("memory").at("world").at("holding"), "copied");
  const auto copy_not_world = testing::run_wavetrace("render builtin:room:20k --size 8x8 --set memory.backing=copy --out " +
                                                     temp_path("y.exr"));
  EXPECT_EQ(copy_not_world.exit_code, 1);
  EXPECT_NE(copy_not_world.output.find("memory.backing = copy copies a world file"), std::string::npos)
      << copy_not_world.output;
  // A pool smaller than one page could hold nothing: refused, not rounded up.
  const auto built_again = testing::run_wavetrace("build builtin:room:20k --accel hmq --out " + world);
  ASSERT_EQ(built_again.exit_code, 0) << built_again.output;
  const auto tiny = testing::run_wavetrace("render " + world + " --size 8x8 --out " + temp_path("z.exr") +
                                           " --set memory.backing=file --set memory.budget=1000 "
                                           "--set memory.page_bytes=65536");
  EXPECT_EQ(tiny.exit_code, 1);
  EXPECT_NE(tiny.output.find("memory.budget (1000 bytes) is under one page (memory.page_bytes = 65536)"),
            std::string::npos)
      << tiny.output;
}

}  // namespace
}  // namespace wavetrace
