// A StageOutput for driving one stage by hand: it keeps what the stage emits and lends
// batches from a pool.
#pragma once

#include <vector>

#include "wavetrace/memory/batch_pool.hpp"
#include "wavetrace/stages/stage.hpp"

namespace wavetrace::testing {

class CollectingOutput final : public StageOutput {
 public:
  explicit CollectingOutput(BatchPool& pool) : pool_(pool) {}
  void emit(Batch* batch) override { emitted.push_back(batch); }
  Batch* acquire() override { return pool_.acquire(); }
  void release(Batch* batch) override {
    ++released;
    pool_.release(batch);
  }
  std::vector<Batch*> emitted;
  std::size_t released = 0;

 private:
  BatchPool& pool_;
};

}  // namespace wavetrace::testing
