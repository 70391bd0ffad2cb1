// Wiring the stage chain by hand: the same stage objects the config-driven pipeline uses,
// connected as nodes of a tbb::flow::graph, here a primary-ray pass reordered by the hit
// point heuristic (generate → approx_hit → zsort → trace) that only counts hits.
// Usage: hand_wired_pipeline [SCENE]
#include <cstdio>

#include <fmt/format.h>
#include <tbb/flow_graph.h>

#include <wavetrace/accel/registry.hpp>
#include <wavetrace/scene/lights.hpp>
#include <wavetrace/scene/load_scene.hpp>
#include <wavetrace/stages/approx_hit.hpp>
#include <wavetrace/stages/generate.hpp>
#include <wavetrace/pipeline/pipeline.hpp>
#include <wavetrace/setup/render_setup.hpp>
#include <wavetrace/stages/trace.hpp>

using namespace wavetrace;

int main(int argc, char** argv) {
  const Scene scene = load_scene({argc > 1 ? argv[1] : "builtin:default", 0});
  const std::unique_ptr<Accelerator> accelerator = make_accelerator(scene.mesh, AcceleratorOptions{});
  const Camera camera = resolve_camera(CameraOverride{}, scene);

  const Proxy proxy(scene.mesh, ProxyOptions{}, *accelerator);  // 2% of the triangles

  GenerateStage generate(camera, ImageSpec{320, 240, 1}, PixelOrder::scanline);
  Film film(320, 240);  // approx_hit puts the sky of rays missing the scene's box here
  ApproxHitStage approx_hit(proxy, &film, scene.background);
  ZSortStage zsort(ZSortOptions{ReorderHeuristic::hph, CurveKind::hilbert, 1 << 14}, scene.bounds);
  TraceStage trace(*accelerator, scene.material_runs);
  PipelineContext context(/*batch_capacity=*/1024, /*rays_in_flight=*/1 << 16);
  StageCounters generate_counters("generate"), approx_counters("approx_hit"), zsort_counters("zsort"),
      trace_counters("trace");

  std::atomic<std::uint64_t> hits{0};
  tbb::flow::graph graph;
  auto generate_node = make_generate_node(graph, generate, context, generate_counters);
  auto approx_node = make_stage_node(graph, approx_hit, context, approx_counters);
  auto zsort_node = make_buffering_node(graph, zsort, context, zsort_counters);  // serial
  auto trace_node = make_stage_node(graph, trace, context, trace_counters);
  // A hand-written final node: count hits, then end the batch's rays.
  tbb::flow::function_node<Batch*> count_hits(graph, tbb::flow::unlimited, [&](Batch* batch) {
    std::uint64_t found = 0;
    for (std::size_t i = 0; i < batch->rays.count; ++i) found += batch->hits.is_hit(i);
    hits += found;
    const std::size_t rays = batch->rays.count;
    context.pool().release(batch);
    context.retire_rays(rays);
    return tbb::flow::continue_msg();
  });
  tbb::flow::make_edge(tbb::flow::output_port<0>(*generate_node), *approx_node);
  tbb::flow::make_edge(tbb::flow::output_port<0>(*approx_node), *zsort_node);
  tbb::flow::make_edge(tbb::flow::output_port<0>(*zsort_node), *trace_node);
  tbb::flow::make_edge(tbb::flow::output_port<0>(*trace_node), count_hits);
  generate_node->try_put(tbb::flow::continue_msg());
  graph.wait_for_all();

  const StageStats generated = generate_counters.snapshot(), approximated = approx_counters.snapshot(),
                   traced = trace_counters.snapshot();
  fmt::print("{}: {} of {} primary rays hit ({:.1f}%); approx_hit retired {} missing the box; {} flushes of zsort; "
             "trace {:.2f} Mrays/s per thread\n",
             scene.name, hits.load(), generated.rays_out, 100.0 * double(hits.load()) / double(generated.rays_out),
             approximated.rays_in - approximated.rays_out, zsort.flushes(), traced.mrays_per_s());
  return 0;
}
