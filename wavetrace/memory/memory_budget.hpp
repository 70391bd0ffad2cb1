// memory.budget, as both pagers take it: the page pool's size (a share of the world or bytes),
// and what a world file opened for real paging asks of its pager. Not accel.memory_budget,
// which bounds the whole process for accel.type = auto (setup/accel_choice.hpp).
#pragma once

#include <cstddef>
#include <string_view>

#include "wavetrace/memory/page_mapping.hpp"

namespace wavetrace {

// A pool budget: a share of the world's pages ("20%", rounded up) or bytes ("512MiB",
// "1.5GB", "4096", rounded down to whole pages).
struct MemoryBudget {
  bool is_share = true;
  double share = 1.0;      // in (0, 1]
  std::size_t bytes = 0;   // when !is_share
  bool operator==(const MemoryBudget&) const = default;
};
// Throws std::invalid_argument naming the text on a malformed or non-positive budget.
MemoryBudget parse_memory_budget(std::string_view text);

// A world file paged for real (memory.backing = file): pages of `page_bytes` under `budget`,
// with a counter per observed stage.
struct PagingRequest {
  std::size_t page_bytes = std::size_t{128} << 10;
  MemoryBudget budget;  // a share of the file's bytes, or bytes
  std::size_t clients = 1;
  PageMapping mapping = PageMapping::automatic;
};

}  // namespace wavetrace
