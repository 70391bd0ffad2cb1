// Stage table and stats JSON of a render.
#include "app/render_report.hpp"

#include <fmt/format.h>

namespace wavetrace {

nlohmann::json bounds_json(const Bounds3& bounds) {
  return {{"min", {bounds.lower.x, bounds.lower.y, bounds.lower.z}},
          {"max", {bounds.upper.x, bounds.upper.y, bounds.upper.z}}};
}

nlohmann::json render_stats_json(const RenderFacts& facts) {
  const MemoryReport memory = facts.accelerator.memory();
  const BuildReport build = facts.accelerator.build();
  const double triangles = double(facts.scene.mesh.triangle_count());
  nlohmann::json stages = nlohmann::json::array();
  for (const StageStats& stage : facts.output.run.stages) {
    stages.push_back({{"name", stage.name},
                      {"rays_in", stage.rays_in},
                      {"rays_out", stage.rays_out},
                      {"seconds", stage.seconds},
                      {"mrays_per_s", stage.mrays_per_s()}});
  }
  nlohmann::json hit_rates = nlohmann::json::array();
  for (const DepthHitRate& rate : facts.output.hit_rates) {
    hit_rates.push_back({{"depth", rate.depth}, {"rays", rate.rays}, {"hits", rate.hits}, {"hit_rate", rate.rate()}});
  }
  return {
      {"scene",
       {{"source", facts.scene.name},
        {"triangles", facts.scene.mesh.triangle_count()},
        {"vertices", facts.scene.mesh.vertex_count()},
        {"bounds", bounds_json(facts.scene.mesh.bounds())},
        {"degenerate_dropped", facts.scene.cleanup.degenerate_dropped}}},
      {"accel",
       {{"type", facts.accelerator.name()},
        {"bytes", memory.total()},
        {"bytes_per_triangle", double(memory.total()) / triangles},
        {"parts", {{"hierarchy", memory.hierarchy}, {"geometry", memory.geometry}, {"other", memory.other}}},
        {"build_seconds", build.seconds},
        {"build_peak_bytes", build.peak_bytes}}},
      {"stages", stages},
      {"hit_rates", hit_rates},
      {"render", {{"seconds", facts.output.run.seconds}, {"threads", facts.output.run.threads}}},
      {"image",
       {{"width", facts.plan.image.width},
        {"height", facts.plan.image.height},
        {"spp", facts.plan.image.samples_per_pixel},
        {"path", facts.image_path}}},
  };
}

std::string render_table(const RenderFacts& facts) {
  const PipelineRun& run = facts.output.run;
  const double thread_seconds = run.seconds * run.threads;
  std::string table = fmt::format("{:<10} {:>14} {:>14} {:>10} {:>8} {:>12}\n", "stage", "rays in", "rays out",
                                  "seconds", "share", "Mrays/s/thr");
  double traced = 0.0;
  for (const StageStats& stage : run.stages) {
    table += fmt::format("{:<10} {:>14} {:>14} {:>10.3f} {:>7.1f}% {:>12.2f}\n", stage.name, stage.rays_in,
                         stage.rays_out, stage.seconds, 100.0 * stage.seconds / thread_seconds, stage.mrays_per_s());
    if (stage.name == "trace") traced = double(stage.rays_in);
  }
  if (!facts.output.hit_rates.empty()) {
    table += "hit rate by depth (camera 0, bounces 1+):";
    for (const DepthHitRate& rate : facts.output.hit_rates) {
      table += fmt::format(" {}: {:.1f}%", rate.depth, 100.0 * rate.rate());
    }
    table += "\n";
  }
  const MemoryReport memory = facts.accelerator.memory();
  const BuildReport build = facts.accelerator.build();
  table += fmt::format("render: {:.3f} s wall on {} threads ({:.3f} thread-seconds), {:.2f} Mrays/s traced\n",
                       run.seconds, run.threads, thread_seconds, traced / run.seconds * 1e-6);
  table += fmt::format("accel {}: {:.1f} MB, {:.1f} bytes/triangle (hierarchy {:.1f}, geometry {:.1f}), built in {:.3f} s\n",
                       facts.accelerator.name(), double(memory.total()) * 1e-6,
                       double(memory.total()) / double(facts.scene.mesh.triangle_count()),
                       double(memory.hierarchy) / double(facts.scene.mesh.triangle_count()),
                       double(memory.geometry) / double(facts.scene.mesh.triangle_count()), build.seconds);
  if (facts.output.rejected_contributions > 0) {
    table += fmt::format("warning: {} non-finite film contributions were dropped\n", facts.output.rejected_contributions);
  }
  return table;
}

}  // namespace wavetrace
