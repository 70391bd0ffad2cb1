// The least bound on a run's weight that `ranks` runs can keep is found by bisection (greedy
// packing from the left needs the fewest runs for a bound), then the runs are cut greedily.
#include "wavetrace/distribute/chunk_deal.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace wavetrace {
namespace {

// The runs greedy packing under `bound` cuts `weights` into (bound >= every weight).
std::size_t runs_within(std::span<const std::uint64_t> weights, std::uint64_t bound) {
  std::size_t runs = 1;
  std::uint64_t run = 0;
  for (const std::uint64_t weight : weights) {
    if (run + weight > bound) {
      ++runs;
      run = 0;
    }
    run += weight;
  }
  return runs;
}

}  // namespace

std::vector<int> deal_chunk_runs(std::span<const std::uint64_t> weights, int ranks) {
  if (ranks <= 0) throw std::invalid_argument("deal_chunk_runs: no ranks to deal to");
  std::vector<int> owner(weights.size(), 0);
  if (weights.empty()) return owner;
  std::uint64_t low = *std::max_element(weights.begin(), weights.end());
  std::uint64_t high = std::accumulate(weights.begin(), weights.end(), std::uint64_t{0});
  while (low < high) {  // the least bound within which `ranks` runs suffice
    const std::uint64_t middle = low + (high - low) / 2;
    if (runs_within(weights, middle) <= std::size_t(ranks)) {
      high = middle;
    } else {
      low = middle + 1;
    }
  }
  // Greedy under the bound, moving on early where the chunks left are no more than the ranks
  // after this one: each then takes one, and no run grows past the bound.
  int rank = 0;
  std::uint64_t run = 0;
  for (std::size_t c = 0; c < weights.size(); ++c) {
    const std::size_t chunks_left = weights.size() - c;
    if (c > 0 && (run + weights[c] > low || chunks_left <= std::size_t(ranks - 1 - rank))) {
      ++rank;
      run = 0;
    }
    owner[c] = rank;
    run += weights[c];
  }
  return owner;
}

}  // namespace wavetrace
