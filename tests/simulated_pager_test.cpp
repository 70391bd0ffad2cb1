// The pager: hand-computed LRU faults, budgets, I/O time, agreement with a reference LRU on
// a random trace, and thread safety.
#include <gtest/gtest.h>

#include <list>
#include <thread>
#include <unordered_map>

#include "wavetrace/kernels/random.hpp"
#include "wavetrace/memory/memory_probe.hpp"
#include "wavetrace/memory/simulated_pager.hpp"

namespace wavetrace {
namespace {

constexpr std::size_t kPage = 4096;

TEST(SimulatedPager, FaultsFollowLeastRecentlyUsedEviction) {
  std::vector<std::byte> world(4 * kPage);
  MemoryBudget budget;
  budget.is_share = false;
  budget.bytes = 2 * kPage;
  SimulatedPager pager({world}, kPage, budget, io_preset("disk"));
  ASSERT_EQ(pager.page_count(), 4u);
  ASSERT_EQ(pager.budget_pages(), 2u);
  const auto read = [&](int page) { pager.touch(pager.page_of(world.data() + page * kPage + 7), 0); };
  read(0);  // fault
  read(1);  // fault
  read(0);  // hit; 1 is now least recent
  read(2);  // fault, evicts 1
  read(0);  // hit
  read(1);  // fault, evicts 2
  read(2);  // fault, evicts 0
  const PagerCounters counters = pager.counters(0);
  EXPECT_EQ(counters.accesses, 7u);
  EXPECT_EQ(counters.faults, 5u);
  EXPECT_EQ(counters.bytes_loaded, 5 * kPage);
  EXPECT_DOUBLE_EQ(counters.simulated_io_seconds, 5 * 8e-3 + 5.0 * kPage / 101e6);
}

TEST(SimulatedPager, SpansArePagedFromTheirStartAndShortLastPagesLoadTheirSize) {
  std::vector<std::byte> a(kPage + 100), b(10);
  SimulatedPager pager({b, a}, kPage, MemoryBudget{}, io_preset("nvme"));
  EXPECT_EQ(pager.page_count(), 3u);
  EXPECT_EQ(pager.world_bytes(), kPage + 110);
  EXPECT_EQ(pager.budget_pages(), 3u);  // 100% holds every page, short ones included
  EXPECT_EQ(pager.page_of(a.data() + kPage - 1) + 1, pager.page_of(a.data() + kPage));
  EXPECT_EQ(pager.page_of(a.data() + a.size()), SimulatedPager::kNoPage);
  pager.touch(pager.page_of(a.data() + kPage + 5), 0);
  pager.touch(pager.page_of(b.data()), 0);
  EXPECT_EQ(pager.counters(0).bytes_loaded, 110u);
  pager.touch(SimulatedPager::kNoPage, 0);
  EXPECT_EQ(pager.outside_accesses(), 1u);
}

TEST(SimulatedPager, BudgetsParseAsSharesOrSizes) {
  EXPECT_DOUBLE_EQ(parse_memory_budget("20%").share, 0.2);
  EXPECT_TRUE(parse_memory_budget("20%").is_share);
  EXPECT_EQ(parse_memory_budget("512MiB").bytes, 512u << 20);
  EXPECT_EQ(parse_memory_budget("1.5GB").bytes, 1500000000u);
  EXPECT_EQ(parse_memory_budget("4096").bytes, 4096u);
  // The last: a size past any machine (a fuzz finding: its conversion to bytes was undefined).
  for (const char* bad : {"0%", "150%", "-1", "abc", "", "12parsecs", "nan%", "1888888888888888888888888888888888B"}) {
    EXPECT_THROW(parse_memory_budget(bad), std::invalid_argument) << bad;
  }
  std::vector<std::byte> world(10 * kPage);
  EXPECT_EQ(SimulatedPager({world}, kPage, parse_memory_budget("20%"), io_preset("disk")).budget_pages(), 2u);
  EXPECT_EQ(SimulatedPager({world}, kPage, parse_memory_budget("25%"), io_preset("disk")).budget_pages(), 3u);  // rounded up
  EXPECT_EQ(SimulatedPager({world}, kPage, parse_memory_budget("100"), io_preset("disk")).budget_pages(), 1u);  // at least one
  EXPECT_THROW(SimulatedPager({world}, 5000, MemoryBudget{}, io_preset("disk")), std::invalid_argument);
  EXPECT_THROW(io_preset("floppy"), std::invalid_argument);
}

// A textbook LRU over a linked list and a map, to check the pager against.
std::uint64_t reference_lru_faults(const std::vector<std::uint32_t>& trace, std::size_t capacity) {
  std::list<std::uint32_t> order;
  std::unordered_map<std::uint32_t, std::list<std::uint32_t>::iterator> where;
  std::uint64_t faults = 0;
  for (std::uint32_t page : trace) {
    if (auto found = where.find(page); found != where.end()) {
      order.erase(found->second);
    } else {
      ++faults;
      if (order.size() == capacity) {
        where.erase(order.back());
        order.pop_back();
      }
    }
    order.push_front(page);
    where[page] = order.begin();
  }
  return faults;
}

TEST(SimulatedPager, MatchesAReferenceLruOnARandomTraceAndProbesAgree) {
  std::vector<std::byte> world(64 * kPage);
  std::vector<std::uint32_t> trace;
  std::vector<std::size_t> offsets;
  for (std::uint32_t i = 0; i < 20000; ++i) {
    // Skewed toward low pages, with runs of repeats, as traversal is.
    const std::uint32_t bits = random_bits(i, 0, 0, RandomPurpose::benchmark);
    const std::size_t offset = std::size_t(bits % (64 * kPage)) * (bits % 3 == 0 ? 1 : (bits % 7 + 1)) / 8;
    offsets.push_back(offset);
    trace.push_back(static_cast<std::uint32_t>(offset / kPage));
  }
  for (std::size_t capacity : {1u, 3u, 8u, 20u, 64u}) {
    MemoryBudget budget;
    budget.is_share = false;
    budget.bytes = capacity * kPage;
    SimulatedPager direct({world}, kPage, budget, io_preset("disk"));
    for (std::size_t offset : offsets) direct.touch(direct.page_of(world.data() + offset), 0);
    EXPECT_EQ(direct.counters(0).faults, reference_lru_faults(trace, capacity)) << capacity << " pages";
    // A probe skips the LRU update for repeated pages of its thread: the same counts.
    SimulatedPager probed({world}, kPage, budget, io_preset("disk"));
    {
      RecordingProbe probe(MemoryObservers{&probed, nullptr}, 0, 0);
      for (std::size_t offset : offsets) probe.read(world.data() + offset, 1);
    }
    EXPECT_EQ(probed.counters(0).faults, direct.counters(0).faults);
    EXPECT_EQ(probed.counters(0).accesses, offsets.size());
  }
}

TEST(SimulatedPager, ProbeReadAcrossAPageBoundaryTouchesBothPages) {
  std::vector<std::byte> world(4 * kPage);
  SimulatedPager pager({world}, kPage, MemoryBudget{}, io_preset("disk"));
  {
    RecordingProbe probe(MemoryObservers{&pager, nullptr}, 0, 0);
    probe.read(world.data() + kPage - 4, 8);
  }
  EXPECT_EQ(pager.counters(0).faults, 2u);
  EXPECT_EQ(pager.counters(0).accesses, 2u);
}

TEST(SimulatedPager, ThreadsCountEveryAccessAndClientsApart) {
  std::vector<std::byte> world(32 * kPage);
  SimulatedPager pager({world}, kPage, parse_memory_budget("50%"), io_preset("disk"), 2);
  std::vector<std::thread> threads;
  for (std::size_t t = 0; t < 4; ++t) {
    threads.emplace_back([&, t] {
      for (std::uint32_t i = 0; i < 50000; ++i) {
        const std::uint32_t bits = random_bits(i, std::uint32_t(t), 0, RandomPurpose::benchmark);
        pager.touch(pager.page_of(world.data() + bits % world.size()), t % 2);
      }
    });
  }
  for (std::thread& thread : threads) thread.join();
  EXPECT_EQ(pager.counters(0).accesses, 100000u);
  EXPECT_EQ(pager.counters(1).accesses, 100000u);
  EXPECT_EQ(pager.total().accesses, 200000u);
  // Uniform accesses to 32 pages through a pool of 16: in steady state a page is resident
  // with probability 16/32 whatever the interleaving, so about half the accesses fault.
  const double fault_rate = double(pager.total().faults) / double(pager.total().accesses);
  EXPECT_NEAR(fault_rate, 0.5, 0.02);
  EXPECT_EQ(pager.total().bytes_loaded, pager.total().faults * kPage);
}

}  // namespace
}  // namespace wavetrace
