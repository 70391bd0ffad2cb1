// Fuzzes the configuration as a user gives it: a TOML file, then `--set section.key=value`
// lines (the input's lines after a line "--set"), then the plan a render makes of it. Any
// input is a plan or a ConfigError/SceneError naming the problem.
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "wavetrace/setup/config.hpp"
#include "wavetrace/setup/render_setup.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view input(reinterpret_cast<const char*>(data), size);
  constexpr std::string_view kSeparator = "\n--set\n";
  const std::size_t split = input.find(kSeparator);
  try {
    wavetrace::Config config;
    config.load_string(input.substr(0, split), "fuzz.toml");
    if (split != std::string_view::npos) {
      std::string_view assignments = input.substr(split + kSeparator.size());
      while (!assignments.empty()) {
        const std::size_t end = assignments.find('\n');
        config.set(assignments.substr(0, end));
        assignments = end == std::string_view::npos ? std::string_view() : assignments.substr(end + 1);
      }
    }
    wavetrace::plan_render(config);
  } catch (const wavetrace::ConfigError&) {
  } catch (const wavetrace::SceneError&) {
  }
  return 0;
}
