// Data mode's deal: a chunked world's chunks cut into one run of consecutive chunks a rank
// (chunks follow the scene's order, so a run is a region), the heaviest run as light as it
// can be: the linear partition problem, solved exactly.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

namespace wavetrace {

// The rank owning each chunk: `ranks` runs in order (rank 0 first), the largest run weight
// the least any such cut allows; among cuts that reach it, each run as long as that bound
// lets it be, so the deal is the same on every rank. Every rank owns a chunk where there
// are at least as many chunks as ranks. ranks > 0.
std::vector<int> deal_chunk_runs(std::span<const std::uint64_t> weights, int ranks);

}  // namespace wavetrace
