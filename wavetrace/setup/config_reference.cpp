// The configuration reference, rendered from config_schema(): the table is the one source,
// this is its reader's view.
#include "wavetrace/setup/config_reference.hpp"

#include <bit>
#include <cstdint>

#include <fmt/format.h>

#include "wavetrace/setup/config.hpp"

namespace wavetrace {
namespace {

std::string type_name(ConfigType type) {
  switch (type) {
    case ConfigType::boolean: return "bool";
    case ConfigType::integer: return "integer";
    case ConfigType::real: return "real";
    case ConfigType::text: return "text";
    case ConfigType::vector3: return "x, y, z";
    case ConfigType::text_list: return "list";
  }
  return "?";
}

std::string joined_choices(const ConfigKey& key, std::string_view separator) {
  std::string joined;
  for (const std::string& choice : key.choices) joined += (joined.empty() ? "" : std::string(separator)) + "`" + choice + "`";
  return joined;
}

// Integer bounds as written in the table: 2^k for the large powers of two, else the number.
std::string bound(const ConfigKey& key, double value) {
  if (key.type != ConfigType::integer) return fmt::format("{:g}", value);
  const auto whole = static_cast<std::uint64_t>(value);
  if (whole >= 1024 && std::has_single_bit(whole)) return fmt::format("2^{}", std::countr_zero(whole));
  return fmt::format("{}", whole);
}

std::string range_of(const ConfigKey& key) {
  if (key.type == ConfigType::integer || key.type == ConfigType::real) {
    std::string range = fmt::format("[{}, {}]", bound(key, key.min), bound(key, key.max));
    if (!key.choices.empty()) range += " or " + joined_choices(key, ", ");
    return range;
  }
  if (key.type == ConfigType::text_list) return "of " + joined_choices(key, ", ");
  return joined_choices(key, " \\| ");
}

// Help texts hold no pipes of their own; escape any so a row stays one row.
std::string cell(const std::string& text) {
  std::string escaped;
  for (char c : text) escaped += c == '|' ? std::string("\\|") : std::string(1, c);
  return escaped;
}

}  // namespace

std::string configuration_markdown() {
  std::string md =
      "# Configuration\n\n"
      "<!-- Generated from the key table (wavetrace/setup/config_keys.cpp) by `build/wavetrace keys >\n"
      "docs/configuration.md`; a test fails when this file is stale. Edit the table, not this file. -->\n\n"
      "One TOML file (`--config FILE`) with the sections below, and any key overridden on the command line as\n"
      "`--set section.key=value` (lists comma-separated). An unknown key, a value of the wrong type or out of its\n"
      "range, and keys that contradict each other are errors that name the key. The commands' own options\n"
      "(`--spp`, `--size`, `--threads`, `--accel TYPE[:key=value]...`) set the keys they name.\n\n"
      "**Two budgets, two meanings.** `memory.budget` is the *page pool*: the bytes of the world that stay\n"
      "resident while rays page it (simulated, or real with `memory.backing = file`), a share of the world\n"
      "(`20%`) or a size (`512MiB`). `accel.memory_budget` is the *whole process* that `accel.type = auto` may\n"
      "plan for (structure, mesh and build temporaries), a size, a share of the memory available now, or\n"
      "`available`. Neither limits the other.\n\n"
      "```toml\n[scene]\nsource = \"data/bunny00.off\"\nsubdivide = 2\n[render]\nwidth = 800\nheight = 600\nspp = 32\n"
      "[accel]\ntype = \"hmq\"\n[accel.hmq]\nwidth = 8\n[reorder]\nheuristic = \"hph\"\n```\n";
  std::string section;
  for (const ConfigKey& key : config_schema()) {
    const std::string key_section = key.name.substr(0, key.name.find('.'));
    if (key_section != section) {
      section = key_section;
      md += fmt::format("\n## [{}]\n\n| key | type | default | range | what it does |\n|---|---|---|---|---|\n", section);
    }
    const std::string shown = key.default_value ? to_string(*key.default_value) : std::string();
    const std::string default_text = !key.default_value ? "(unset)" : shown.empty() ? "(empty)" : "`" + shown + "`";
    md += fmt::format("| `{}` | {} | {} | {} | {} |\n", key.name, type_name(key.type), cell(default_text),
                      range_of(key), cell(key.help));
  }
  return md;
}

}  // namespace wavetrace
