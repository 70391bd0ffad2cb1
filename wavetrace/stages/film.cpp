// Fixed-point film accumulation: relaxed atomics, or a copy per worker thread.
#include "wavetrace/stages/film.hpp"

#include <cmath>

#include <tbb/task_arena.h>

namespace wavetrace {

Film::Film(std::uint32_t width, std::uint32_t height, std::uint32_t per_thread_copies)
    : width_(width),
      height_(height),
      copies_(per_thread_copies),
      sums_(new std::int64_t[std::size_t(width) * height * 3]()),
      thread_sums_(per_thread_copies > 0 ? new std::int64_t[std::size_t(width) * height * 3 * per_thread_copies]()
                                         : nullptr) {}

void Film::add(std::uint32_t pixel, float r, float g, float b) {
  const float channels[3] = {r, g, b};
  for (float value : channels) {
    if (!(value >= 0.0f) || !std::isfinite(value)) {
      rejected_.fetch_add(1, std::memory_order_relaxed);
      return;
    }
  }
  const int thread = copies_ > 0 ? tbb::this_task_arena::current_thread_index() : -1;
  std::int64_t* own = thread >= 0 && std::uint32_t(thread) < copies_
                          ? thread_sums_.get() + std::size_t(thread) * width_ * height_ * 3
                          : nullptr;
  for (int c = 0; c < 3; ++c) {
    if (channels[c] == 0.0f) continue;
    // Round half up by hand: non-negative input, and llround is a library call per channel.
    const auto fixed = static_cast<std::int64_t>(double(std::fmin(channels[c], kMaxContribution)) * kScale + 0.5);
    const std::size_t slot = std::size_t(pixel) * 3 + c;
    if (own != nullptr) {
      own[slot] += fixed;
    } else {
      std::atomic_ref<std::int64_t>(sums_[slot]).fetch_add(fixed, std::memory_order_relaxed);
    }
  }
}

std::vector<std::int64_t> Film::sums() const {
  const std::size_t size = std::size_t(width_) * height_ * 3;
  std::vector<std::int64_t> sums(sums_.get(), sums_.get() + size);
  for (std::uint32_t copy = 0; copy < copies_; ++copy) {
    const std::int64_t* own = thread_sums_.get() + std::size_t(copy) * size;
    for (std::size_t i = 0; i < size; ++i) sums[i] += own[i];
  }
  return sums;
}

std::vector<float> Film::resolve(std::uint32_t samples_per_pixel) const { return resolve(sums(), samples_per_pixel); }

std::vector<float> Film::resolve(std::span<const std::int64_t> sums, std::uint32_t samples_per_pixel) {
  std::vector<float> image(sums.size());
  const double scale = 1.0 / (kScale * samples_per_pixel);
  for (std::size_t i = 0; i < image.size(); ++i) image[i] = static_cast<float>(double(sums[i]) * scale);
  return image;
}

}  // namespace wavetrace
