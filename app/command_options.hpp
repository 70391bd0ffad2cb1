// The options render, build, bench, info and export share, declared once: each has one name,
// one help text and one meaning (the config key it sets) in every command that takes it.
#pragma once

#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "wavetrace/setup/config.hpp"

namespace wavetrace {

// Which scenes the command reads: every kind, or not saved worlds (.wtw).
enum class SceneKinds { with_worlds, without_worlds };

// `scene` (positional, as render, build, info and export take it) and --scene.
void add_scene_option(CLI::App& command, std::string& scene, SceneKinds kinds, bool positional = true);
// --accel TYPE[:key=value]...; `list`: comma-separated, each measured (bench).
void add_accel_option(CLI::App& command, std::string& accel, bool list = false, std::string_view note = "");
void add_spp_option(CLI::App& command, std::optional<int>& spp);
void add_spp_option(CLI::App& command, int& spp);
void add_size_option(CLI::App& command, std::string& size);
void add_threads_option(CLI::App& command, std::optional<int>& threads);
void add_threads_option(CLI::App& command, int& threads);
void add_config_option(CLI::App& command, std::string& path);
// --set section.key=value, repeatable, applied in order after the command's defaults.
void add_set_option(CLI::App& command, std::vector<std::string>& assignments, std::string_view example = "");
void add_subdivide_option(CLI::App& command, int& levels);

// --size WIDTHxHEIGHT into render.width and render.height; an error names the option.
void set_image_size(Config& config, const std::string& size);

}  // namespace wavetrace
