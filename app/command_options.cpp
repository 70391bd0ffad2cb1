// The shared options' names and help texts, and what --size means.
#include "app/command_options.hpp"

#include <fmt/format.h>

namespace wavetrace {

void add_scene_option(CLI::App& command, std::string& scene, SceneKinds kinds, bool positional) {
  command.add_option(positional ? "scene,--scene" : "--scene", scene,
                     kinds == SceneKinds::with_worlds
                         ? "mesh file, scene file (.toml), builtin:NAME[:TRIANGLES] or a saved world (.wtw)"
                         : "mesh file, scene file (.toml) or builtin:NAME[:TRIANGLES]");
}

void add_accel_option(CLI::App& command, std::string& accel, bool list, std::string_view note) {
  const std::string what =
      list ? "comma-separated accelerators, each TYPE[:key=value]..., e.g. hmq:width=8,embree:mode=robust"
           : "accelerator: TYPE[:key=value]... (accel.type, accel.TYPE.key, build.chunk_triangles), e.g. hmq:width=8";
  command.add_option("--accel", accel, note.empty() ? what : what + "; " + std::string(note));
}

void add_spp_option(CLI::App& command, std::optional<int>& spp) {
  command.add_option("--spp", spp, "samples per pixel (render.spp)");
}
void add_spp_option(CLI::App& command, int& spp) { command.add_option("--spp", spp, "samples per pixel (render.spp)"); }

void add_size_option(CLI::App& command, std::string& size) {
  command.add_option("--size", size, "image size as WIDTHxHEIGHT (render.width, render.height)");
}

void add_threads_option(CLI::App& command, std::optional<int>& threads) {
  command.add_option("--threads", threads, "worker threads, 0 = all cores (render.threads)");
}
void add_threads_option(CLI::App& command, int& threads) {
  command.add_option("--threads", threads, "worker threads, 0 = all cores (render.threads)");
}

void add_config_option(CLI::App& command, std::string& path) {
  command.add_option("--config", path, "TOML config file (docs/configuration.md)");
}

void add_set_option(CLI::App& command, std::vector<std::string>& assignments, std::string_view example) {
  const std::string what = "override a config key: section.key=value" +
                           (example.empty() ? std::string() : fmt::format(" (e.g. {})", example));
  command.add_option("--set", assignments, what)->expected(1)->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
}

void add_subdivide_option(CLI::App& command, int& levels) {
  command.add_option("--subdivide", levels, "levels of Loop subdivision first (scene.subdivide)");
}

void set_image_size(Config& config, const std::string& size) {
  const std::size_t by = size.find('x');
  if (by == std::string::npos) throw ConfigError(fmt::format("--size '{}': expected WIDTHxHEIGHT", size));
  config.set("render.width=" + size.substr(0, by));
  config.set("render.height=" + size.substr(by + 1));
}

}  // namespace wavetrace
