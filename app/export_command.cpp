// `wavetrace export`: any scene to binary PLY, a piece at a time, so a builtin of billions of
// triangles is written without ever being whole in memory.
#include <chrono>
#include <memory>

#include <fmt/format.h>

#include "app/command_options.hpp"
#include "app/commands.hpp"
#include "wavetrace/scene/ply_file.hpp"
#include "wavetrace/scene/load_scene.hpp"
#include "wavetrace/scene/triangle_source.hpp"
#include "wavetrace/setup/config.hpp"

namespace wavetrace {
namespace {

struct ExportArguments {
  std::string scene = "builtin:default";
  std::string out;
  int subdivide = 0;
  std::vector<std::string> assignments;
};

int run_export(const ExportArguments& args) {
  Config config;
  for (const std::string& assignment : args.assignments) config.set(assignment);
  const auto piece_triangles = static_cast<std::size_t>(config.integer("build.chunk_triangles"));
  if (!args.out.ends_with(".ply")) throw ConfigError(fmt::format("--out '{}': export writes .ply files", args.out));
  const auto start = std::chrono::steady_clock::now();
  SceneRequest request{args.scene, args.subdivide};
  request.streamed = true;
  const Scene scene = load_scene(request);
  const MeshTriangleSource whole(scene.mesh, scene.object_starts);
  const TriangleSource& source = scene.streamed() ? *scene.stream : static_cast<const TriangleSource&>(whole);
  const std::size_t vertices = write_binary_ply(source, args.out, piece_triangles);
  fmt::print("wrote {}: {} triangles, {} vertices (binary PLY), in {:.1f} s\n", args.out, source.triangle_count(), vertices,
             std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  if (scene.materials.size() > 1) fmt::print("note: PLY holds no materials; the scene's {} are not written\n", scene.materials.size());
  return 0;
}

}  // namespace

void add_export_command(CLI::App& app, int& exit_code) {
  auto args = std::make_shared<ExportArguments>();
  CLI::App* command = app.add_subcommand("export", "write a scene's triangles as binary PLY");
  add_scene_option(*command, args->scene, SceneKinds::without_worlds);
  command->add_option("--out", args->out, "the .ply file to write")->required();
  add_subdivide_option(*command, args->subdivide);
  add_set_option(*command, args->assignments, "build.chunk_triangles=1000000, the piece size");
  command->callback([args, &exit_code] { exit_code = run_export(*args); });
}

}  // namespace wavetrace
