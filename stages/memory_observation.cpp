// memory.* keys to a pager and caches, and their counters into the stage statistics.
#include "stages/memory_observation.hpp"

#include <bit>
#include <stdexcept>

#include <fmt/format.h>

namespace wavetrace {

MemoryPlan plan_memory(const Config& config) {
  MemoryPlan plan;
  const std::string budget = config.text("memory.budget");
  try {
    if (budget != "none") plan.budget = parse_memory_budget(budget);
  } catch (const std::invalid_argument& error) {
    throw ConfigError(fmt::format("memory.budget: {}", error.what()));
  }
  plan.page_bytes = static_cast<std::size_t>(config.integer("memory.page_bytes"));
  if (!std::has_single_bit(plan.page_bytes)) {
    throw ConfigError(fmt::format("memory.page_bytes = {} is not a power of two", plan.page_bytes));
  }
  plan.io = io_preset(config.text("memory.io"));
  plan.file_backing = config.text("memory.backing") == "file";
  if (plan.file_backing && !plan.budget) {
    throw ConfigError("memory.backing = file pages a world file under memory.budget: set one (for example 20%)");
  }
  const std::string cache = config.text("memory.cache");
  if (cache != "none") {
    CacheGeometry geometry = cache == "custom" ? CacheGeometry{"custom", 64, 0, 0} : cache_preset(cache);
    if (cache == "custom" && !(config.has("memory.cache_bytes") && config.has("memory.cache_ways"))) {
      throw ConfigError("memory.cache = 'custom' needs memory.cache_bytes and memory.cache_ways");
    }
    if (config.has("memory.cache_line_bytes")) geometry.line_bytes = std::size_t(config.integer("memory.cache_line_bytes"));
    if (config.has("memory.cache_bytes")) geometry.capacity_bytes = std::size_t(config.integer("memory.cache_bytes"));
    if (config.has("memory.cache_ways")) geometry.ways = std::size_t(config.integer("memory.cache_ways"));
    try {
      validate_cache_geometry(geometry);
    } catch (const std::invalid_argument& error) {
      throw ConfigError(fmt::format("memory.cache: {}", error.what()));
    }
    plan.cache = geometry;
  }
  return plan;
}

std::string to_string(ObservedStage stage) { return stage == ObservedStage::trace ? "trace" : "approx_hit"; }

MemoryObservation::MemoryObservation(const MemoryPlan& plan, std::vector<std::span<const std::byte>> world,
                                     int threads, FilePager* file_pager)
    : file_pager_(file_pager) {
  if (file_pager_ != nullptr) file_pager_->reset();
  if (plan.budget) {
    pager_ = std::make_unique<Pager>(std::move(world), plan.page_bytes, *plan.budget, plan.io, kObservedStageCount);
  }
  if (plan.cache) caches_ = std::make_unique<CacheBank>(*plan.cache, std::size_t(threads), kObservedStageCount);
  observers_ = {pager_.get(), caches_.get(), file_pager_};
}

void MemoryObservation::report(std::vector<StageStats>& stages) const {
  for (StageStats& stage : stages) {
    for (std::size_t client = 0; client < kObservedStageCount; ++client) {
      if (stage.name != to_string(ObservedStage(client))) continue;
      if (pager_) stage.pager = PagerStats{pager_->page_bytes(), pager_->budget_bytes(), pager_->counters(client)};
      if (caches_) stage.cache = CacheStats{caches_->geometry(), caches_->total(client)};
      if (file_pager_) stage.disk = DiskStats{file_pager_->page_bytes(), file_pager_->budget_bytes(), file_pager_->counters(client)};
    }
  }
}

}  // namespace wavetrace
