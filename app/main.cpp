// The `wavetrace` command line: render, build, info, bench, export, keys.
#include <cstdio>
#include <exception>
#include <new>
#include <stdexcept>
#include <string_view>

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include "app/commands.hpp"
#include "wavetrace/distribute/mpi_session.hpp"

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
    // Only render is shared by ranks: under mpirun every other command would run once a rank
    // (N builds writing one file), so it is refused on every rank alike.
    if (const int ranks = wavetrace::MpiSession::launched_ranks(); ranks > 1 && argc > 1 &&
                                                                   std::string_view(argv[1]) != "render") {
      throw std::runtime_error(fmt::format("wavetrace {} runs alone: under mpirun ({} ranks) only render is shared",
                                           argv[1], ranks));
    }
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
