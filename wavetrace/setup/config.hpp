// The run configuration: one TOML file plus `--set section.key=value` overrides, checked
// against a schema so that an unknown key or an out-of-range value is an error naming it.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <variant>
#include <vector>

#include <glm/vec3.hpp>

namespace wavetrace {

struct RenderPlan;
class Config;

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class ConfigType { boolean, integer, real, text, vector3, text_list };

using ConfigValue = std::variant<bool, std::int64_t, double, std::string, glm::vec3, std::vector<std::string>>;

struct ConfigKey {
  std::string name;  // "section.key" or "section.sub.key"
  ConfigType type;
  std::optional<ConfigValue> default_value;  // none: unset unless given
  double min = 0.0, max = 0.0;               // integer and real keys
  std::vector<std::string> choices;          // text keys (and list items) limited to these;
                                             // number keys also take these words
  std::string help;
  // Reads the key's value into the plan field it sets (the readers are config_keys.cpp's).
  void (*read)(const Config& config, std::string_view key, RenderPlan& plan);
  // For the keys that choose how an accelerator is built (widths, modes, error bounds), what a
  // world file records of the one built (after auto or a pixel bound chose); null for others.
  std::optional<ConfigValue> (*record)(const RenderPlan& plan) = nullptr;
};

// Every key wavetrace knows, with its type, default, limits and plan field (config_keys.cpp).
const std::vector<ConfigKey>& config_schema();
// The top-level sections of DESIGN.md; a section with no keys yet rejects every key.
const std::vector<std::string>& config_sections();

class Config {
 public:
  Config();  // every key at its default

  void load_file(const std::string& path);
  void load_string(std::string_view toml, std::string_view origin = "config");
  // "section.key=value"; the value is parsed as the key's type.
  void set(std::string_view assignment);
  void set_value(std::string_view key, ConfigValue value);
  // As `set`, for a value an earlier run recorded (a world file's build settings): it does
  // not count as given, since the user did not choose it now.
  void restore(std::string_view assignment);

  bool has(std::string_view key) const;
  // Whether the user gave the key (file, --set or set_value), not only its default; two keys
  // that would override each other are an error only when both were given.
  bool given(std::string_view key) const { return given_.contains(key); }
  // The key's value as `set` reads it back ("section.key=value"), exactly (reals to 17 digits).
  std::string assignment(std::string_view key) const;
  bool boolean(std::string_view key) const;
  std::int64_t integer(std::string_view key) const;
  double real(std::string_view key) const;  // throws ConfigError when the key holds a word
  // The word a number key holds instead of a number (accel.max_error = "pixel"), if any.
  std::optional<std::string> word(std::string_view key) const;
  const std::string& text(std::string_view key) const;
  glm::vec3 vector3(std::string_view key) const;
  const std::vector<std::string>& text_list(std::string_view key) const;

  // Every key that has a value, default or given (world files record them all).
  const std::map<std::string, ConfigValue, std::less<>>& values() const { return values_; }

 private:
  const ConfigValue& value(std::string_view key, ConfigType type) const;
  void assign(std::string_view assignment, bool given);
  std::map<std::string, ConfigValue, std::less<>> values_;
  std::set<std::string, std::less<>> given_;
};

std::string to_string(const ConfigValue& value);

}  // namespace wavetrace
