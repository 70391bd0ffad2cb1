// A built array kept as an accelerator's StoredArray: its elements stay as they were, and
// the pages of its allocation past its last element go back to the OS.
#include <gtest/gtest.h>

#include <cstdint>

#include "wavetrace/memory/process_memory.hpp"
#include "wavetrace/memory/stored_array.hpp"

namespace wavetrace {
namespace {

std::uint32_t pattern(std::size_t i) { return static_cast<std::uint32_t>(i * 2654435761u + 12345u); }

TEST(StoredArray, KeepsItsElementsAndHandsBackTheSpareCapacity) {
  // An end inside a huge page and off a 4 KiB boundary, with spare capacity that is resident:
  // filled at a larger size, then cut (a vector keeps its capacity when it shrinks).
  constexpr std::size_t kUsed = ((std::size_t{5} << 20) + 12345) / sizeof(std::uint32_t);
  constexpr std::size_t kFilled = (std::size_t{24} << 20) / sizeof(std::uint32_t);
  LargeArray<std::uint32_t> built(kFilled);
  for (std::size_t i = 0; i < built.size(); ++i) built[i] = pattern(i);
  built.resize(kUsed);
  ASSERT_GE(built.capacity(), kFilled);
  const std::size_t spare_bytes = (built.capacity() - built.size()) * sizeof(std::uint32_t);

  const ResidentMemory before = read_resident_memory();
  const StoredArray<std::uint32_t> stored(std::move(built));
  const ResidentMemory after = read_resident_memory();

  ASSERT_EQ(stored.size(), kUsed);
  for (std::size_t i = 0; i < stored.size(); ++i) {
    ASSERT_EQ(stored[i], pattern(i)) << "element " << i << " of " << stored.size();
  }
  if (before.current_bytes == 0) GTEST_SKIP() << "resident memory cannot be read here";
  EXPECT_LE(after.current_bytes + spare_bytes / 2, before.current_bytes)
      << "the spare capacity (" << spare_bytes << " bytes) stayed resident";
}

}  // namespace
}  // namespace wavetrace
