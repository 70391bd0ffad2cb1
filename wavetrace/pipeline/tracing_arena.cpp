// Arena set-up and per-thread float mode.
#include "wavetrace/pipeline/tracing_arena.hpp"

#include <tbb/info.h>

#include "wavetrace/accel/embree/embree_accelerator.hpp"

namespace wavetrace {

TracingArena::TracingArena(int threads)
    : threads_(threads > 0 ? threads : tbb::info::default_concurrency()), arena_(threads_), observer_(arena_) {}

TracingArena::~TracingArena() = default;

void TracingArena::FloatModeObserver::on_scheduler_entry(bool) { set_embree_thread_float_mode(); }

void TracingArena::enter_calling_thread() { set_embree_thread_float_mode(); }

}  // namespace wavetrace
