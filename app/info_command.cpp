// `wavetrace info`: what a scene is made of, as text or JSON.
#include <algorithm>
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/command_options.hpp"
#include "app/commands.hpp"
#include "app/render_report.hpp"
#include "wavetrace/scene/mesh_report.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/setup/world_file.hpp"

namespace wavetrace {
namespace {

struct InfoArguments {
  std::string scene = "builtin:default";
  int subdivide = 0;
  bool json = false;
};

// A saved world: what it holds and what it costs, from its sections (checked, not traced).
int run_world_info(const InfoArguments& args) {
  const std::unique_ptr<LoadedWorld> loaded = load_world(args.scene);
  const LoadedWorld& world = *loaded;
  const double triangles = double(std::max<std::size_t>(world.scene.triangle_count, 1));
  const MemoryReport memory = world.accelerator->memory();
  nlohmann::json sections = nlohmann::json::array();
  for (const SectionInfo& section : world.file->sections()) {
    sections.push_back({{"name", section.name}, {"offset", section.offset}, {"bytes", section.size}});
  }
  const nlohmann::json out = {
      {"file", args.scene},
      {"file_bytes", world.file->file_bytes()},
      {"file_bytes_per_triangle", double(world.file->file_bytes()) / triangles},
      {"scene", world.scene.name},
      {"triangles", world.scene.triangle_count},
      {"vertices", world.scene.vertex_count},
      {"bounds", bounds_json(world.scene.bounds)},
      {"materials", world.scene.materials.size()},
      {"lights", world.lights->count()},
      {"accel", world.type},
      {"accel_bytes", memory.total()},
      {"rebuilt_at_load", world.rebuilt},
      {"proxy_triangles", world.proxy ? world.proxy->report().triangles : 0},
      {"build_notes", world.notes},
      {"build", {{"scene_seconds", world.build.scene_seconds}, {"build_seconds", world.build.build_seconds},
                 {"peak_rss_bytes", world.build.peak_rss_bytes}}},
      {"load_seconds", world.seconds},
      {"verify_seconds", world.file->verify_seconds()},
      {"sections", sections}};
  if (args.json) {
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("world file           {} ({:.3f} GB, {:.2f} bytes/triangle, {} sections)\n", args.scene,
             double(world.file->file_bytes()) * 1e-9, double(world.file->file_bytes()) / triangles, sections.size());
  fmt::print("scene                {}\n", world.scene.name);
  fmt::print("triangles            {}\n", world.scene.triangle_count);
  fmt::print("bounds               ({:g}, {:g}, {:g}) .. ({:g}, {:g}, {:g})\n", world.scene.bounds.lower.x,
             world.scene.bounds.lower.y, world.scene.bounds.lower.z, world.scene.bounds.upper.x,
             world.scene.bounds.upper.y, world.scene.bounds.upper.z);
  fmt::print("materials            {} ({} emissive triangles)\n", world.scene.materials.size(), world.lights->count());
  fmt::print("accel                {}: {:.1f} MB, {:.2f} bytes/triangle{}\n", world.type, double(memory.total()) * 1e-6,
             double(memory.total()) / triangles, world.rebuilt ? " (rebuilt from the saved geometry)" : " (in place)");
  fmt::print("build                scene {:.2f} s, build {:.2f} s, peak resident {:.2f} GB\n", world.build.scene_seconds,
             world.build.build_seconds, double(world.build.peak_rss_bytes) * 1e-9);
  fmt::print("load                 {:.3f} s (checksums {:.3f} s)\n", world.seconds, world.file->verify_seconds());
  if (world.proxy) fmt::print("proxy                {} triangles\n", world.proxy->report().triangles);
  fmt::print("notes                {}\n", world.notes);
  return 0;
}

int run_info(const InfoArguments& args) {
  if (is_world_file(args.scene)) return run_world_info(args);
  const Scene scene = load_scene({args.scene, args.subdivide});
  const MeshReport report = analyze_mesh(scene.mesh);
  if (args.json) {
    const nlohmann::json out = {{"source", scene.name},
                                {"triangles", report.triangles},
                                {"vertices", report.vertices},
                                {"bounds", bounds_json(report.bounds)},
                                {"connected_components", report.connected_components},
                                {"edges", report.edges},
                                {"boundary_edges", report.boundary_edges},
                                {"non_manifold_edges", report.non_manifold_edges},
                                {"closed", report.closed()},
                                {"degenerate_dropped", scene.cleanup.degenerate_dropped},
                                {"subdivision_levels", scene.subdivision_levels},
                                {"non_manifold_faces_dropped_by_subdivision", scene.non_manifold_faces_dropped},
                                {"materials", scene.materials.size()}};
    fmt::print("{}\n", out.dump(2));
    return 0;
  }
  fmt::print("scene                {}\n", scene.name);
  fmt::print("triangles            {}\n", report.triangles);
  fmt::print("vertices             {}\n", report.vertices);
  fmt::print("bounds               ({:g}, {:g}, {:g}) .. ({:g}, {:g}, {:g})\n", report.bounds.lower.x,
             report.bounds.lower.y, report.bounds.lower.z, report.bounds.upper.x, report.bounds.upper.y,
             report.bounds.upper.z);
  fmt::print("components           {}\n", report.connected_components);
  fmt::print("edges                {} ({} boundary, {} non-manifold){}\n", report.edges, report.boundary_edges,
             report.non_manifold_edges, report.closed() ? ", closed" : "");
  fmt::print("degenerate dropped   {}\n", scene.cleanup.degenerate_dropped);
  if (scene.subdivision_levels > 0) {
    fmt::print("subdivision          {} levels ({} non-manifold faces left out)\n", scene.subdivision_levels,
               scene.non_manifold_faces_dropped);
  }
  fmt::print("materials            {}\n", scene.materials.size());
  return 0;
}

}  // namespace

void add_info_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<InfoArguments>();
  CLI::App* command = app.add_subcommand("info", "report a scene's size, bounds and topology, or what a saved world holds");
  add_scene_option(*command, args->scene, SceneKinds::with_worlds);
  add_subdivide_option(*command, args->subdivide);
  command->add_flag("--json", args->json, "print JSON");
  command->callback([args, &exit_code] { exit_code = run_info(*args); });
}

}  // namespace wavetrace
