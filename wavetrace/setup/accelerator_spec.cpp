// TYPE[:key=value]... to config keys.
#include "wavetrace/setup/accelerator_spec.hpp"

#include <algorithm>

#include <fmt/format.h>

namespace wavetrace {

void apply_accelerator_spec(Config& config, const std::string& text) {
  std::size_t colon = text.find(':');
  const std::string type = text.substr(0, colon);
  config.set("accel.type=" + type);
  while (colon != std::string::npos) {
    const std::size_t next = text.find(':', colon + 1);
    const std::string option = text.substr(colon + 1, next == std::string::npos ? std::string::npos : next - colon - 1);
    if (option.find('=') == std::string::npos) {
      throw ConfigError(fmt::format("--accel '{}': '{}' is not key=value", text, option));
    }
    // isa= names the kernel set of our walks (accel.isa), but a type's own key where it has
    // one (accel.embree.isa).
    const std::string name = option.substr(0, option.find('='));
    const bool own = std::ranges::any_of(config_schema(), [&](const ConfigKey& key) {
      return key.name == "accel." + type + "." + name;
    });
    const std::string section = name == "chunk_triangles" || name == "chunks_at_once" ? "build."
                                : type == "auto" || (name == "isa" && !own) ? "accel."
                                                                            : "accel." + type + ".";
    config.set(section + option);
    colon = next;
  }
}

}  // namespace wavetrace
