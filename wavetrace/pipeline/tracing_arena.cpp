// Arena set-up and per-thread float mode.
#include "wavetrace/pipeline/tracing_arena.hpp"

#include <tbb/info.h>

#include "wavetrace/accel/embree/embree_accelerator.hpp"

namespace wavetrace {

namespace {
std::optional<tbb::global_control> parallelism_for(int threads) {
  if (threads <= tbb::info::default_concurrency()) return std::nullopt;
  return std::optional<tbb::global_control>(std::in_place, tbb::global_control::max_allowed_parallelism,
                                            static_cast<std::size_t>(threads));
}
}  // namespace

TracingArena::TracingArena(int threads)
    : threads_(threads > 0 ? threads : tbb::info::default_concurrency()),
      parallelism_(parallelism_for(threads_)),
      arena_(threads_),
      observer_(arena_) {}

TracingArena::~TracingArena() = default;

void TracingArena::FloatModeObserver::on_scheduler_entry(bool) { set_embree_thread_float_mode(); }

void TracingArena::enter_calling_thread() { set_embree_thread_float_mode(); }

}  // namespace wavetrace
