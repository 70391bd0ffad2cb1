// The `wavetrace` command line: render, build, info, bench, export, keys.
#include <cstdio>
#include <exception>
#include <new>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "app/commands.hpp"

int main(int argc, char** argv) {
  CLI::App app("wavetrace: a CPU wavefront ray tracer for very large triangle meshes");
  app.require_subcommand(1);
  int exit_code = 0;
  wavetrace::add_render_command(app, exit_code);
  wavetrace::add_info_command(app, exit_code);
  wavetrace::add_bench_command(app, exit_code);
  wavetrace::add_export_command(app, exit_code);
  wavetrace::add_build_command(app, exit_code);
  wavetrace::add_keys_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& error) {
    return app.exit(error);
  } catch (const std::bad_alloc&) {
    // Commands that know what they were allocating say so (render); this is the rest.
    fmt::print(stderr, "wavetrace: error: out of memory\n");
    return 1;
  } catch (const std::exception& error) {
    fmt::print(stderr, "wavetrace: error: {}\n", error.what());
    return 1;
  }
  return exit_code;
}
