// Set lookup by line number modulo the set count; within a set a linear scan of the ways,
// replacing the one used longest ago.
#include "wavetrace/memory/cache_simulator.hpp"

#include <bit>
#include <stdexcept>

namespace wavetrace {

CacheGeometry cache_preset(std::string_view name) {
  if (name == "paper_l2") return {"paper_l2", 64, 6u << 20, 24};
  if (name == "l1d") return {"l1d", 64, 32u << 10, 8};
  if (name == "l2") return {"l2", 64, 512u << 10, 8};
  throw std::invalid_argument("unknown cache preset '" + std::string(name) + "' (known: paper_l2, l1d, l2)");
}

void validate_cache_geometry(const CacheGeometry& geometry) {
  if (!std::has_single_bit(geometry.line_bytes) || geometry.line_bytes < 4 || geometry.line_bytes > 4096) {
    throw std::invalid_argument("cache line of " + std::to_string(geometry.line_bytes) +
                                " bytes: must be a power of two from 4 to 4096");
  }
  if (geometry.ways == 0 || geometry.ways > 256 || geometry.sets() == 0 ||
      geometry.capacity_bytes != geometry.sets() * geometry.ways * geometry.line_bytes) {
    throw std::invalid_argument("cache of " + std::to_string(geometry.capacity_bytes) + " bytes, " +
                                std::to_string(geometry.ways) + " ways and " + std::to_string(geometry.line_bytes) +
                                "-byte lines: capacity must be a whole, non-zero number of sets (ways 1-256)");
  }
}

CacheSimulator::CacheSimulator(const CacheGeometry& geometry, std::size_t clients)
    : geometry_(geometry), counters_(std::max<std::size_t>(clients, 1)) {
  validate_cache_geometry(geometry);
  line_shift_ = static_cast<unsigned>(std::countr_zero(geometry.line_bytes));
  sets_ = geometry.sets();
  tags_.assign(sets_ * geometry.ways, 0);
  last_use_.assign(sets_ * geometry.ways, 0);
}

void CacheSimulator::access_line(std::uintptr_t line, std::size_t client) {
  CacheCounters& counters = counters_[client];
  ++counters.accesses;
  ++clock_;
  const std::size_t base = (line % sets_) * geometry_.ways;
  const std::uintptr_t tag = line + 1;
  std::size_t victim = base;
  for (std::size_t way = base; way < base + geometry_.ways; ++way) {
    if (tags_[way] == tag) {
      last_use_[way] = clock_;
      return;
    }
    if (last_use_[way] < last_use_[victim]) victim = way;  // empty ways have stamp 0: filled first
  }
  ++counters.misses;
  tags_[victim] = tag;
  last_use_[victim] = clock_;
}

CacheBank::CacheBank(const CacheGeometry& geometry, std::size_t threads, std::size_t clients) {
  for (std::size_t t = 0; t < std::max<std::size_t>(threads, 1); ++t) {
    caches_.push_back(std::make_unique<CacheSimulator>(geometry, clients));
  }
}

CacheCounters CacheBank::total(std::size_t client) const {
  CacheCounters sum;
  for (const auto& cache : caches_) {
    sum.accesses += cache->counters(client).accesses;
    sum.misses += cache->counters(client).misses;
  }
  return sum;
}

}  // namespace wavetrace
