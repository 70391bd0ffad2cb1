// generate: camera rays for every (pixel, sample) of the image, in scanline or Z-curve
// pixel order, a batch at a time.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <functional>
#include <mutex>
#include <string>
#include <vector>

#include "wavetrace/memory/ray_batch.hpp"
#include "wavetrace/scene/camera.hpp"
#include "wavetrace/stages/ray_source.hpp"

namespace wavetrace {

enum class PixelOrder { scanline, zcurve };
PixelOrder parse_pixel_order(const std::string& text);

struct ImageSpec {
  std::uint32_t width = 640;
  std::uint32_t height = 480;
  std::uint32_t samples_per_pixel = 8;
  // Samples are numbered from seed * samples_per_pixel: each path's draws hang on its
  // (pixel, sample), so another seed draws independent samples of the same image.
  std::uint32_t seed = 0;
  std::uint32_t pixel_count() const { return width * height; }
  bool operator==(const ImageSpec&) const = default;
};

// A run of camera rays by their index in the image's order (pixel in pixel order, then
// sample): [first, first + count).
struct CameraRayRange {
  std::uint64_t first = 0;
  std::uint64_t count = 0;
};
// Hands out the camera rays one process is to generate when several share an image (a
// distributed render): each call the next range, count 0 once there are no more. Called under
// generate's lock, one call at a time, a range per many batches.
using CameraRaySource = std::function<CameraRayRange()>;

class GenerateStage final : public RaySource {
 public:
  // Without `ranges`, every camera ray of the image; with them, the ranges they hand out.
  GenerateStage(const Camera& camera, const ImageSpec& image, PixelOrder order, CameraRaySource ranges = {});

  std::string name() const override { return "generate"; }
  std::uint64_t total_rays() const override { return total_; }
  // Camera rays claimed so far (with ranges: of this process's ranges).
  std::uint64_t generated() const override {
    return ranges_ ? claimed_.load(std::memory_order_relaxed) : std::min(next_.load(std::memory_order_relaxed), total_);
  }
  bool exhausted() const override {
    return ranges_ ? ranges_done_.load(std::memory_order_acquire) : generated() >= total_;
  }

  // Camera rays by their index in the image's order (pixel in pixel order, then sample).
  Claim claim(std::size_t capacity) override;
  // A pure function of the indices.
  void fill_range(RayBatch& rays, const Claim& claimed) const override;
  // Both: fills `rays` with the next camera rays (up to its capacity); returns how many.
  std::size_t fill(RayBatch& rays);

  // The camera ray of (pixel, sample) into slot `slot`: a pure function of the two, so
  // the megakernel, which walks pixels its own way, makes the very rays fill makes.
  void write_camera_ray(RayBatch& rays, std::size_t slot, std::uint32_t pixel, std::uint32_t sample) const;
  const ImageSpec& image() const { return image_; }

 private:
  CameraFrame frame_;
  ImageSpec image_;
  float inverse_width_, inverse_height_;
  std::vector<std::uint32_t> pixel_order_;  // empty: scanline
  std::uint64_t total_;
  std::atomic<std::uint64_t> next_{0};
  // With a source of ranges: claims take the lock (one per batch) and draw from `range_`.
  CameraRaySource ranges_;
  std::mutex range_mutex_;
  CameraRayRange range_;
  std::atomic<std::uint64_t> claimed_{0};
  std::atomic<bool> ranges_done_{false};
};

}  // namespace wavetrace
