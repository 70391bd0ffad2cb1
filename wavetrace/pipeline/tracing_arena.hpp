// A TBB arena of a set number of threads whose every thread has the float mode Embree
// asks for (flush-to-zero, denormals-are-zero), so all tracing code sees the same mode.
#pragma once

#include <optional>

#include <tbb/global_control.h>
#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

namespace wavetrace {

class TracingArena {
 public:
  explicit TracingArena(int threads);  // 0: all cores
  ~TracingArena();
  TracingArena(const TracingArena&) = delete;
  TracingArena& operator=(const TracingArena&) = delete;

  int threads() const { return threads_; }
  template <typename Function>
  void execute(Function&& function) {
    arena_.execute([&] {
      enter_calling_thread();
      function();
    });
  }

 private:
  class FloatModeObserver final : public tbb::task_scheduler_observer {
   public:
    explicit FloatModeObserver(tbb::task_arena& arena) : tbb::task_scheduler_observer(arena) { observe(true); }
    ~FloatModeObserver() override { observe(false); }
    void on_scheduler_entry(bool) override;
  };
  static void enter_calling_thread();

  int threads_;
  // More threads than cores: TBB lets an arena's workers run only up to the cores (less the
  // caller) unless the process's limit is raised, so `--threads 8` on 2 cores ran on 2. Out of
  // core, threads beyond the cores are how more page reads get in flight.
  std::optional<tbb::global_control> parallelism_;
  tbb::task_arena arena_;
  FloatModeObserver observer_;
};

}  // namespace wavetrace
