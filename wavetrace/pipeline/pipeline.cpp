// Flow-graph nodes around stages, ray accounting, and the threaded run.
#include "wavetrace/pipeline/pipeline.hpp"

#include <algorithm>
#include <exception>
#include <mutex>
#include <optional>
#include <stdexcept>
#include <string>
#include <thread>

#include <tbb/task_arena.h>

#include "wavetrace/pipeline/tracing_arena.hpp"

namespace wavetrace {
namespace {

using Clock = std::chrono::steady_clock;

std::uint64_t nanoseconds_since(Clock::time_point start) {
  return static_cast<std::uint64_t>(std::chrono::duration_cast<std::chrono::nanoseconds>(Clock::now() - start).count());
}

// Routes a stage's output into its node's port, counting rays as they enter the graph
// before they can be seen (and retired) downstream.
class PortOutput final : public StageOutput {
 public:
  PortOutput(PipelineContext& context, BatchNode::output_ports_type& ports) : context_(context), ports_(ports) {}
  void emit(Batch* batch) override {
    emitted_rays += batch->rays.count;
    context_.add_rays(batch->rays.count);
    std::get<0>(ports_).try_put(batch);
  }
  Batch* acquire() override { return context_.pool().acquire(); }
  void release(Batch* batch) override { context_.pool().release(batch); }
  std::size_t emitted_rays = 0;

 private:
  PipelineContext& context_;
  BatchNode::output_ports_type& ports_;
};

}  // namespace

PipelineMode parse_pipeline_mode(const std::string& text) {
  if (text == "wavefront") return PipelineMode::wavefront;
  if (text == "megakernel") return PipelineMode::megakernel;
  throw std::invalid_argument("unknown pipeline mode '" + text + "' (wavefront, megakernel)");
}

std::string to_string(PipelineMode mode) { return mode == PipelineMode::megakernel ? "megakernel" : "wavefront"; }

PipelineContext::PipelineContext(std::size_t batch_capacity, std::size_t rays_in_flight, BatchPool* shared_pool,
                                 std::size_t rays_per_source_ray)
    : pool_(shared_pool),
      budget_(std::max(rays_in_flight, 2 * batch_capacity)),
      source_budget_(std::max(budget_ / std::max<std::size_t>(rays_per_source_ray, 1), 2 * batch_capacity)) {
  if (pool_ == nullptr) {
    pool_ = &own_pool_.emplace(batch_capacity);
  } else if (pool_->batch_capacity() != batch_capacity) {
    throw std::logic_error("a shared batch pool's capacity differs from the pipeline's batch size");
  }
}

void PipelineContext::add_rays(std::size_t count) {
  live_rays_.fetch_add(std::int64_t(count), std::memory_order_acq_rel);
  const std::int64_t now = in_core_rays();
  std::int64_t peak = peak_in_core_rays_.load(std::memory_order_relaxed);
  while (now > peak && !peak_in_core_rays_.compare_exchange_weak(peak, now, std::memory_order_relaxed)) {
  }
}

void PipelineContext::retire_rays(std::size_t count) {
  const std::int64_t now = live_rays_.fetch_sub(std::int64_t(count), std::memory_order_seq_cst) - std::int64_t(count);
  if (buffer_node_ != nullptr) {
    const auto waiting = std::int64_t(buffer_stage_->buffered_rays());
    if (waiting > 0 && now <= waiting) buffer_node_->try_put(nullptr);
    // A draining disk buffer emits more as the rays in memory make room.
    if (buffer_stage_->draining() && in_core_rays() < std::int64_t(source_budget_)) buffer_node_->try_put(nullptr);
  }
  wake_generator();
}

void PipelineContext::wake_generator() {
  if (generator_node_ != nullptr && !generator_stage_->exhausted() &&
      in_core_rays() + std::int64_t(pool_->batch_capacity()) <= std::int64_t(source_budget_)) {
    generator_node_->try_put(tbb::flow::continue_msg());
  }
}

std::unique_ptr<GenerateNode> make_generate_node(tbb::flow::graph& graph, RaySource& stage,
                                                 PipelineContext& context, StageCounters& counters) {
  // Any number of bodies at once: each claims its rays (counting them alive first, so the
  // budget sees them) and fills its batch in parallel with the others.
  auto node = std::make_unique<GenerateNode>(
      graph, tbb::flow::unlimited, [&stage, &context, &counters](tbb::flow::continue_msg, GenerateNode::output_ports_type& ports) {
        const std::size_t capacity = context.pool().batch_capacity();
        while (!stage.exhausted() &&
               context.in_core_rays() + std::int64_t(capacity) <= std::int64_t(context.source_budget())) {
          const Clock::time_point start = Clock::now();
          const RaySource::Claim claimed = stage.claim(capacity);
          if (claimed.count == 0) return;
          context.add_rays(claimed.count);
          Batch* batch = context.pool().acquire();
          stage.fill_range(batch->rays, claimed);
          counters.record(0, claimed.count, nanoseconds_since(start));
          std::get<0>(ports).try_put(batch);
        }
      });
  context.attach_generator(node.get(), &stage);
  return node;
}

void OrderedHandOff::push(Batch* batch) {
  {
    std::lock_guard lock(mutex_);
    queue_.push_back(batch);
  }
  changed_.notify_all();
}

Batch* OrderedHandOff::pop() {
  Batch* batch = nullptr;
  {
    std::lock_guard lock(mutex_);
    if (queue_.empty()) throw std::logic_error("an ordered hand-off was asked for a batch it does not hold");
    batch = queue_.front();
    queue_.pop_front();
    ++popped_;
  }
  changed_.notify_all();
  return batch;
}

bool OrderedHandOff::next_ahead(std::size_t depth, const std::function<void(const Batch&)>& copy) {
  std::unique_lock lock(mutex_);
  for (;;) {
    if (closed_) return false;
    // A batch already taken is no longer worth reading ahead: skip to the queue's head.
    seen_ = std::max(seen_, popped_);
    const std::uint64_t place = seen_ - popped_;
    if (place < queue_.size() && place < depth) break;
    changed_.wait(lock);
  }
  copy(*queue_[seen_ - popped_]);
  ++seen_;
  return true;
}

void OrderedHandOff::close() {
  {
    std::lock_guard lock(mutex_);
    closed_ = true;
  }
  changed_.notify_all();
}

std::unique_ptr<BatchNode> make_stage_node(tbb::flow::graph& graph, const Stage& stage, PipelineContext& context,
                                           StageCounters& counters, OrderedHandOff* hand_off) {
  // Calls that never suspend are never more than the threads. A data-mode rank's trace calls
  // suspend while other ranks answer, and unbounded, its one thread started a fresh call
  // whenever one suspended while resumed calls waited behind the fresh ones, each holding a
  // round's scratch: 171-198 calls, 25-29 MB a rank (distributed.md, "Calls a stage runs at once").
  const std::size_t calls_at_once = std::size_t(tbb::this_task_arena::max_concurrency()) + kSuspendedCallsPerStage;
  return std::make_unique<BatchNode>(
      graph, calls_at_once, [&stage, &context, &counters, hand_off](Batch* batch, BatchNode::output_ports_type& ports) {
        if (hand_off != nullptr) batch = hand_off->pop();
        const Clock::time_point start = Clock::now();
        const std::size_t rays_in = batch->rays.count;
        PortOutput out(context, ports);
        stage.process(batch, out);
        counters.record(rays_in, out.emitted_rays, nanoseconds_since(start));
        context.retire_rays(rays_in);
      });
}

namespace {

// A buffering stage's output: its rays are already counted alive, so emitting adds nothing.
class BufferedOutput final : public StageOutput {
 public:
  BufferedOutput(PipelineContext& context, BatchNode::output_ports_type& ports, OrderedHandOff* hand_off)
      : context_(context), ports_(ports), hand_off_(hand_off) {}
  void emit(Batch* batch) override {
    if (hand_off_ != nullptr) hand_off_->push(batch);
    std::get<0>(ports_).try_put(batch);
  }
  Batch* acquire() override { return context_.pool().acquire(); }
  void release(Batch* batch) override { context_.pool().release(batch); }

 private:
  PipelineContext& context_;
  BatchNode::output_ports_type& ports_;
  OrderedHandOff* hand_off_;
};

}  // namespace

std::unique_ptr<BatchNode> make_buffering_node(tbb::flow::graph& graph, const BufferingStage& stage,
                                               PipelineContext& context, StageCounters& counters,
                                               OrderedHandOff* hand_off) {
  auto node = std::make_unique<BatchNode>(
      graph, tbb::flow::serial, [&stage, &context, &counters, hand_off](Batch* batch, BatchNode::output_ports_type& ports) {
        const Clock::time_point start = Clock::now();
        BufferedOutput out(context, ports, hand_off);
        const std::size_t rays_in = batch != nullptr ? batch->rays.count : 0;
        const std::size_t spilled = stage.spilled_rays();
        std::size_t rays_out = batch != nullptr ? stage.take(batch, out) : 0;
        const std::size_t waiting = stage.buffered_rays();
        if (!stage.draining() && waiting > 0 && std::int64_t(waiting) >= context.live_rays()) rays_out += stage.flush(out);
        if (stage.draining()) {
          // Emit the merged stream as far as the budget allows; a retiring ray pokes for more.
          const std::int64_t room = std::int64_t(context.source_budget()) - context.in_core_rays();
          if (room > 0) rays_out += stage.drain(out, std::size_t(room));
        }
        if (stage.spilled_rays() > spilled) context.wake_generator();  // the spilled rays left memory
        if (rays_in > 0 || rays_out > 0) counters.record(rays_in, rays_out, nanoseconds_since(start));
      });
  context.attach_buffer(node.get(), &stage);
  return node;
}

std::unique_ptr<tbb::flow::function_node<Batch*>> make_retire_node(tbb::flow::graph& graph, PipelineContext& context) {
  return std::make_unique<tbb::flow::function_node<Batch*>>(graph, tbb::flow::unlimited, [&context](Batch* batch) {
    const std::size_t count = batch->rays.count;
    context.pool().release(batch);
    context.retire_rays(count);
    return tbb::flow::continue_msg();
  });
}

Pipeline::Pipeline(RaySource& generate, std::vector<const Stage*> chain, bool loops, const PipelineOptions& options,
                   BatchPool* shared_pool)
    : generate_(generate), chain_(std::move(chain)), loops_(loops), options_(options), shared_pool_(shared_pool) {}

PipelineRun Pipeline::run(const std::function<void(const Progress&)>& on_progress, std::chrono::milliseconds interval) {
  TracingArena arena(options_.threads);
  const int threads = arena.threads();

  StageCounters generate_counters(generate_.name());
  std::vector<std::unique_ptr<StageCounters>> counters;
  for (const Stage* stage : chain_) counters.push_back(std::make_unique<StageCounters>(stage->name()));
  const StageCounters* trace_counters = nullptr;
  for (const auto& c : counters) {
    if (c->snapshot().name == "trace") trace_counters = c.get();
  }

  std::size_t rays_per_source_ray = 1;
  for (const Stage* stage : chain_) rays_per_source_ray = std::max(rays_per_source_ray, stage->rays_out_per_ray());
  PipelineContext context(options_.batch_size, options_.rays_in_flight, shared_pool_, rays_per_source_ray);
  const Clock::time_point start = Clock::now();
  const ProcessCpuTime cpu_at_start = read_process_cpu_time();

  std::optional<ProgressReporter> reporter;
  reporter.emplace(
      on_progress,
      [&] {
        return Progress{generate_.generated(), generate_.total_rays(), trace_counters ? trace_counters->rays_in() : 0,
                        std::chrono::duration<double>(Clock::now() - start).count()};
      },
      interval);
  arena.execute([&] {
    tbb::flow::graph graph;
    auto generate_node = make_generate_node(graph, generate_, context, generate_counters);
    std::vector<std::unique_ptr<OrderedHandOff>> hand_offs(chain_.size());  // [i]: from stage i to stage i + 1
    std::vector<std::unique_ptr<BatchNode>> nodes;
    for (std::size_t i = 0; i < chain_.size(); ++i) {
      if (const auto* buffering = dynamic_cast<const BufferingStage*>(chain_[i])) {
        if (i + 1 < chain_.size() && dynamic_cast<const BufferingStage*>(chain_[i + 1]) == nullptr) {
          hand_offs[i] = std::make_unique<OrderedHandOff>();
        }
        nodes.push_back(make_buffering_node(graph, *buffering, context, *counters[i], hand_offs[i].get()));
      } else {
        nodes.push_back(make_stage_node(graph, *chain_[i], context, *counters[i], i > 0 ? hand_offs[i - 1].get() : nullptr));
      }
    }
    std::unique_ptr<tbb::flow::function_node<Batch*>> retire;
    if (nodes.empty()) {
      retire = make_retire_node(graph, context);
      tbb::flow::make_edge(tbb::flow::output_port<0>(*generate_node), *retire);
    } else {
      tbb::flow::make_edge(tbb::flow::output_port<0>(*generate_node), *nodes.front());
      for (std::size_t i = 0; i + 1 < nodes.size(); ++i) {
        tbb::flow::make_edge(tbb::flow::output_port<0>(*nodes[i]), *nodes[i + 1]);
      }
      if (loops_) {
        tbb::flow::make_edge(tbb::flow::output_port<0>(*nodes.back()), *nodes.front());
      } else {
        retire = make_retire_node(graph, context);
        tbb::flow::make_edge(tbb::flow::output_port<0>(*nodes.back()), *retire);
      }
    }
    // Each stage that reads ahead gets a thread of its own beside the arena's workers: it
    // mostly waits for the disk, and a worker taken by it would trace nothing meanwhile.
    std::vector<std::jthread> readers_ahead;
    std::exception_ptr look_ahead_error;
    std::mutex look_ahead_error_mutex;
    const auto stop_reading_ahead = [&] {
      for (const auto& hand_off : hand_offs) {
        if (hand_off) hand_off->close();
      }
      readers_ahead.clear();  // joins
    };
    for (std::size_t i = 1; i < chain_.size(); ++i) {
      const Stage* stage = chain_[i];
      const LookAhead plan = stage->look_ahead_plan();
      const std::size_t depth = plan.batches;
      OrderedHandOff* hand_off = hand_offs[i - 1].get();
      if (hand_off == nullptr || depth == 0) continue;
      const auto read_ahead = [&, stage, hand_off, depth] {
        Batch* copy = context.pool().acquire();
        try {
          while (hand_off->next_ahead(depth, [&](const Batch& upcoming) { stage->copy_ahead(upcoming, *copy); })) {
            stage->look_ahead(*copy);
          }
        } catch (...) {
          // The stage's own reads will meet the same failure; keep it to report should they not.
          std::lock_guard lock(look_ahead_error_mutex);
          look_ahead_error = std::current_exception();
        }
        context.pool().release(copy);
      };
      for (std::size_t reader = 0; reader < plan.threads; ++reader) readers_ahead.emplace_back(read_ahead);
    }
    generate_node->try_put(tbb::flow::continue_msg());
    try {
      graph.wait_for_all();
    } catch (...) {
      stop_reading_ahead();
      throw;
    }
    stop_reading_ahead();
    if (look_ahead_error) std::rethrow_exception(look_ahead_error);
  });
  if (context.live_rays() != 0) {
    throw std::logic_error("the pipeline drained with " + std::to_string(context.live_rays()) + " rays still alive");
  }

  PipelineRun result;
  result.seconds = std::chrono::duration<double>(Clock::now() - start).count();
  result.cpu = read_process_cpu_time() - cpu_at_start;
  reporter.reset();
  result.threads = threads;
  result.stages.push_back(generate_counters.snapshot());
  for (const auto& c : counters) result.stages.push_back(c->snapshot());
  result.batches_allocated = context.pool().allocated();
  result.peak_rays_in_core = std::size_t(context.peak_in_core_rays());
  return result;
}

}  // namespace wavetrace
