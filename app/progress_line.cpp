// Carriage-return progress on a TTY.
#include "app/progress_line.hpp"

#include <unistd.h>

#include <fmt/format.h>

namespace wavetrace {

ProgressLine::ProgressLine(std::FILE* stream) : stream_(stream), enabled_(isatty(fileno(stream)) != 0) {}

void ProgressLine::update(const Progress& progress) {
  if (!enabled_) return;
  const double fraction =
      progress.camera_rays_total ? double(progress.camera_rays_generated) / double(progress.camera_rays_total) : 0.0;
  const double eta = fraction > 0.0 ? progress.seconds * (1.0 - fraction) / fraction : 0.0;
  const double rate = progress.seconds > 0.0 ? double(progress.rays_traced) / progress.seconds * 1e-6 : 0.0;
  fmt::print(stream_, "\r  {:5.1f}%  {:.1f}M rays traced  {:.2f} Mrays/s  {:.1f} s elapsed  ETA {:.1f} s   ",
             100.0 * fraction, double(progress.rays_traced) * 1e-6, rate, progress.seconds, eta);
  std::fflush(stream_);
  drawn_ = true;
}

void ProgressLine::finish() {
  if (!drawn_) return;
  fmt::print(stream_, "\r{:100}\r", "");
  std::fflush(stream_);
}

}  // namespace wavetrace
