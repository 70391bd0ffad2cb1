// Parsing memory.budget: "20%" or a size with a unit.
#include "wavetrace/memory/memory_budget.hpp"

#include <charconv>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

namespace wavetrace {

MemoryBudget parse_memory_budget(std::string_view text) {
  const auto fail = [&]() -> MemoryBudget {
    throw std::invalid_argument("memory budget '" + std::string(text) +
                                "' is not a share in (0%, 100%] or a size such as 512MiB, 2GB, 4096");
  };
  double value = 0.0;
  const auto [end, status] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (status != std::errc() || end == text.data() || !(value > 0.0) || !std::isfinite(value)) return fail();
  const std::string_view unit(end, text.data() + text.size() - end);
  MemoryBudget budget;
  if (unit == "%") {
    if (value > 100.0) return fail();
    budget.share = value / 100.0;
    return budget;
  }
  const std::pair<std::string_view, double> units[] = {{"", 1.0},       {"B", 1.0},          {"KiB", 1024.0},
                                                       {"MiB", 1 << 20}, {"GiB", 1 << 30},   {"KB", 1e3},
                                                       {"MB", 1e6},      {"GB", 1e9}};
  for (const auto& [name, scale] : units) {
    if (unit == name) {
      // Past 2^62 bytes no machine has it, and the conversion below would be undefined
      // (a fuzz finding: "1888...888B").
      if (value * scale > 0x1p62) return fail();
      budget.is_share = false;
      budget.bytes = static_cast<std::size_t>(value * scale);
      return budget.bytes > 0 ? budget : fail();
    }
  }
  return fail();
}

}  // namespace wavetrace
