// The subcommands of the `wavetrace` command line.
#pragma once

#include <CLI/CLI.hpp>

namespace wavetrace {

// Each adds its subcommand to the app; the callback runs it and sets `exit_code`.
void add_render_command(CLI::App& app, int& exit_code);
void add_info_command(CLI::App& app, int& exit_code);
void add_bench_command(CLI::App& app, int& exit_code);
void add_export_command(CLI::App& app, int& exit_code);
void add_build_command(CLI::App& app, int& exit_code);
void add_keys_command(CLI::App& app, int& exit_code);
// `bench report`, added under the bench command.
void add_bench_report_command(CLI::App& bench, int& exit_code);

}  // namespace wavetrace
