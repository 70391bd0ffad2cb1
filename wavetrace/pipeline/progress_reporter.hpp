// Progress reports from a helper thread while a render runs, for the wavefront and the
// megakernel alike: started with a callback, stopped (and joined) by its destructor.
#pragma once

#include <chrono>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <mutex>
#include <thread>

namespace wavetrace {

struct Progress {
  std::uint64_t camera_rays_generated = 0;
  std::uint64_t camera_rays_total = 0;
  std::uint64_t rays_traced = 0;
  double seconds = 0.0;
};

class ProgressReporter {
 public:
  // Calls `report` about every `interval` with what `poll` says; nothing when `report` is empty.
  ProgressReporter(const std::function<void(const Progress&)>& report, std::function<Progress()> poll,
                   std::chrono::milliseconds interval);
  ~ProgressReporter();
  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

 private:
  std::mutex mutex_;
  std::condition_variable signal_;
  bool done_ = false;
  std::thread thread_;
};

}  // namespace wavetrace
