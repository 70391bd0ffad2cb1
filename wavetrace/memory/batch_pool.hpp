// A thread-safe buffer of batches: stages take empty batches from it and give spent ones
// back, so steady-state rendering allocates nothing.
#pragma once

#include <atomic>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include <tbb/concurrent_queue.h>

#include "wavetrace/memory/ray_batch.hpp"

namespace wavetrace {

class BatchPool {
 public:
  explicit BatchPool(std::size_t batch_capacity = kDefaultBatchCapacity);
  ~BatchPool();
  BatchPool(const BatchPool&) = delete;
  BatchPool& operator=(const BatchPool&) = delete;

  std::size_t batch_capacity() const { return batch_capacity_; }

  // An empty batch (count 0) owned by the caller until released.
  Batch* acquire();
  void release(Batch* batch);

  // Batches ever allocated: the pool's high-water mark, for memory reports.
  std::size_t allocated() const { return allocated_.load(std::memory_order_relaxed); }

 private:
  std::size_t batch_capacity_;
  tbb::concurrent_queue<Batch*> free_;
  std::atomic<std::size_t> allocated_{0};
  std::mutex owned_mutex_;  // taken only when the pool grows
  std::vector<std::unique_ptr<Batch>> owned_;
};

}  // namespace wavetrace
