// `wavetrace info`: what a scene is made of, as text or JSON.
#include <memory>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "app/commands.hpp"
#include "app/render_report.hpp"
#include "scene/mesh_report.hpp"
#include "scene/scene.hpp"

namespace wavetrace {
namespace {

struct InfoArguments {
  std::string scene = "builtin:default";
  int subdivide = 0;
  bool json = false;
};

int run_info(const InfoArguments& args) {
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
  CLI::App* command = app.add_subcommand("info", "report a scene's size, bounds and topology");
  command->add_option("scene,--scene", args->scene, "mesh file, scene file (.toml) or builtin:NAME[:TRIANGLES]");
  command->add_option("--subdivide", args->subdivide, "levels of Loop subdivision first");
  command->add_flag("--json", args->json, "print JSON");
  command->callback([args, &exit_code] { exit_code = run_info(*args); });
}

}  // namespace wavetrace
