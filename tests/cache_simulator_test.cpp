// The set-associative LRU cache against miss counts computed by hand.
#include <gtest/gtest.h>

#include <vector>

#include "wavetrace/memory/cache_simulator.hpp"

namespace wavetrace {
namespace {

// Addresses start at a line-aligned base so line counts are exact.
struct Memory {
  explicit Memory(std::size_t bytes) : storage(bytes + 4096) {}
  const std::byte* at(std::size_t offset) const {
    const auto base = (reinterpret_cast<std::uintptr_t>(storage.data()) + 4095) & ~std::uintptr_t{4095};
    return reinterpret_cast<const std::byte*>(base + offset);
  }
  std::vector<std::byte> storage;
};

TEST(CacheSimulator, PresetsHaveThePapersAndThisMachinesGeometry) {
  EXPECT_EQ(cache_preset("paper_l2").capacity_bytes, 6u << 20);
  EXPECT_EQ(cache_preset("paper_l2").ways, 24u);
  EXPECT_EQ(cache_preset("paper_l2").sets(), 4096u);
  EXPECT_EQ(cache_preset("l1d").sets(), 64u);
  EXPECT_EQ(cache_preset("l2").sets(), 1024u);
  EXPECT_THROW(cache_preset("l3"), std::invalid_argument);
  EXPECT_THROW(validate_cache_geometry({"bad", 48, 4096, 4}), std::invalid_argument);    // line not a power of two
  EXPECT_THROW(validate_cache_geometry({"bad", 64, 1000, 4}), std::invalid_argument);    // not whole sets
  EXPECT_THROW(validate_cache_geometry({"bad", 64, 4096, 0}), std::invalid_argument);    // no ways
}

TEST(CacheSimulator, SequentialReadsMissOncePerLineAndRereadsHitWhileTheyFit) {
  const CacheGeometry l1 = cache_preset("l1d");  // 32 KiB
  Memory memory(64 << 10);
  CacheSimulator cache(l1);
  for (std::size_t offset = 0; offset < (16 << 10); offset += 4) cache.access(memory.at(offset), 4, 0);
  EXPECT_EQ(cache.counters(0).accesses, (16u << 10) / 4);
  EXPECT_EQ(cache.counters(0).misses, (16u << 10) / 64);
  for (std::size_t offset = 0; offset < (16 << 10); offset += 64) cache.access(memory.at(offset), 64, 0);
  EXPECT_EQ(cache.counters(0).misses, (16u << 10) / 64);  // all still resident
  // Sweeping twice the capacity in order evicts each line before it comes back: LRU misses all.
  CacheSimulator sweep(l1);
  for (int pass = 0; pass < 2; ++pass) {
    for (std::size_t offset = 0; offset < (64 << 10); offset += 64) sweep.access(memory.at(offset), 64, 0);
  }
  EXPECT_EQ(sweep.counters(0).misses, 2u * (64 << 10) / 64);
}

TEST(CacheSimulator, StridedReadsIntoOneSetThrashBeyondTheWays) {
  const CacheGeometry geometry{"test", 64, 64 * 4 * 16, 4};  // 16 sets of 4 ways
  const std::size_t stride = 64 * 16;                       // every address maps to set 0
  Memory memory(stride * 8);
  CacheSimulator fits(geometry);
  for (int round = 0; round < 10; ++round) {
    for (std::size_t k = 0; k < 4; ++k) fits.access(memory.at(k * stride), 8, 0);
  }
  EXPECT_EQ(fits.counters(0).misses, 4u);  // compulsory only
  CacheSimulator thrashes(geometry);
  for (int round = 0; round < 10; ++round) {
    for (std::size_t k = 0; k < 5; ++k) thrashes.access(memory.at(k * stride), 8, 0);
  }
  EXPECT_EQ(thrashes.counters(0).misses, 50u);  // five lines cycling through four ways: LRU always evicts the next
  // Lines in other sets do not conflict with set 0.
  CacheSimulator spread(geometry);
  for (int round = 0; round < 10; ++round) {
    for (std::size_t k = 0; k < 5; ++k) spread.access(memory.at(k * 64), 8, 0);
  }
  EXPECT_EQ(spread.counters(0).misses, 5u);
}

TEST(CacheSimulator, ReadsSpanningTwoLinesCountTwoAndClientsAreApart) {
  CacheSimulator cache(cache_preset("l1d"), 2);
  Memory memory(256);
  cache.access(memory.at(60), 8, 0);
  EXPECT_EQ(cache.counters(0).accesses, 2u);
  EXPECT_EQ(cache.counters(0).misses, 2u);
  cache.access(memory.at(0), 4, 1);
  EXPECT_EQ(cache.counters(1).accesses, 1u);
  EXPECT_EQ(cache.counters(1).misses, 0u);  // the line is shared; only the counts are apart
  CacheBank bank(cache_preset("l1d"), 2);
  bank.for_thread(0).access(memory.at(0), 4, 0);
  bank.for_thread(1).access(memory.at(0), 4, 0);
  EXPECT_EQ(bank.total(0).misses, 2u);  // per-core caches: each thread misses once
}

}  // namespace
}  // namespace wavetrace
