// The film: per-pixel radiance sums in 64-bit fixed point, so that accumulation is
// exact and order-independent (an image is bit-identical for any thread count, batch
// size or ray order).
#pragma once

#include <atomic>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace wavetrace {

class Film {
 public:
  // `per_thread_copies` > 0 gives each of that many worker threads (by their index in the
  // TBB arena the render runs in) its own copy of the sums, added without atomics and summed
  // by resolve; other threads, and every thread with 0 copies, add atomically to the shared
  // sums. Integer sums, so the image is the same either way.
  Film(std::uint32_t width, std::uint32_t height, std::uint32_t per_thread_copies = 0);

  std::uint32_t width() const { return width_; }
  std::uint32_t height() const { return height_; }

  // Adds radiance to a pixel; thread-safe. Non-finite or negative contributions are
  // dropped and counted (a correct tracer makes none).
  void add(std::uint32_t pixel, float r, float g, float b);

  // Linear RGB, rows top to bottom, averaged over `samples_per_pixel`.
  std::vector<float> resolve(std::uint32_t samples_per_pixel) const;

  // The fixed-point sums (r, g, b per pixel, rows top to bottom; the per-thread copies
  // folded in): films of processes that shared an image add up to the one film that a
  // single process would have held, exactly, in any order.
  std::vector<std::int64_t> sums() const;
  // The image of such sums, as resolve makes it.
  static std::vector<float> resolve(std::span<const std::int64_t> sums, std::uint32_t samples_per_pixel);

  std::uint64_t rejected_contributions() const { return rejected_.load(std::memory_order_relaxed); }

  // 2^-24 resolution; sums up to about 5e11 per pixel and channel before overflow.
  static constexpr double kScale = 16777216.0;
  static constexpr float kMaxContribution = 1e9f;

 private:
  std::uint32_t width_, height_;
  std::uint32_t copies_;
  std::unique_ptr<std::int64_t[]> sums_;         // r, g, b per pixel, shared (atomic adds)
  std::unique_ptr<std::int64_t[]> thread_sums_;  // copies_ more, one per worker thread
  std::atomic<std::uint64_t> rejected_{0};
};

}  // namespace wavetrace
