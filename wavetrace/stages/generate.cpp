// Camera ray generation with per-pixel jitter keyed by (pixel, sample).
#include "wavetrace/stages/generate.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>
#include <utility>

#include <glm/geometric.hpp>

#include "wavetrace/kernels/morton.hpp"
#include "wavetrace/kernels/random.hpp"

namespace wavetrace {

PixelOrder parse_pixel_order(const std::string& text) {
  if (text == "scanline") return PixelOrder::scanline;
  if (text == "zcurve") return PixelOrder::zcurve;
  throw std::invalid_argument("unknown pixel order '" + text + "' (scanline, zcurve)");
}

GenerateStage::GenerateStage(const Camera& camera, const ImageSpec& image, PixelOrder order, CameraRaySource ranges)
    : frame_(camera, float(image.width) / float(image.height)),
      image_(image),
      inverse_width_(1.0f / float(image.width)),
      inverse_height_(1.0f / float(image.height)),
      total_(std::uint64_t(image.pixel_count()) * image.samples_per_pixel),
      ranges_(std::move(ranges)) {
  if (order == PixelOrder::zcurve) {
    // Walk the Z-curve of the enclosing power-of-two square, keeping the pixels inside.
    std::uint32_t side = 1;
    while (side < image.width || side < image.height) side *= 2;
    pixel_order_.reserve(image.pixel_count());
    for (std::uint64_t code = 0; code < std::uint64_t(side) * side; ++code) {
      const Point2u p = morton2d_decode(code);
      if (p.x < image.width && p.y < image.height) pixel_order_.push_back(p.y * image.width + p.x);
    }
  }
}

GenerateStage::Claim GenerateStage::claim(std::size_t capacity) {
  if (!ranges_) {
    const std::uint64_t first = next_.fetch_add(capacity, std::memory_order_relaxed);
    if (first >= total_) return {};
    return {first, static_cast<std::size_t>(std::min<std::uint64_t>(capacity, total_ - first))};
  }
  std::lock_guard lock(range_mutex_);
  if (range_.count == 0 && !ranges_done_.load(std::memory_order_relaxed)) {
    range_ = ranges_();
    if (range_.first > total_ || range_.count > total_ - range_.first) {
      throw std::logic_error("a ray range source handed out rays past the image's");
    }
    if (range_.count == 0) ranges_done_.store(true, std::memory_order_release);
  }
  if (range_.count == 0) return {};
  const Claim claimed{range_.first, static_cast<std::size_t>(std::min<std::uint64_t>(capacity, range_.count))};
  range_.first += claimed.count;
  range_.count -= claimed.count;
  claimed_.fetch_add(claimed.count, std::memory_order_relaxed);
  return claimed;
}

void GenerateStage::fill_range(RayBatch& rays, const Claim& claimed) const {
  const std::uint32_t spp = image_.samples_per_pixel;
  // Walk the (pixel, sample) pairs on from the claim's first ray: one division per batch.
  auto order_index = static_cast<std::uint32_t>(claimed.first / spp);
  auto sample = static_cast<std::uint32_t>(claimed.first % spp);
  std::uint32_t pixel = pixel_order_.empty() ? order_index : pixel_order_[order_index];
  for (std::size_t i = 0; i < claimed.count; ++i) {
    write_camera_ray(rays, i, pixel, sample);
    if (++sample == spp && i + 1 < claimed.count) {
      sample = 0;
      ++order_index;
      pixel = pixel_order_.empty() ? order_index : pixel_order_[order_index];
    }
  }
  rays.count = claimed.count;
}

std::size_t GenerateStage::fill(RayBatch& rays) {
  const Claim claimed = claim(rays.capacity());
  fill_range(rays, claimed);
  return claimed.count;
}

void GenerateStage::write_camera_ray(RayBatch& rays, std::size_t slot, std::uint32_t pixel, std::uint32_t image_sample) const {
  const std::uint32_t sample = image_sample + image_.seed * image_.samples_per_pixel;
  const std::uint64_t path = path_key(pixel, sample);
  const float jitter_x = unit_float32(path_draw(path, 0, RandomPurpose::pixel_jitter, 0));
  const float jitter_y = unit_float32(path_draw(path, 0, RandomPurpose::pixel_jitter, 1));
  const float x = (float(pixel % image_.width) + jitter_x) * inverse_width_;
  const float y = 1.0f - (float(pixel / image_.width) + jitter_y) * inverse_height_;
  const glm::vec3 direction = glm::normalize(frame_.direction(x, y));
  rays.set_geometry(slot, frame_.origin, direction, 0.0f, std::numeric_limits<float>::infinity());
  rays.pixel[slot] = pixel;
  rays.sample[slot] = sample;
  rays.depth[slot] = 0;
  rays.kind[slot] = RayKind::camera;
  rays.throughput_r[slot] = rays.throughput_g[slot] = rays.throughput_b[slot] = 1.0f;
  rays.flags[slot] = ray_flags::alive;
}

}  // namespace wavetrace
