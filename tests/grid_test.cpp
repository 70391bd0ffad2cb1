// The one-level hashed grid: agreement with Embree (robust) on closed, soup, scanned,
// open and sparse scenes, axis-parallel rays on cell faces, any hit, no leaks, the
// resolution guard, and its memory report.
#include <algorithm>
#include <bit>
#include <cstring>

#include <gtest/gtest.h>
#include <tbb/task_arena.h>

#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/accel/grid/array_grid.hpp"
#include "wavetrace/accel/grid/hashed_grid.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/leak_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"

#include "accel_agreement.hpp"

namespace wavetrace {
namespace {

struct Disagreement {
  std::size_t rays = 0, hit_differs = 0, far_t = 0;
};

Disagreement compare_with_robust_embree(const Scene& scene, const Accelerator& grid, RaySetKind kind, std::size_t count) {
  AcceleratorOptions robust;
  robust.embree.mode = EmbreeMode::robust;
  const auto reference = make_accelerator(scene.mesh, robust);
  const RaySet rays = make_ray_set(kind, scene, *reference, count);
  const auto expected = trace_ray_set(*reference, rays);
  const auto actual = trace_ray_set(grid, rays);
  Disagreement result;
  const float diagonal = scene.mesh.bounds().diagonal();
  for (std::size_t b = 0; b < rays.batches.size(); ++b) {
    for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
      ++result.rays;
      result.hit_differs += expected[b]->is_hit(i) != actual[b]->is_hit(i);
      if (!rays.any_hit() && expected[b]->is_hit(i) && actual[b]->is_hit(i)) {
        result.far_t += std::fabs(expected[b]->t[i] - actual[b]->t[i]) > 1e-4f * diagonal;
      }
    }
  }
  return result;
}

class GridAgreesWithEmbree : public ::testing::TestWithParam<std::string> {};

TEST_P(GridAgreesWithEmbree, OnAtLeast9999PerMyriadOfRays) {
  const Scene scene = load_scene({GetParam(), 0});
  const auto arraygrid = make_array_grid_accelerator(scene.mesh, ArrayGridOptions{});
  for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
    const Disagreement result = compare_with_robust_embree(scene, *arraygrid, kind, 10000);
    EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays)) << to_string(kind) << " arraygrid";
    EXPECT_LE(double(result.far_t), 1e-4 * double(result.rays)) << to_string(kind) << " arraygrid";
  }
  for (const std::uint32_t macrocells : {0u, 6u, 2u}) {  // grid, mlgrid, mlgrid with many levels
    for (const double density : {32.0, 4.0}) {
      HashedGridOptions options;
      options.density = density;
      options.macrocell_factor = macrocells;
      const auto grid = make_hashed_grid_accelerator(scene.mesh, options);
      for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::random, RaySetKind::diffuse, RaySetKind::shadow}) {
        const Disagreement result = compare_with_robust_embree(scene, *grid, kind, 10000);
        EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays))
            << to_string(kind) << " density " << density << " macrocells " << macrocells;
        EXPECT_LE(double(result.far_t), 1e-4 * double(result.rays))
            << to_string(kind) << " density " << density << " macrocells " << macrocells;
      }
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Scenes, GridAgreesWithEmbree,
                         ::testing::ValuesIn(testing::agreement_scenes("builtin:soup:50k")),
                         testing::agreement_scene_label);

TEST(Grid, AxisParallelRaysAlongCellFacesFromInsideAndOutside) {
  // An axis-aligned box mesh on a grid whose cell faces it shares: rays along the axes,
  // many of them exactly in face and edge planes, starting inside and outside the grid.
  // A ray running along a box edge lies in two triangles' planes, where "hit" is a matter of
  // convention (robust Embree says miss, our watertight test hit), so the reference is the
  // BVH: the same triangle test, so any difference is the grid missing a cell.
  const Scene stadium = make_builtin_scene("builtin:stadium:2000");
  const auto reference = make_bvh_accelerator(stadium.mesh, BvhOptions{});
  HashedGridOptions with_macrocells;
  with_macrocells.macrocell_factor = 6;
  const auto grid = make_hashed_grid_accelerator(stadium.mesh, HashedGridOptions{});
  const auto mlgrid = make_hashed_grid_accelerator(stadium.mesh, with_macrocells);
  const auto arraygrid = make_array_grid_accelerator(stadium.mesh, ArrayGridOptions{});
  RayBatch rays(4096);
  const float coordinates[] = {-500.0f, -250.0f, 0.0f, 0.5f, 250.0f, 500.0f};
  for (int axis = 0; axis < 3; ++axis) {
    for (const float sign : {-1.0f, 1.0f}) {
      for (const float start : {0.0f, -2000.0f * sign}) {  // inside the box, then outside the grid
        for (const float a : coordinates) {
          for (const float b : coordinates) {
            const std::size_t i = rays.count++;
            glm::vec3 origin(0.0f), direction(0.0f);
            origin[axis] = start;
            origin[(axis + 1) % 3] = a;
            origin[(axis + 2) % 3] = b;
            direction[axis] = sign;
            rays.set_geometry(i, origin, direction, 0.0f, std::numeric_limits<float>::infinity());
            rays.flags[i] = ray_flags::alive;
            rays.kind[i] = RayKind::camera;
          }
        }
      }
    }
  }
  HitBatch expected(4096), actual(4096), macro(4096), nested(4096);
  reference->intersect_closest(rays, expected, rays.all());
  grid->intersect_closest(rays, actual, rays.all());
  mlgrid->intersect_closest(rays, macro, rays.all());
  arraygrid->intersect_closest(rays, nested, rays.all());
  for (std::size_t i = 0; i < rays.count; ++i) {
    ASSERT_EQ(macro.is_hit(i), expected.is_hit(i)) << "mlgrid ray " << i;
    ASSERT_EQ(nested.is_hit(i), expected.is_hit(i)) << "arraygrid ray " << i;
    if (expected.is_hit(i)) {
      EXPECT_NEAR(macro.t[i], expected.t[i], 1e-3f) << "mlgrid ray " << i;
      EXPECT_NEAR(nested.t[i], expected.t[i], 1e-3f) << "arraygrid ray " << i;
    }
  }
  std::size_t inside_hits = 0;
  for (std::size_t i = 0; i < rays.count; ++i) {
    ASSERT_EQ(actual.is_hit(i), expected.is_hit(i)) << "ray " << i;
    if (expected.is_hit(i)) {
      EXPECT_NEAR(actual.t[i], expected.t[i], 1e-3f) << "ray " << i;
      ++inside_hits;
    }
  }
  EXPECT_GE(inside_hits, rays.count / 2);  // every ray from inside the closed box hits it
}

TEST(Grid, AnyHitMatchesClosestHitOnOcclusion) {
  const Scene scene = make_builtin_scene("builtin:default:20000");
  const auto grid = make_hashed_grid_accelerator(scene.mesh, HashedGridOptions{});
  const auto reference = make_accelerator(scene.mesh, AcceleratorOptions{});
  const RaySet shadows = make_ray_set(RaySetKind::shadow, scene, *reference, 20000);
  const auto occluded = trace_ray_set(*grid, shadows);
  std::size_t blocked = 0;
  for (std::size_t b = 0; b < shadows.batches.size(); ++b) {
    HitBatch closest(shadows.batches[b]->capacity());
    grid->intersect_closest(*shadows.batches[b], closest, shadows.batches[b]->all());
    for (std::size_t i = 0; i < shadows.batches[b]->count; ++i) {
      ASSERT_EQ(occluded[b]->is_hit(i), closest.is_hit(i));
      blocked += closest.is_hit(i);
    }
  }
  EXPECT_GT(blocked, 0u);
}

TEST(Grid, NoRayEscapesTheClosedSphereOrTheRoom) {
  for (const char* source : {"builtin:sphere:200k", "builtin:room:50k"}) {
    const Scene scene = make_builtin_scene(source);
    const LeakReport report = run_leak_bench(
        scene,
        {parse_accelerator_spec("grid", Config{}), parse_accelerator_spec("mlgrid", Config{}),
         parse_accelerator_spec("arraygrid", Config{})},
        200000, 0);
    ASSERT_EQ(report.results.size(), 3u);
    for (const LeakResult& result : report.results) EXPECT_EQ(result.escaped, 0u) << source << " " << result.label;
  }
}

TEST(Grid, ResolutionGuardCapsTheCellsAndStaysCorrect) {
  const Scene stadium = make_builtin_scene("builtin:stadium:5000");
  HashedGridOptions options;
  options.max_cells = 2000;
  const auto guarded = make_hashed_grid_accelerator(stadium.mesh, options);
  EXPECT_NE(guarded->build_notes().find("resolution guard"), std::string::npos) << guarded->build_notes();
  const auto free = make_hashed_grid_accelerator(stadium.mesh, HashedGridOptions{});
  EXPECT_EQ(free->build_notes().find("resolution guard"), std::string::npos) << free->build_notes();
  EXPECT_LT(guarded->memory().hierarchy, free->memory().hierarchy);
  const Disagreement result = compare_with_robust_embree(stadium, *guarded, RaySetKind::primary, 5000);
  EXPECT_EQ(result.hit_differs, 0u);
}

TEST(Grid, MacrocellLevelsCoverTheGridAndCostLittle) {
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  HashedGridOptions options;
  options.macrocell_factor = 6;
  const auto grid = make_hashed_grid_accelerator(scene.mesh, HashedGridOptions{});
  const auto mlgrid = make_hashed_grid_accelerator(scene.mesh, options);
  EXPECT_EQ(mlgrid->name(), "mlgrid");
  EXPECT_NE(mlgrid->build_notes().find("macrocells level 1"), std::string::npos) << mlgrid->build_notes();
  EXPECT_GT(mlgrid->memory().hierarchy, grid->memory().hierarchy);
  EXPECT_LT(mlgrid->memory().hierarchy, grid->memory().hierarchy * 11 / 10);  // a bit per 216 cells and up
  EXPECT_THROW(parse_accelerator_spec("mlgrid:macrocell_factor=1", Config{}), ConfigError);
}

// The build's slab tasks own their cells: the arrays must not depend on how many threads ran
// them, and each cell's list must ascend (the layout's promise) without a sort.
TEST(Grid, BuildIsTheSameOnAnyThreadCountAndEveryListAscends) {
  const Scene scene = make_builtin_scene("builtin:room:30k");  // walls, strands and small triangles
  for (const std::uint32_t macrocells : {0u, 6u}) {
    HashedGridOptions options;
    options.macrocell_factor = macrocells;
    std::vector<std::vector<std::byte>> arrays_by_threads[2];
    for (const int threads : {1, 2}) {
      tbb::task_arena arena(threads);
      arena.execute([&] {
        const auto grid = make_hashed_grid_accelerator(scene.mesh, options);
        double phase_seconds = 0.0;
        for (const char* phase : {"bounds", "slabs", "lists", "macrocells"}) {
          EXPECT_GE(grid->build().phases.seconds(phase), 0.0) << phase;
          phase_seconds += grid->build().phases.seconds(phase);
        }
        EXPECT_LE(phase_seconds, grid->build().seconds);
        for (const char* stage : {"lists.runs", "lists.cells", "lists.place", "lists.fill"}) {  // thread-seconds, overlapping
          EXPECT_GT(grid->build().phases.seconds(stage), 0.0) << stage;
        }
        EXPECT_EQ(grid->build().phases.entries().size(), 8u);
        for (const auto span : grid->memory_spans()) arrays_by_threads[threads - 1].emplace_back(span.begin(), span.end());
      });
    }
    ASSERT_EQ(arrays_by_threads[0], arrays_by_threads[1]) << "macrocell factor " << macrocells;
    // Spans: D, O, H, L, then the mesh (and macrocell levels).
    const auto as_words = [](const std::vector<std::byte>& bytes) {
      std::vector<std::uint32_t> words(bytes.size() / 4);
      std::memcpy(words.data(), bytes.data(), words.size() * 4);
      return words;
    };
    const std::vector<std::uint32_t> starts = as_words(arrays_by_threads[0][2]), items = as_words(arrays_by_threads[0][3]);
    ASSERT_EQ(starts.back(), items.size());
    std::size_t cells_with_items = 0;
    for (std::size_t slot = 0; slot + 1 < starts.size(); ++slot) {
      ASSERT_LE(starts[slot], starts[slot + 1]);
      ASSERT_TRUE(std::is_sorted(items.begin() + starts[slot], items.begin() + starts[slot + 1])) << "slot " << slot;
      ASSERT_EQ(std::adjacent_find(items.begin() + starts[slot], items.begin() + starts[slot + 1]),
                items.begin() + starts[slot + 1]) << "a triangle twice in slot " << slot;
      cells_with_items += starts[slot + 1] > starts[slot];
    }
    EXPECT_GT(cells_with_items, scene.mesh.triangle_count() / 4);
    // D marks exactly the cells with a list: one set bit for each non-empty slot.
    std::size_t marked_cells = 0;
    for (const std::byte byte : arrays_by_threads[0][0]) marked_cells += std::size_t(std::popcount(std::uint8_t(byte)));
    EXPECT_EQ(marked_cells, cells_with_items);
  }
}

// Listing a triangle only in the cells it overlaps changes the lists, never a closest hit: the
// same triangle, distance and barycentrics as the paper's bounding-box lists, for every ray.
TEST(Grid, ListsOfTheCellsATriangleOverlapsFindTheHitsOfBoundingBoxLists) {
  for (const char* source : {"builtin:fur:20k", "builtin:room:30k", "builtin:stadium:2000"}) {
    const Scene scene = make_builtin_scene(source);
    for (const std::uint32_t macrocells : {0u, 6u}) {
      HashedGridOptions exact, boxes;
      exact.macrocell_factor = boxes.macrocell_factor = macrocells;
      boxes.bounding_box_lists = true;
      const auto exact_grid = make_hashed_grid_accelerator(scene.mesh, exact);
      const auto box_grid = make_hashed_grid_accelerator(scene.mesh, boxes);
      EXPECT_LT(exact_grid->memory().hierarchy, box_grid->memory().hierarchy) << source;
      for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::diffuse, RaySetKind::random, RaySetKind::shadow}) {
        const RaySet rays = make_ray_set(kind, scene, *box_grid, 5000);
        const auto expected = trace_ray_set(*box_grid, rays);
        const auto actual = trace_ray_set(*exact_grid, rays);
        for (std::size_t b = 0; b < rays.batches.size(); ++b) {
          for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
            // Any hit: whichever occluder comes first, which the lists may change.
            ASSERT_EQ(actual[b]->is_hit(i), expected[b]->is_hit(i)) << source << " " << to_string(kind) << " ray " << i;
            if (rays.any_hit() || !expected[b]->is_hit(i)) continue;
            ASSERT_EQ(actual[b]->primitive[i], expected[b]->primitive[i]) << source << " " << to_string(kind) << " ray " << i;
            ASSERT_EQ(actual[b]->t[i], expected[b]->t[i]) << source << " " << to_string(kind) << " ray " << i;
            ASSERT_EQ(actual[b]->u[i], expected[b]->u[i]) << source << " " << to_string(kind) << " ray " << i;
            ASSERT_EQ(actual[b]->v[i], expected[b]->v[i]) << source << " " << to_string(kind) << " ray " << i;
          }
        }
      }
    }
  }
  const Scene fur = make_builtin_scene("builtin:fur:20k");
  HashedGridOptions boxes;
  boxes.bounding_box_lists = true;
  const auto entries = [](const Accelerator& grid) {
    const std::string notes = grid.build_notes();
    return std::stod(notes.substr(notes.rfind("H, ") + 3));
  };
  // The fur's strands cross many cells: their boxes hold several times the cells they meet.
  EXPECT_GT(entries(*make_hashed_grid_accelerator(fur.mesh, boxes)),
            2.0 * entries(*make_hashed_grid_accelerator(fur.mesh, HashedGridOptions{})));
}

TEST(ArrayGrid, NestsCrowdedCellsAndItsGuardStopsRefinement) {
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  const auto nested = make_array_grid_accelerator(scene.mesh, ArrayGridOptions{});
  ArrayGridOptions flat_options;
  flat_options.max_depth = 0;
  const auto flat = make_array_grid_accelerator(scene.mesh, flat_options);
  EXPECT_NE(flat->build_notes().find("1 grids"), std::string::npos) << flat->build_notes();
  EXPECT_EQ(nested->build_notes().find("1 grids"), std::string::npos) << nested->build_notes();
  for (const bool by_entries : {false, true}) {
    ArrayGridOptions guarded_options;
    (by_entries ? guarded_options.max_entries : guarded_options.max_cells) = 1000;
    const auto guarded = make_array_grid_accelerator(scene.mesh, guarded_options);
    EXPECT_NE(guarded->build_notes().find("resolution guard"), std::string::npos) << guarded->build_notes();
    EXPECT_LT(guarded->memory().total(), nested->memory().total());
    const Disagreement result = compare_with_robust_embree(scene, *guarded, RaySetKind::primary, 5000);
    EXPECT_LE(double(result.hit_differs), 1e-4 * double(result.rays));
  }
  std::size_t spans = 0;
  for (const auto& span : nested->memory_spans()) spans += span.size();
  EXPECT_EQ(spans, nested->memory().total());
}

TEST(Grid, MemoryIsItsFourArraysAndTheMeshItReadsInPlace) {
  const Scene scene = make_builtin_scene("builtin:sphere:50k");
  const auto grid = make_hashed_grid_accelerator(scene.mesh, HashedGridOptions{});
  const MemoryReport memory = grid->memory();
  EXPECT_EQ(memory.geometry, scene.mesh.vertex_count() * 12 + scene.mesh.triangle_count() * 12);
  std::size_t spans = 0;
  for (const auto& span : grid->memory_spans()) spans += span.size();
  EXPECT_EQ(spans, memory.total());
  // Every triangle is listed at least once: L holds at least N entries.
  EXPECT_GE(memory.hierarchy, scene.mesh.triangle_count() * sizeof(std::uint32_t));
  EXPECT_GT(grid->build().seconds, 0.0);
  EXPECT_GE(grid->build().peak_bytes, memory.total());
}

}  // namespace
}  // namespace wavetrace
