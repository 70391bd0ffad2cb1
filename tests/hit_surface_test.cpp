// Mesh-free shading: every accelerator's closest hits carry the hit point and geometric
// normal of the triangle it found, and the trace stage adds its material.
#include <gtest/gtest.h>

#include "wavetrace/accel/hit_surface.hpp"
#include "wavetrace/accel/registry.hpp"
#include "wavetrace/bench/accel_bench.hpp"
#include "wavetrace/bench/ray_sets.hpp"
#include "wavetrace/scene/builtin_scenes.hpp"
#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/render_setup.hpp"
#include "wavetrace/stages/trace.hpp"

namespace wavetrace {
namespace {

class HitSurface : public ::testing::TestWithParam<std::string> {};

TEST_P(HitSurface, IsTheFoundTrianglesPointAndNormal) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const auto accelerator = build_world_accelerator(scene, parse_accelerator_spec(GetParam(), Config{}).options);
  // The surface the accelerator answers for: hmq's is snapped to its grid (8 bits: visibly),
  // and secondary rays must leave that surface, not the mesh's.
  const TriangleMesh surface = accelerator->represented_mesh(scene.mesh).value_or(scene.mesh);
  EXPECT_EQ(surface.positions != scene.mesh.positions, GetParam().starts_with("hmq"));
  for (const RaySetKind kind : {RaySetKind::primary, RaySetKind::diffuse}) {
    const RaySet rays = make_ray_set(kind, scene, *accelerator, 3000);
    const auto hits = trace_ray_set(*accelerator, rays, kind == RaySetKind::primary);
    std::size_t checked = 0;
    for (std::size_t b = 0; b < rays.batches.size(); ++b) {
      const HitBatch& hit = *hits[b];
      for (std::size_t i = 0; i < rays.batches[b]->count; ++i) {
        if (!hit.is_hit(i)) continue;
        HitBatch expected(1);
        expected.set_hit(0, hit.t[i], hit.primitive[i], hit.u[i], hit.v[i]);
        set_surface_from_mesh(expected, 0, surface, hit.primitive[i]);
        ASSERT_EQ(hit.point(i), expected.point(0)) << to_string(kind) << " ray " << i;
        ASSERT_EQ(hit.normal(i), expected.normal(0)) << to_string(kind) << " ray " << i;
        ++checked;
      }
    }
    EXPECT_GT(checked, 2000u) << to_string(kind);
  }
}

INSTANTIATE_TEST_SUITE_P(Types, HitSurface, ::testing::Values("embree", "bvh", "raystrips", "hmq:bits=8", "grid", "arraygrid"),
                         [](const ::testing::TestParamInfo<std::string>& info) { return "type" + std::to_string(info.index); });

TEST(HitSurface, TraceWritesEachHitsMaterialFromTheRuns) {
  const Scene scene = make_builtin_scene("builtin:room:20k");
  const auto accelerator = make_accelerator(scene.mesh, AcceleratorOptions{});
  const RaySet rays = make_ray_set(RaySetKind::diffuse, scene, *accelerator, 2000);
  TraceStage trace(*accelerator, scene.material_runs);
  std::size_t checked = 0;
  for (const auto& source : rays.batches) {
    Batch batch(source->capacity());
    for (std::size_t i = 0; i < source->count; ++i) batch.rays.copy_ray(i, *source, i);
    batch.rays.count = source->count;
    struct Collect final : StageOutput {
      Batch* acquire() override { return nullptr; }
      void emit(Batch*) override {}
      void release(Batch*) override {}
    } out;
    trace.process(&batch, out);
    for (std::size_t i = 0; i < batch.rays.count; ++i) {
      if (!batch.hits.is_hit(i)) continue;
      ASSERT_EQ(batch.hits.material[i], scene.mesh.material(batch.hits.primitive[i]));
      ++checked;
    }
  }
  EXPECT_GT(checked, 1000u);
}

}  // namespace
}  // namespace wavetrace
