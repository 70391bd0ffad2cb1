// Where a build's time goes: seconds by named phase, kept in the order the phases first ran,
// so that a build's stats (`accel.build_phases`) read as the build did.
#pragma once

#include <chrono>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace wavetrace {

class BuildPhases {
 public:
  void add(std::string_view phase, double seconds) {
    for (auto& [name, total] : phases_) {
      if (name == phase) {
        total += seconds;
        return;
      }
    }
    phases_.emplace_back(std::string(phase), seconds);
  }
  // Another build's phases, each name given `prefix` (a chunked build's "chunk." phases).
  void add(const BuildPhases& other, std::string_view prefix = {}) {
    for (const auto& [name, seconds] : other.phases_) add(std::string(prefix) + name, seconds);
  }
  double seconds(std::string_view phase) const {
    for (const auto& [name, total] : phases_) {
      if (name == phase) return total;
    }
    return 0.0;
  }
  const std::vector<std::pair<std::string, double>>& entries() const { return phases_; }
  bool empty() const { return phases_.empty(); }

 private:
  std::vector<std::pair<std::string, double>> phases_;
};

// A stopwatch read between phases: each lap() is the seconds since the previous one.
class PhaseClock {
 public:
  double lap() {
    const auto now = std::chrono::steady_clock::now();
    const double seconds = std::chrono::duration<double>(now - last_).count();
    last_ = now;
    return seconds;
  }
  // Times the phase and adds it under `name`.
  void lap(BuildPhases& phases, std::string_view name) { phases.add(name, lap()); }
  // Seconds since the clock was made.
  double elapsed() const { return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count(); }

 private:
  std::chrono::steady_clock::time_point start_ = std::chrono::steady_clock::now();
  std::chrono::steady_clock::time_point last_ = start_;
};

}  // namespace wavetrace
