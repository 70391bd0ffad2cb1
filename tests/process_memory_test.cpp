// Resident memory read from the OS: it sees memory the process touches, and its peak
// window can be restarted.
#include <gtest/gtest.h>

#include <cstring>
#include <vector>

#include "wavetrace/memory/process_memory.hpp"

namespace wavetrace {
namespace {

TEST(ProcessMemory, SeesTouchedMemoryAndItsPeak) {
  const ResidentMemory before = read_resident_memory();
  ASSERT_GT(before.current_bytes, 0u);
  ASSERT_GE(before.peak_bytes, before.current_bytes);
  constexpr std::size_t kBytes = std::size_t{256} << 20;
  {
    std::vector<char> block(kBytes);
    std::memset(block.data(), 1, block.size());  // resident only once touched
    const ResidentMemory during = read_resident_memory();
    EXPECT_GE(during.current_bytes, before.current_bytes + kBytes * 9 / 10);
    EXPECT_GE(during.peak_bytes, during.current_bytes);
    volatile char sink = block[kBytes / 2];
    (void)sink;
  }
  const ResidentMemory after = read_resident_memory();
  EXPECT_GE(after.peak_bytes, before.current_bytes + kBytes * 9 / 10) << "the peak remembers the freed block";
  if (reset_peak_resident_memory()) {
    const ResidentMemory reset = read_resident_memory();
    EXPECT_LT(reset.peak_bytes, after.peak_bytes - kBytes / 2) << "a new window starts at the current size";
  }
  EXPECT_GT(available_memory_bytes(), 0u);
}

}  // namespace
}  // namespace wavetrace
