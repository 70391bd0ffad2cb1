// `wavetrace keys`: every configuration key as docs/configuration.md shows it.
#include <fmt/format.h>

#include "app/commands.hpp"
#include "wavetrace/setup/config_reference.hpp"

namespace wavetrace {

void add_keys_command(CLI::App& app, int& exit_code) {
  CLI::App* command = app.add_subcommand(
      "keys", "print every configuration key (type, default, range, help) as Markdown: docs/configuration.md");
  command->callback([&exit_code] {
    fmt::print("{}", configuration_markdown());
    exit_code = 0;
  });
}

}  // namespace wavetrace
