// The reporting thread: wakes every interval until told to stop.
#include "wavetrace/pipeline/progress_reporter.hpp"

namespace wavetrace {

ProgressReporter::ProgressReporter(const std::function<void(const Progress&)>& report, std::function<Progress()> poll,
                                   std::chrono::milliseconds interval) {
  if (!report) return;
  thread_ = std::thread([this, report, poll = std::move(poll), interval] {
    std::unique_lock lock(mutex_);
    while (!signal_.wait_for(lock, interval, [&] { return done_; })) report(poll());
  });
}

ProgressReporter::~ProgressReporter() {
  if (!thread_.joinable()) return;
  {
    std::lock_guard lock(mutex_);
    done_ = true;
  }
  signal_.notify_all();
  thread_.join();
}

}  // namespace wavetrace
