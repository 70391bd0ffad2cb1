// Fixed-point film accumulation with relaxed atomics.
#include "stages/film.hpp"

#include <cmath>

namespace wavetrace {

Film::Film(std::uint32_t width, std::uint32_t height)
    : width_(width), height_(height), sums_(new std::int64_t[std::size_t(width) * height * 3]()) {}

void Film::add(std::uint32_t pixel, float r, float g, float b) {
  const float channels[3] = {r, g, b};
  for (float value : channels) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      rejected_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  }
  for (int c = 0; c < 3; ++c) {
    if (channels[c] == 0.0f) continue;
    // Round half up by hand: non-negative input, and llround is a library call per channel.
    const auto fixed = static_cast<std::int64_t>(double(std::fmin(channels[c], kMaxContribution)) * kScale + 0.5);
    std::atomic_ref<std::int64_t>(sums_[std::size_t(pixel) * 3 + c]).fetch_add(fixed, std::memory_order_relaxed);
  }
}

std::vector<float> Film::resolve(std::uint32_t samples_per_pixel) const {
  std::vector<float> image(std::size_t(width_) * height_ * 3);
  const double scale = 1.0 / (kScale * samples_per_pixel);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<float>(double(sums_[i]) * scale);
  return image;
}

}  // namespace wavetrace
