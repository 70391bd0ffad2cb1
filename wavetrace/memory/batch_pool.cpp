// Batch recycling through a concurrent free list.
#include "wavetrace/memory/batch_pool.hpp"

namespace wavetrace {

BatchPool::BatchPool(std::size_t batch_capacity) : batch_capacity_(batch_capacity) {}

BatchPool::~BatchPool() = default;

Batch* BatchPool::acquire() {
  Batch* batch = nullptr;
  if (!free_.try_pop(batch)) {
    auto fresh = std::make_unique<Batch>(batch_capacity_);
    batch = fresh.get();
    {
      std::lock_guard lock(owned_mutex_);
      owned_.push_back(std::move(fresh));
    }
    allocated_.fetch_add(1, std::memory_order_relaxed);
  }
  batch->rays.count = 0;
  return batch;
}

void BatchPool::release(Batch* batch) { free_.push(batch); }

}  // namespace wavetrace
