// TOML loading (toml++), --set parsing and schema checks.
#include "wavetrace/setup/config.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>

#include <fmt/format.h>
#include <toml++/toml.h>

namespace wavetrace {
namespace {

const ConfigKey* find_key(std::string_view name) {
  const auto& schema = config_schema();
  const auto found = std::find_if(schema.begin(), schema.end(), [&](const ConfigKey& key) { return key.name == name; });
  return found == schema.end() ? nullptr : &*found;
}

const ConfigKey& require_key(std::string_view name) {
  if (const ConfigKey* key = find_key(name)) return *key;
  const std::string section(name.substr(0, name.find('.')));
  const auto& sections = config_sections();
  if (std::find(sections.begin(), sections.end(), section) == sections.end()) {
    std::string known;
    for (const std::string& s : sections) known += (known.empty() ? "" : ", ") + s;
    throw ConfigError(fmt::format("unknown config section '{}' in key '{}' (sections: {})", section, name, known));
  }
  std::string known;
  for (const ConfigKey& key : config_schema()) {
    if (key.name.starts_with(section + ".")) known += (known.empty() ? "" : ", ") + key.name;
  }
  throw ConfigError(fmt::format("unknown config key '{}'{}", name,
                                known.empty() ? fmt::format(" (section '{}' has no keys yet)", section)
                                              : fmt::format(" (known in this section: {})", known)));
}

// A number key whose schema lists choices takes those words too ("pixel"), held as text.
bool is_word_of(const ConfigKey& key, const std::string& text) {
  return key.type == ConfigType::real && std::find(key.choices.begin(), key.choices.end(), text) != key.choices.end();
}

std::string_view type_name(ConfigType type) {
  switch (type) {
    case ConfigType::boolean: return "true or false";
    case ConfigType::integer: return "an integer";
    case ConfigType::real: return "a number";
    case ConfigType::text: return "a string";
    case ConfigType::vector3: return "three numbers";
    default: return "a list of strings";
  }
}

// ", or pixel" for a number key that also takes words.
std::string words_of(const ConfigKey& key) {
  std::string words;
  if (key.type != ConfigType::real) return words;
  for (const std::string& choice : key.choices) words += fmt::format(", or '{}'", choice);
  return words;
}

std::string trim(std::string_view text) {
  const auto first = text.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const auto last = text.find_last_not_of(" \t");
  return std::string(text.substr(first, last - first + 1));
}

std::string unquote(std::string text) {
  if (text.size() >= 2 && (text.front() == '"' || text.front() == '\'') && text.back() == text.front()) {
    return text.substr(1, text.size() - 2);
  }
  return text;
}

std::vector<std::string> split_list(std::string text) {
  text = trim(text);
  if (text.size() >= 2 && text.front() == '[' && text.back() == ']') text = text.substr(1, text.size() - 2);
  std::vector<std::string> items;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string item = unquote(trim(text.substr(start, comma == std::string::npos ? std::string::npos : comma - start)));
    if (!item.empty()) items.push_back(item);
    if (comma == std::string::npos) break;
    start = comma + 1;
  }
  return items;
}

template <typename Number>
std::optional<Number> parse_number(const std::string& text) {
  Number value{};
  const char* end = text.data() + text.size();
  const auto [stop, status] = std::from_chars(text.data(), end, value);
  if (text.empty() || status != std::errc() || stop != end) return std::nullopt;
  return value;
}

ConfigValue parse_text_value(const ConfigKey& key, const std::string& raw) {
  const std::string text = trim(raw);
  const auto fail = [&]() -> ConfigValue {
    throw ConfigError(fmt::format("{} = '{}': expected {}{}", key.name, text, type_name(key.type), words_of(key)));
  };
  switch (key.type) {
    case ConfigType::boolean:
      if (text == "true" || text == "1") return true;
      if (text == "false" || text == "0") return false;
      return fail();
    case ConfigType::integer:
      if (auto value = parse_number<std::int64_t>(text)) return *value;
      return fail();
    case ConfigType::real:
      if (auto value = parse_number<double>(text)) return *value;
      if (is_word_of(key, unquote(text))) return unquote(text);
      return fail();
    case ConfigType::text: return unquote(text);
    case ConfigType::vector3: {
      const std::vector<std::string> items = split_list(text);
      if (items.size() != 3) return fail();
      glm::vec3 vector;
      for (int axis = 0; axis < 3; ++axis) {
        const auto component = parse_number<double>(items[axis]);
        if (!component) return fail();
        vector[axis] = static_cast<float>(*component);
      }
      return vector;
    }
    default: return split_list(text);
  }
}

ConfigValue from_toml(const ConfigKey& key, const toml::node& node) {
  const auto fail = [&]() -> ConfigValue {
    throw ConfigError(fmt::format("{}: expected {}{}", key.name, type_name(key.type), words_of(key)));
  };
  switch (key.type) {
    case ConfigType::boolean:
      if (auto value = node.value_exact<bool>()) return *value;
      return fail();
    case ConfigType::integer:
      if (auto value = node.value_exact<std::int64_t>()) return *value;
      return fail();
    case ConfigType::real:
      if (node.is_number()) return *node.value<double>();
      if (auto word = node.value_exact<std::string>(); word && is_word_of(key, *word)) return *word;
      return fail();
    case ConfigType::text:
      if (auto value = node.value_exact<std::string>()) return *value;
      return fail();
    case ConfigType::vector3: {
      const toml::array* array = node.as_array();
      if (array == nullptr || array->size() != 3) return fail();
      glm::vec3 vector;
      for (std::size_t axis = 0; axis < 3; ++axis) {
        if (!(*array)[axis].is_number()) return fail();
        vector[static_cast<int>(axis)] = static_cast<float>(*(*array)[axis].value<double>());
      }
      return vector;
    }
    default: {
      const toml::array* array = node.as_array();
      if (array == nullptr) return fail();
      std::vector<std::string> items;
      for (const toml::node& item : *array) {
        auto text = item.value_exact<std::string>();
        if (!text) return fail();
        items.push_back(*text);
      }
      return items;
    }
  }
}

void check_limits(const ConfigKey& key, const ConfigValue& value) {
  const auto check_range = [&](double number, const std::string& shown) {
    if (!std::isfinite(number) || number < key.min || number > key.max) {
      throw ConfigError(fmt::format("{} = {} is out of range [{:g}, {:g}]", key.name, shown, key.min, key.max));
    }
  };
  const auto check_choice = [&](const std::string& text) {
    if (key.choices.empty() || std::find(key.choices.begin(), key.choices.end(), text) != key.choices.end()) return;
    std::string known;
    for (const std::string& choice : key.choices) known += (known.empty() ? "" : ", ") + choice;
    throw ConfigError(fmt::format("{} = '{}' is not one of: {}", key.name, text, known));
  };
  if (const auto* integer = std::get_if<std::int64_t>(&value)) check_range(double(*integer), std::to_string(*integer));
  if (const auto* real = std::get_if<double>(&value)) check_range(*real, fmt::format("{:g}", *real));
  if (const auto* text = std::get_if<std::string>(&value)) check_choice(*text);
  if (const auto* list = std::get_if<std::vector<std::string>>(&value)) {
    for (const std::string& item : *list) check_choice(item);
  }
  if (const auto* vector = std::get_if<glm::vec3>(&value)) {
    if (!std::isfinite(vector->x) || !std::isfinite(vector->y) || !std::isfinite(vector->z)) {
      throw ConfigError(fmt::format("{}: components must be finite", key.name));
    }
  }
}

void flatten(const toml::table& table, const std::string& prefix, Config& config) {
  for (const auto& [name, node] : table) {
    const std::string key = prefix.empty() ? std::string(name.str()) : prefix + "." + std::string(name.str());
    if (const toml::table* nested = node.as_table()) {
      flatten(*nested, key, config);
      continue;
    }
    if (prefix.empty()) throw ConfigError(fmt::format("'{}' must be inside a section such as [render]", key));
    config.set_value(key, from_toml(require_key(key), node));
  }
}

}  // namespace

Config::Config() {
  for (const ConfigKey& key : config_schema()) {
    if (key.default_value) values_.emplace(key.name, *key.default_value);
  }
}

void Config::load_file(const std::string& path) {
  try {
    const toml::table table = toml::parse_file(path);
    flatten(table, "", *this);
  } catch (const toml::parse_error& error) {
    throw ConfigError(fmt::format("{}:{}:{}: {}", path, error.source().begin.line, error.source().begin.column,
                                  error.description()));
  } catch (const ConfigError& error) {
    throw ConfigError(fmt::format("{}: {}", path, error.what()));
  }
}

void Config::load_string(std::string_view toml_text, std::string_view origin) {
  try {
    const toml::table table = toml::parse(toml_text, origin);
    flatten(table, "", *this);
  } catch (const toml::parse_error& error) {
    throw ConfigError(fmt::format("{}:{}: {}", origin, error.source().begin.line, error.description()));
  }
}

void Config::set(std::string_view assignment) { assign(assignment, true); }

void Config::restore(std::string_view assignment) { assign(assignment, false); }

void Config::assign(std::string_view assignment, bool given) {
  const std::size_t equals = assignment.find('=');
  if (equals == std::string_view::npos) {
    throw ConfigError(fmt::format("--set '{}': expected section.key=value", assignment));
  }
  const std::string key = trim(assignment.substr(0, equals));
  set_value(key, parse_text_value(require_key(key), std::string(assignment.substr(equals + 1))));
  if (!given) given_.erase(key);
}

void Config::set_value(std::string_view name, ConfigValue value) {
  const ConfigKey& key = require_key(name);
  if (key.type == ConfigType::real) {
    if (const auto* integer = std::get_if<std::int64_t>(&value)) value = double(*integer);
  }
  const bool word = std::holds_alternative<std::string>(value) && is_word_of(key, std::get<std::string>(value));
  if (value.index() != static_cast<std::size_t>(key.type) && !word) {
    throw ConfigError(fmt::format("{}: expected {}", key.name, type_name(key.type)));
  }
  check_limits(key, value);
  values_.insert_or_assign(key.name, std::move(value));
  given_.insert(key.name);
}

std::string Config::assignment(std::string_view name) const {
  const auto found = values_.find(name);
  if (found == values_.end()) throw std::logic_error(fmt::format("config key {} has no value", name));
  struct Text {
    std::string operator()(bool value) const { return value ? "true" : "false"; }
    std::string operator()(std::int64_t value) const { return fmt::format("{}", value); }
    std::string operator()(double value) const { return fmt::format("{:.17g}", value); }
    std::string operator()(const std::string& value) const { return "'" + value + "'"; }
    std::string operator()(const glm::vec3& value) const {
      return fmt::format("[{:.9g}, {:.9g}, {:.9g}]", value.x, value.y, value.z);
    }
    std::string operator()(const std::vector<std::string>& items) const {
      std::string text = "[";
      for (std::size_t i = 0; i < items.size(); ++i) text += (i ? ", '" : "'") + items[i] + "'";
      return text + "]";
    }
  };
  return found->first + "=" + std::visit(Text{}, found->second);
}

bool Config::has(std::string_view key) const { return values_.find(key) != values_.end(); }

const ConfigValue& Config::value(std::string_view name, ConfigType type) const {
  const ConfigKey& key = require_key(name);
  if (key.type != type) throw std::logic_error(fmt::format("config key {} read as the wrong type", name));
  const auto found = values_.find(name);
  if (found == values_.end()) throw std::logic_error(fmt::format("config key {} has no value", name));
  return found->second;
}

bool Config::boolean(std::string_view key) const { return std::get<bool>(value(key, ConfigType::boolean)); }
std::int64_t Config::integer(std::string_view key) const {
  return std::get<std::int64_t>(value(key, ConfigType::integer));
}
double Config::real(std::string_view key) const {
  const ConfigValue& held = value(key, ConfigType::real);
  if (const auto* word = std::get_if<std::string>(&held)) {
    throw ConfigError(fmt::format("{} = '{}': a number is needed here", key, *word));
  }
  return std::get<double>(held);
}
std::optional<std::string> Config::word(std::string_view key) const {
  const ConfigValue& held = value(key, ConfigType::real);
  if (const auto* word = std::get_if<std::string>(&held)) return *word;
  return std::nullopt;
}
const std::string& Config::text(std::string_view key) const {
  return std::get<std::string>(value(key, ConfigType::text));
}
glm::vec3 Config::vector3(std::string_view key) const { return std::get<glm::vec3>(value(key, ConfigType::vector3)); }
const std::vector<std::string>& Config::text_list(std::string_view key) const {
  return std::get<std::vector<std::string>>(value(key, ConfigType::text_list));
}

std::string to_string(const ConfigValue& value) {
  struct Printer {
    std::string operator()(bool b) const { return b ? "true" : "false"; }
    std::string operator()(std::int64_t i) const { return std::to_string(i); }
    std::string operator()(double d) const { return fmt::format("{:g}", d); }
    std::string operator()(const std::string& s) const { return s; }
    std::string operator()(const glm::vec3& v) const { return fmt::format("[{:g}, {:g}, {:g}]", v.x, v.y, v.z); }
    std::string operator()(const std::vector<std::string>& list) const {
      std::string joined;
      for (const std::string& item : list) joined += (joined.empty() ? "" : ", ") + item;
      return "[" + joined + "]";
    }
  };
  return std::visit(Printer{}, value);
}

}  // namespace wavetrace
