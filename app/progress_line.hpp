// A live progress line on a terminal (rays done, Mrays/s, elapsed, ETA); silent otherwise.
#pragma once

#include <cstdio>

#include "wavetrace/pipeline/pipeline.hpp"

namespace wavetrace {

class ProgressLine {
 public:
  explicit ProgressLine(std::FILE* stream);
  bool enabled() const { return enabled_; }
  void update(const Progress& progress);
  void finish();  // clears the line

 private:
  std::FILE* stream_;
  bool enabled_;
  bool drawn_ = false;
};

}  // namespace wavetrace
