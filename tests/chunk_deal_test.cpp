// Data mode's deal of chunks to ranks: runs in order, the heaviest as light as any cut allows.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "wavetrace/distribute/chunk_deal.hpp"

namespace wavetrace {
namespace {

std::uint64_t heaviest_run(const std::vector<std::uint64_t>& weights, const std::vector<int>& owner, int ranks) {
  std::vector<std::uint64_t> runs(std::size_t(ranks), 0);
  for (std::size_t c = 0; c < weights.size(); ++c) runs[std::size_t(owner[c])] += weights[c];
  return *std::max_element(runs.begin(), runs.end());
}

// The least heaviest run over every cut into at most `ranks` runs, by trying them all.
std::uint64_t least_heaviest_by_search(const std::vector<std::uint64_t>& weights, std::size_t from, int ranks) {
  if (from == weights.size()) return 0;
  std::uint64_t run = 0;
  std::uint64_t best = UINT64_MAX;
  for (std::size_t end = from; end < weights.size(); ++end) {
    run += weights[end];
    if (ranks == 1 && end + 1 < weights.size()) continue;
    best = std::min(best, std::max(run, least_heaviest_by_search(weights, end + 1, ranks - 1)));
  }
  return best;
}

TEST(ChunkDeal, TheHeaviestRunIsTheLeastAnyCutAllows) {
  std::mt19937_64 random(7);
  for (int trial = 0; trial < 400; ++trial) {
    const std::size_t chunks = 1 + random() % 9;
    const int ranks = 1 + int(random() % 5);
    std::vector<std::uint64_t> weights(chunks);
    for (std::uint64_t& weight : weights) weight = random() % (trial % 3 == 0 ? 4 : 1000);  // zeros and ties too
    const std::vector<int> owner = deal_chunk_runs(weights, ranks);
    ASSERT_EQ(owner.size(), chunks);
    // Runs in order, from rank 0, one rank after another.
    EXPECT_EQ(owner[0], 0);
    for (std::size_t c = 1; c < chunks; ++c) EXPECT_TRUE(owner[c] == owner[c - 1] || owner[c] == owner[c - 1] + 1);
    EXPECT_LT(owner.back(), ranks);
    // Every rank a chunk where there are enough of them.
    EXPECT_EQ(owner.back(), std::min<int>(ranks, int(chunks)) - 1) << "trial " << trial;
    EXPECT_EQ(heaviest_run(weights, owner, ranks), least_heaviest_by_search(weights, 0, ranks)) << "trial " << trial;
  }
}

// Where the earlier deal (each chunk to the rank its weight's middle falls in) gave one rank
// 110 and another nothing: 20, 80, 90, 20 over three ranks.
TEST(ChunkDeal, CutsWhereTheHeaviestRunIsLightest) {
  const std::vector<std::uint64_t> weights = {20, 80, 90, 20};
  EXPECT_EQ(deal_chunk_runs(weights, 3), (std::vector<int>{0, 0, 1, 2}));  // 100, 90, 20
  EXPECT_EQ(deal_chunk_runs(weights, 2), (std::vector<int>{0, 0, 1, 1}));  // 100 and 110
  EXPECT_EQ(deal_chunk_runs(weights, 6), (std::vector<int>{0, 1, 2, 3}));  // more ranks than chunks
  EXPECT_EQ(deal_chunk_runs({}, 3), std::vector<int>{});
  EXPECT_THROW(deal_chunk_runs(weights, 0), std::invalid_argument);
}

}  // namespace
}  // namespace wavetrace
