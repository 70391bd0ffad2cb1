// accel.type = auto: what it measures of a scene, what it chooses under a budget and an
// error bound, and the methods it never puts on their failure case.
#include <algorithm>
#include <filesystem>
#include <fstream>

#include <fmt/format.h>
#include <glm/trigonometric.hpp>
#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/accel_choice.hpp"
#include "wavetrace/accel/grid/hashed_grid.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "test_support.hpp"

namespace wavetrace {
namespace {

constexpr std::size_t kMB = 1000000;
// The process as a small render's, one build at a time.
const AutoAllowance kAllowance{kAutoProcessBaseBytes, 1};
// A budget of `megabytes` for the world, besides what auto counts for the process.
std::size_t world_budget(std::size_t megabytes) { return kAllowance.process_bytes + megabytes * kMB; }

// Chunks of 10k triangles keep the builds' temporaries small, so that on 100k-triangle
// scenes the compact structures cost less than the uncompressed ones, as at scale.
constexpr std::size_t kSmallChunk = 10000;
AcceleratorOptions small_chunks() {
  AcceleratorOptions options;
  options.chunk_triangles = kSmallChunk;
  return options;
}

SceneTraits traits_of(const std::string& source) {
  const Scene scene = make_builtin_scene(source);
  return measure_scene_traits(MeshTriangleSource(scene.mesh), kSmallChunk);
}

AccelChoice choose(const SceneTraits& traits, std::size_t budget, double max_error,
                   const AcceleratorOptions& base = small_chunks(), bool streamed = true) {
  return choose_accelerator(traits, budget, max_error, base, streamed, kAllowance);
}

const AccelCandidate& candidate(const AccelChoice& choice, const std::string& type) {
  for (const AccelCandidate& c : choice.candidates) {
    if (c.options.type == type) return c;
  }
  throw std::logic_error("no candidate " + type);
}

// The fastest measured that fits: bvh:width=8 where its build fits, robust Embree where only
// Embree's smaller build does (bvh's temporaries are about 190 B/tri, Embree's 32).
TEST(AccelChoice, ASmallSceneGetsTheFastestThatFits) {
  const SceneTraits sphere = traits_of("builtin:sphere:20k");
  const AccelChoice roomy = choose(sphere, world_budget(1000), 0.01, AcceleratorOptions{}, false);
  EXPECT_EQ(roomy.spec, "bvh:width=8");
  EXPECT_EQ(roomy.options.bvh.width, 8u);
  EXPECT_TRUE(candidate(roomy, "bvh").chosen);
  EXPECT_TRUE(candidate(roomy, "embree").fits);

  const double embree_bytes = candidate(roomy, "embree").estimated_bytes;
  const double bvh_bytes = candidate(roomy, "bvh").estimated_bytes;
  ASSERT_LT(embree_bytes, bvh_bytes);
  const AccelChoice tight = choose(sphere, std::size_t((embree_bytes + bvh_bytes) / 2), 0.01, AcceleratorOptions{}, false);
  EXPECT_EQ(tight.options.type, "embree");
  EXPECT_EQ(tight.options.embree.mode, EmbreeMode::robust);
  EXPECT_FALSE(candidate(tight, "bvh").fits);
  EXPECT_TRUE(candidate(tight, "embree").chosen);
  EXPECT_NE(tight.summary.find("embree:mode=robust"), std::string::npos) << tight.summary;
}

TEST(AccelChoice, ABudgetThatExcludesUncompressedStructuresGetsACompactOne) {
  const SceneTraits sphere = traits_of("builtin:sphere:100k");
  const AccelChoice lossy = choose(sphere, world_budget(8), 0.01);
  EXPECT_EQ(lossy.spec, "hmq:width=8:epsilon=0.01");
  EXPECT_FALSE(candidate(lossy, "embree").fits);
  EXPECT_FALSE(candidate(lossy, "bvh").fits);
  // Exact only: HMQ is out, the strips are the compact exact method (at 8 MB mlgrid, listing
  // each triangle in the cells it overlaps, squeezes in too: about 39.8 MB of 40).
  const AccelChoice exact = choose(sphere, world_budget(6), 0.0);
  EXPECT_EQ(exact.spec, "raystrips:width=8");
  EXPECT_FALSE(candidate(exact, "hmq").meets_error);
  EXPECT_THROW(choose(sphere, world_budget(1), 0.01), ConfigError);
}

TEST(AccelChoice, ASoupNeverGetsRayStrips) {
  const SceneTraits soup = traits_of("builtin:soup:100k");
  const SceneTraits sphere = traits_of("builtin:sphere:100k");
  EXPECT_LT(soup.triangles_per_vertex, kSoupTrianglesPerVertex);
  EXPECT_GT(sphere.triangles_per_vertex, 5.0);
  for (const std::size_t budget : {world_budget(6), world_budget(8), world_budget(10), world_budget(13), world_budget(100)}) {
    const AccelChoice on_sphere = choose(sphere, budget, 0.0);
    EXPECT_FALSE(candidate(on_sphere, "raystrips").failure_case);
    try {
      const AccelChoice on_soup = choose(soup, budget, 0.0);
      EXPECT_NE(on_soup.options.type, "raystrips") << budget;
      EXPECT_TRUE(candidate(on_soup, "raystrips").failure_case) << budget;
      // Where it fits (about 11 MB estimated with the soup's own vertices) and bvh:width=8
      // (about 14 MB) does not, the grid is the exact method left.
      if (budget == world_budget(13)) {
        EXPECT_EQ(on_soup.options.type, "mlgrid") << budget;
      }
    } catch (const ConfigError& error) {
      EXPECT_NE(on_sphere.options.type, "embree") << budget << ": " << error.what();
    }
  }
}

// The list entries auto counts on its sample are the grid's own, for either kind of list (a
// scene this small is sampled whole).
TEST(AccelChoice, TheGridEntriesItCountsAreTheBuiltGridsOwn) {
  const Scene fur = make_builtin_scene("builtin:fur:20k");
  const SceneTraits traits = measure_scene_traits(MeshTriangleSource(fur.mesh), kSmallChunk);
  const auto entries = [&](bool boxes) {
    HashedGridOptions options;
    options.bounding_box_lists = boxes;
    const std::string notes = make_hashed_grid_accelerator(fur.mesh, options)->build_notes();
    return std::stod(notes.substr(notes.rfind("H, ") + 3));
  };
  EXPECT_NEAR(traits.grid_entries_per_triangle, entries(false), 0.02 * entries(false));
  EXPECT_NEAR(traits.grid_box_entries_per_triangle, entries(true), 0.02 * entries(true));
  EXPECT_GT(traits.grid_box_entries_per_triangle, 2.0 * traits.grid_entries_per_triangle);  // strands
}

TEST(AccelChoice, AStadiumNeverGetsAHashedGrid) {
  const SceneTraits stadium = traits_of("builtin:stadium:100k");
  const SceneTraits soup = traits_of("builtin:soup:100k");
  EXPECT_GT(stadium.triangles_per_grid_cell, 1000.0);  // the small sphere shares a few cells
  EXPECT_LT(soup.triangles_per_grid_cell, kCrowdedGridCell);
  // Even where the grid is the only exact method left (strips ruled out as on a soup).
  SceneTraits crowded_soup = stadium;
  crowded_soup.triangles_per_vertex = soup.triangles_per_vertex;
  EXPECT_EQ(choose(soup, world_budget(13), 0.0).options.type, "mlgrid");
  EXPECT_THROW(choose(crowded_soup, world_budget(10), 0.0), ConfigError);  // where only the grid fits
  for (const std::size_t budget : {world_budget(6), world_budget(10), world_budget(100)}) {
    const AccelChoice choice = choose(stadium, budget, 0.0);
    EXPECT_NE(choice.options.type, "mlgrid");
    EXPECT_TRUE(candidate(choice, "mlgrid").failure_case);
  }
}

// Chunks are runs of the source's order: cut from a sphere sorted along x they are slabs
// that tile it; cut from the same triangles shuffled each spans the whole sphere, and a ray
// descends into all ten. Auto ranks a chunked structure by that, and takes the whole grid
// over chunked strips when the chunks overlap.
TEST(AccelChoice, ChunksThatOverlapRankAChunkedStructureBelowAWholeOne) {
  const Scene scene = make_builtin_scene("builtin:sphere:100k");
  TriangleMesh sorted = scene.mesh;
  const auto centroid_x = [&](const glm::uvec3& t) {
    return sorted.positions[t.x].x + sorted.positions[t.y].x + sorted.positions[t.z].x;
  };
  std::sort(sorted.triangles.begin(), sorted.triangles.end(),
            [&](const glm::uvec3& a, const glm::uvec3& b) { return centroid_x(a) < centroid_x(b); });
  TriangleMesh shuffled = sorted;
  for (std::size_t i = 0; i < shuffled.triangles.size(); ++i) {  // a fixed permutation: stride 7919, prime
    shuffled.triangles[i] = sorted.triangles[(i * 7919) % sorted.triangles.size()];
  }
  const SceneTraits tiled = measure_scene_traits(MeshTriangleSource(sorted), kSmallChunk);
  const SceneTraits overlapping = measure_scene_traits(MeshTriangleSource(shuffled), kSmallChunk);
  const std::size_t chunks = (scene.mesh.triangle_count() + kSmallChunk - 1) / kSmallChunk;
  EXPECT_EQ(tiled.chunks, chunks);
  EXPECT_LT(tiled.chunk_overlap, 1.5);
  EXPECT_GT(overlapping.chunk_overlap, 0.9 * double(chunks));
  EXPECT_EQ(measure_scene_traits(MeshTriangleSource(sorted)).chunk_overlap, 1.0);  // never chunked

  // Both fit 10 MB exact: tiled strips (0.33x Embree's speed) beat the grid (0.24x);
  // strips through ten overlapping chunks (0.33 / 6.3) do not.
  const AccelChoice on_tiled = choose(tiled, world_budget(10), 0.0);
  const AccelChoice on_overlapping = choose(overlapping, world_budget(10), 0.0);
  EXPECT_TRUE(candidate(on_tiled, "mlgrid").fits);
  EXPECT_EQ(on_tiled.options.type, "raystrips") << on_tiled.summary;
  EXPECT_EQ(on_overlapping.options.type, "mlgrid") << on_overlapping.summary;
  EXPECT_LT(candidate(on_overlapping, "raystrips").estimated_speed, candidate(on_tiled, "raystrips").estimated_speed);
  EXPECT_FALSE(candidate(on_tiled, "mlgrid").chunked);
  EXPECT_TRUE(candidate(on_tiled, "raystrips").chunked);
}

// A chunked candidate that fits only when its chunks are built one at a time is taken so
// (build.chunks_at_once = 1, named in its spec); with room for all workers' chunks it is not.
TEST(AccelChoice, AChunkedBuildThatFitsOneChunkAtATimeIsBuiltSo) {
  const SceneTraits sphere = traits_of("builtin:sphere:100k");
  const AutoAllowance four_workers{kAutoProcessBaseBytes, 4};
  const auto hmq8_with = [&](std::size_t budget, const AcceleratorOptions& base) {
    return candidate(choose_accelerator(sphere, budget, 0.01, base, true, four_workers), "hmq");
  };
  AcceleratorOptions one_at_a_time = small_chunks();
  one_at_a_time.chunks_at_once = 1;
  const double four_at_once = hmq8_with(world_budget(100000), small_chunks()).estimated_bytes;
  const double one = hmq8_with(world_budget(100000), one_at_a_time).estimated_bytes;
  ASSERT_LT(one, four_at_once);
  const AccelCandidate between = hmq8_with(std::size_t((one + four_at_once) / 2), small_chunks());
  EXPECT_TRUE(between.fits) << between.reason;
  EXPECT_EQ(between.options.chunks_at_once, 1u);
  EXPECT_NE(between.spec.find(":chunks_at_once=1"), std::string::npos) << between.spec;
  EXPECT_EQ(between.estimated_bytes, one);
  const AccelCandidate roomy = hmq8_with(std::size_t(four_at_once) + 1, small_chunks());
  EXPECT_TRUE(roomy.fits);
  EXPECT_EQ(roomy.options.chunks_at_once, 0u);
  // Below one chunk's peak nothing fits this scene: auto says so, naming hmq8's need.
  try {
    hmq8_with(std::size_t(one) - 1, small_chunks());
    ADD_FAILURE() << "nothing should fit below one chunk at a time";
  } catch (const ConfigError& error) {
    EXPECT_NE(std::string(error.what()).find("hmq:width=8"), std::string::npos) << error.what();
  }
}

// A budget too small for a whole (or default-chunked) build takes the compact structure in
// smaller chunks, measured in the same pass: a quarter of the size each step, down to
// kSmallestAutoChunk; a roomy one keeps the options' chunks.
TEST(AccelChoice, ABudgetTooSmallForTheBuildTakesSmallerChunks) {
  const Scene scene = make_builtin_scene("builtin:room:600k");
  const std::size_t default_chunk = AcceleratorOptions{}.chunk_triangles;
  const SceneTraits traits =
      measure_scene_traits(MeshTriangleSource(scene.mesh, scene.object_starts), default_chunk, nullptr, nullptr, true);
  ASSERT_GE(traits.smaller_chunkings.size(), 2u);
  for (std::size_t k = 0; k < traits.smaller_chunkings.size(); ++k) {
    const SceneTraits::Chunking& chunking = traits.smaller_chunkings[k];
    EXPECT_GE(chunking.chunk_triangles, kSmallestAutoChunk);
    EXPECT_GT(chunking.chunks, 1u);
    EXPECT_LE(chunking.sizes.front(), chunking.chunk_triangles);
    EXPECT_GE(chunking.overlap, 1.0);
    if (k > 0) {
      EXPECT_EQ(chunking.chunk_triangles * 4, traits.smaller_chunkings[k - 1].chunk_triangles);
    }
  }
  const auto hmq8_with = [&](std::size_t budget) {
    return candidate(choose_accelerator(traits, budget, 0.01, AcceleratorOptions{}, true, kAllowance), "hmq");
  };
  const AccelCandidate whole = hmq8_with(world_budget(100000));
  EXPECT_TRUE(whole.fits);
  EXPECT_FALSE(whole.chunked);
  EXPECT_EQ(whole.spec.find(":chunk_triangles="), std::string::npos) << whole.spec;
  const AccelCandidate tight = hmq8_with(std::size_t(whole.estimated_bytes) - 1);
  EXPECT_TRUE(tight.fits) << tight.reason;
  EXPECT_TRUE(tight.chunked);
  EXPECT_LT(tight.options.chunk_triangles, default_chunk);
  EXPECT_NE(tight.spec.find(fmt::format(":chunk_triangles={}", tight.options.chunk_triangles)), std::string::npos)
      << tight.spec;
  EXPECT_LT(tight.estimated_bytes, whole.estimated_bytes);
}

TEST(AccelChoice, TheChosenHmqGridMeetsTheErrorBound) {
  const Scene scene = make_builtin_scene("builtin:sphere:100k");
  const MeshTriangleSource source(scene.mesh);
  for (const double bound : {1e-2, 1e-3, 2e-4}) {
    const AccelChoice choice = choose(measure_scene_traits(source), world_budget(8), bound, small_chunks(), false);
    ASSERT_EQ(choice.options.type, "hmq");
    const auto accelerator = build_world_accelerator(scene, choice.options);
    const std::optional<TriangleMesh> represented = accelerator->represented_mesh(scene.mesh);
    ASSERT_TRUE(represented);
    double moved = 0.0;
    for (std::size_t v = 0; v < scene.mesh.vertex_count(); ++v) {
      moved = std::max(moved, double(glm::distance(scene.mesh.positions[v], represented->positions[v])));
    }
    EXPECT_LE(moved, bound);
    EXPECT_GT(moved, bound / 8) << "the coarsest grid within the bound, not a finer one";
  }
  // A bound finer than 24 bits a side can reach on the scene is refused, not met loosely.
  const AccelChoice exact = choose(measure_scene_traits(source), world_budget(8), 1e-9, small_chunks(), false);
  EXPECT_FALSE(candidate(exact, "hmq").meets_error);
  EXPECT_NE(exact.options.type, "hmq");
}

TEST(AccelChoice, TheNearestSurfaceInViewIgnoresWhatTheCameraCannotSee) {
  // A square at z = 0 in view, 3 units ahead; a triangle 0.5 behind the eye and one off to
  // the side, both nearer and both out of view.
  TriangleMesh mesh;
  mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0},    // the square
                    {-1, -1, 3.5}, {1, -1, 3.5}, {0, 1, 3.5},          // behind
                    {5, 0, 2.5}, {6, 0, 2.5}, {5, 1, 2.5}};            // beside
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {7, 8, 9}};
  const MeshTriangleSource source(mesh);
  const Camera camera{glm::vec3(0, 0, 3), glm::vec3(0), glm::vec3(0, 1, 0), 40.0f};
  ImageSpec image;
  image.width = 400;
  image.height = 300;
  const SceneTraits traits = measure_scene_traits(source, 0, &camera, &image);
  ASSERT_TRUE(traits.nearest_in_view);
  EXPECT_NEAR(*traits.nearest_in_view, 3.0, 1e-6);
  // Half a pixel: 3 x tan(20 degrees) / 300 lies between one pixel's two halves.
  EXPECT_NEAR(half_pixel_footprint(camera, image, 3.0), 3.0 * std::tan(glm::radians(20.0)) / 300.0, 1e-9);
  // Nothing in view: a pixel bound cannot be resolved and says so.
  const Camera away{glm::vec3(0, 0, 3), glm::vec3(0, 0, 6), glm::vec3(0, 1, 0), 40.0f};
  TriangleMesh ahead = mesh;
  ahead.triangles = {{0, 1, 2}, {0, 2, 3}};
  EXPECT_FALSE(measure_scene_traits(MeshTriangleSource(ahead), 0, &away, &image).nearest_in_view);
  AccelGoal goal;
  goal.automatic = true;
  EXPECT_THROW(resolve_accelerator(AcceleratorOptions{}, goal, MeshTriangleSource(ahead), away, image, false),
               ConfigError);
}

TEST(AccelChoice, ConfigTakesPixelOrANumberForErrorBounds) {
  Config config;
  EXPECT_FALSE(accel_goal(config).max_error);  // pixel by default
  config.set("accel.max_error=0.25");
  EXPECT_EQ(accel_goal(config).max_error, 0.25);
  config.set("accel.max_error=pixel");
  EXPECT_FALSE(accel_goal(config).max_error);
  EXPECT_THROW(config.set("accel.max_error=pixels"), ConfigError);
  EXPECT_THROW(config.set("accel.max_error=-1"), ConfigError);
  config.set("accel.hmq.epsilon=pixel");
  EXPECT_TRUE(accel_goal(config).hmq_epsilon_pixel);
  EXPECT_THROW(config.real("accel.hmq.epsilon"), ConfigError);
  EXPECT_EQ(accelerator_options(config).hmq.epsilon, 0.0);  // resolved on the scene, later
  Config from_file;
  from_file.load_string("[accel]\ntype = \"auto\"\nmax_error = 0.5\n[accel.hmq]\nepsilon = \"pixel\"\n");
  EXPECT_TRUE(accel_goal(from_file).automatic);
  EXPECT_EQ(accel_goal(from_file).max_error, 0.5);
  EXPECT_THROW(from_file.load_string("[accel]\nmax_error = \"far\"\n"), ConfigError);
  EXPECT_THROW(resolve_accel_memory_budget("lots"), ConfigError);
  EXPECT_EQ(resolve_accel_memory_budget("512MB"), 512 * kMB);
}

TEST(AccelChoice, RenderPrintsTheChoiceAndItsStatsNameIt) {
  const std::string dir = (std::filesystem::temp_directory_path() / "wavetrace_tests").string();
  std::filesystem::create_directories(dir);
  const auto result = testing::run_wavetrace(
      "render builtin:sphere:100k --accel auto --set accel.memory_budget=40MB --set build.chunk_triangles=10000 "
      "--size 64x48 --spp 1 --threads 2 --out " + dir + "/auto.exr --stats " + dir + "/auto.json");
  ASSERT_EQ(result.exit_code, 0) << result.output;
  EXPECT_NE(result.output.find("accel auto: hmq:width=8:epsilon="), std::string::npos) << result.output;
  std::ifstream file(dir + "/auto.json");
  const nlohmann::json stats = nlohmann::json::parse(file);
  EXPECT_EQ(stats["accel"]["type"], "hmq8");
  const nlohmann::json& chosen = stats["accel"]["auto"];
  EXPECT_EQ(chosen["candidates"].size(), 5u);
  EXPECT_FALSE(chosen["candidates"][0]["fits"].get<bool>());  // robust Embree: 46 MB estimated
  for (const nlohmann::json& candidate : chosen["candidates"]) {
    EXPECT_EQ(candidate["chosen"].get<bool>(), candidate["spec"].get<std::string>() == chosen["chosen"].get<std::string>());
  }
  EXPECT_GT(chosen["pixel_distance"].get<double>(), 0.0);
  const double half_pixel = chosen["pixel_distance"].get<double>() * std::tan(glm::radians(20.0)) / 48.0;
  EXPECT_NEAR(chosen["max_error"].get<double>(), half_pixel, 1e-6 * half_pixel);
}

}  // namespace
}  // namespace wavetrace
