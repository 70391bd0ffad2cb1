// The stage chain on a tbb::flow::graph. The building blocks (PipelineContext and the
// node factories) are public so a C++ user can wire the same stage objects by hand;
// Pipeline assembles the chain a config names.
//
// Flow control: the context counts the rays alive in the graph. The generate node emits
// camera batches only while that count stays under the in-flight budget over the chain's
// fan-out (the most rays one ray can become at a stage: a bounce and a light sample, or a
// gather's rays), give or take a batch per thread generating at once, so that the rays its
// batches become stay within the budget; every node that retires rays wakes it, so memory
// stays bounded and the graph drains by itself. A buffering stage (zsort, repack)
// holds rays until it is ready or holds every live ray; whoever sees the latter last (its
// node after taking a batch, or a node after retiring) makes it flush.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include <tbb/flow_graph.h>

#include "wavetrace/memory/batch_pool.hpp"
#include "wavetrace/memory/process_cpu.hpp"
#include "wavetrace/stages/generate.hpp"
#include "wavetrace/pipeline/progress_reporter.hpp"
#include "wavetrace/stages/stage.hpp"
#include "wavetrace/pipeline/stage_counters.hpp"
#include "wavetrace/stages/buffering_stage.hpp"

namespace wavetrace {

using BatchNode = tbb::flow::multifunction_node<Batch*, std::tuple<Batch*>>;
using GenerateNode = tbb::flow::multifunction_node<tbb::flow::continue_msg, std::tuple<Batch*>>;

class PipelineContext {
 public:
  // Batches come from `shared_pool` where given (its capacity must be batch_capacity), else
  // from a pool of the context's own.
  // Each ray a source emits may become `rays_per_source_ray` rays at once.
  PipelineContext(std::size_t batch_capacity, std::size_t rays_in_flight, BatchPool* shared_pool = nullptr,
                  std::size_t rays_per_source_ray = 1);

  BatchPool& pool() { return *pool_; }
  std::int64_t live_rays() const { return live_rays_.load(std::memory_order_acquire); }
  // Live rays in memory: all but those a buffer holds on disk. The flight budget bounds these.
  std::int64_t in_core_rays() const {
    return live_rays() - (buffer_stage_ != nullptr ? std::int64_t(buffer_stage_->spilled_rays()) : 0);
  }
  std::size_t budget() const { return budget_; }
  // The in-core rays under which a source (generate, a draining disk buffer) may emit more:
  // the budget over what each of its rays may become.
  std::size_t source_budget() const { return source_budget_; }
  // The most rays alive in memory at once so far.
  std::int64_t peak_in_core_rays() const { return peak_in_core_rays_.load(std::memory_order_relaxed); }
  // Lets the generator run on if the budget has room (after a buffer moved rays to disk).
  void wake_generator();

  // Rays entering the graph (made by generate or spawn).
  void add_rays(std::size_t count);
  // Rays leaving it; wakes the generator when there is room for another batch.
  void retire_rays(std::size_t count);

  void attach_generator(GenerateNode* node, const RaySource* stage) {
    generator_node_ = node;
    generator_stage_ = stage;
  }
  // The buffering node is poked (sent a null batch) when every live ray is waiting in its
  // stage, since then nothing else will arrive to make it flush.
  void attach_buffer(BatchNode* node, const BufferingStage* stage) {
    buffer_node_ = node;
    buffer_stage_ = stage;
  }

 private:
  std::optional<BatchPool> own_pool_;
  BatchPool* pool_;
  std::size_t budget_;
  std::size_t source_budget_;
  std::atomic<std::int64_t> live_rays_{0};
  std::atomic<std::int64_t> peak_in_core_rays_{0};
  GenerateNode* generator_node_ = nullptr;
  const RaySource* generator_stage_ = nullptr;
  BatchNode* buffer_node_ = nullptr;
  const BufferingStage* buffer_stage_ = nullptr;
};

// The node that emits camera batches while the in-flight budget allows, any number of
// them filled at once; start it with try_put(continue_msg()).
std::unique_ptr<GenerateNode> make_generate_node(tbb::flow::graph& graph, RaySource& stage,
                                                 PipelineContext& context, StageCounters& counters);

// How a buffering stage's batches reach the next stage in the order it emitted them. A
// flush emits hundreds of batches at once; as flow-graph messages each becomes a task, and
// the emitting thread runs its tasks last in, first out while other threads steal them
// first in, first out: the threads would walk a sorted stream from its two ends, each with a
// working set of its own (with a world paged from disk, room:8M at 24%, 35% more page reads
// on two threads). So the buffering node queues each batch here and sends the next node a
// message that only stands for one: whichever task runs next takes the oldest batch.
class OrderedHandOff {
 public:
  void push(Batch* batch);
  Batch* pop();  // one batch was pushed for every message sent, so there is always one

  // For the next stage's look-ahead (Stage::look_ahead_batches): waits for the oldest batch
  // this reader has not seen among the first `depth` in the queue (the next to be popped is
  // the first), hands it to `copy` under the lock (a queued batch is no one's to change) and
  // returns true; returns false once closed.
  bool next_ahead(std::size_t depth, const std::function<void(const Batch&)>& copy);
  void close();  // the graph is done: a waiting reader returns

 private:
  std::mutex mutex_;
  std::condition_variable changed_;
  std::deque<Batch*> queue_;
  std::uint64_t popped_ = 0;  // batches taken so far
  std::uint64_t seen_ = 0;    // the look-ahead's next batch, counted from the first pushed
  bool closed_ = false;
};

// Calls of a stage running at once beyond one a thread: those suspended (a data-mode rank's
// trace waiting for answers); more wait in the node's queue.
inline constexpr std::size_t kSuspendedCallsPerStage = 32;

// A node running `stage` on up to the arena's threads plus kSuspendedCallsPerStage batches at
// once. With `hand_off`, each message stands for the oldest batch in it.
std::unique_ptr<BatchNode> make_stage_node(tbb::flow::graph& graph, const Stage& stage, PipelineContext& context,
                                           StageCounters& counters, OrderedHandOff* hand_off = nullptr);

// The serial node of a buffering stage (zsort, repack): hands it each batch and flushes it
// when it holds every live ray; a null batch is a poke to re-check. One per pipeline. With
// `hand_off`, what it emits goes there in order (the next node made with the same hand-off).
std::unique_ptr<BatchNode> make_buffering_node(tbb::flow::graph& graph, const BufferingStage& stage,
                                               PipelineContext& context, StageCounters& counters,
                                               OrderedHandOff* hand_off = nullptr);

// A node that ends every batch it receives (for chains without spawn).
std::unique_ptr<tbb::flow::function_node<Batch*>> make_retire_node(tbb::flow::graph& graph,
                                                                   PipelineContext& context);

// How paths are run: batches through the stage graph, or one path at a time per worker.
enum class PipelineMode { wavefront, megakernel };
PipelineMode parse_pipeline_mode(const std::string& text);
std::string to_string(PipelineMode mode);

// Rays per batch of a render: a batch and its hits (~100 KB) stay in L2 between stages.
// render.batch_size's default; the benches' ray sets use kDefaultBatchCapacity.
inline constexpr std::size_t kPipelineBatchSize = 1024;

struct PipelineOptions {
  PipelineMode mode = PipelineMode::wavefront;
  std::uint32_t tile_side = 16;  // megakernel tiles
  std::size_t batch_size = kPipelineBatchSize;
  std::size_t rays_in_flight = std::size_t{1} << 18;
  int threads = 0;  // 0: all cores
  bool operator==(const PipelineOptions&) const = default;
};

struct PipelineRun {
  std::vector<StageStats> stages;  // generate first, then the chain in order
  double seconds = 0.0;            // wall time of the whole run
  int threads = 0;
  std::size_t batches_allocated = 0;
  std::size_t peak_rays_in_core = 0;  // the most rays alive in memory at once
  // The process's CPU over the run, every thread of it (the arena's, a stage's readers ahead,
  // a data-parallel rank's exchange): against seconds x threads, how busy the cores were.
  ProcessCpuTime cpu;
};

class Pipeline {
 public:
  // `chain` is everything after generate, in order. If `loops` is set, the last stage's
  // output goes back to the first (spawn feeding new rays into the chain).
  // `generate` makes the chain's new rays: camera rays, or photons for a photon map.
  // `shared_pool`, if given, lends the batches and outlives the pipeline: the passes of one
  // render (photon mapping's two) then reuse memory already touched instead of faulting in
  // fresh pages, which cost the camera pass's zsort two thirds of its gather.
  Pipeline(RaySource& generate, std::vector<const Stage*> chain, bool loops, const PipelineOptions& options,
           BatchPool* shared_pool = nullptr);

  // Runs until every ray has finished. `on_progress`, if given, is called about every
  // `interval` from a helper thread.
  PipelineRun run(const std::function<void(const Progress&)>& on_progress = {},
                  std::chrono::milliseconds interval = std::chrono::milliseconds(250));

 private:
  RaySource& generate_;
  std::vector<const Stage*> chain_;
  bool loops_;
  PipelineOptions options_;
  BatchPool* shared_pool_;
};

}  // namespace wavetrace
