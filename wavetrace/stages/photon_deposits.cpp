// Per-thread deposit lists, merged by key.
#include "wavetrace/stages/photon_deposits.hpp"

#include <algorithm>

#include <tbb/parallel_sort.h>

namespace wavetrace {

void PhotonDeposits::add(std::uint64_t key, const Photon& photon, bool caustic) {
  per_thread_.local().push_back({key, photon, caustic});
}

PhotonDeposits::Maps PhotonDeposits::take() {
  LargeArray<Deposit> all;
  std::size_t total = 0;
  for (const auto& list : per_thread_) total += list.size();
  all.reserve(total);
  for (auto& list : per_thread_) {
    all.insert(all.end(), list.begin(), list.end());
    LargeArray<Deposit>().swap(list);
  }
  // Keys are unique, so any sort gives the one order.
  tbb::parallel_sort(all.begin(), all.end(), [](const Deposit& a, const Deposit& b) { return a.key < b.key; });
  Maps maps;
  maps.global.reserve(all.size());
  for (const Deposit& deposit : all) {
    maps.global.push_back(deposit.photon);
    if (deposit.caustic) maps.caustic.push_back(deposit.photon);
  }
  return maps;
}

}  // namespace wavetrace
