// Camera ray generation with per-pixel jitter keyed by (pixel, sample).
#include "stages/generate.hpp"

#include <cmath>
#include <limits>
#include <stdexcept>

#include <glm/geometric.hpp>

#include "kernels/morton.hpp"
#include "kernels/random.hpp"

namespace wavetrace {

PixelOrder parse_pixel_order(const std::string& text) {
  if (text == "scanline") return PixelOrder::scanline;
  if (text == "zcurve") return PixelOrder::zcurve;
  throw std::invalid_argument("unknown pixel order '" + text + "' (scanline, zcurve)");
}

GenerateStage::GenerateStage(const Camera& camera, const ImageSpec& image, PixelOrder order)
    : frame_(camera, float(image.width) / float(image.height)),
      image_(image),
      total_(std::uint64_t(image.pixel_count()) * image.samples_per_pixel) {
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

std::size_t GenerateStage::fill(RayBatch& rays) {
  const std::uint64_t first = next_.load(std::memory_order_relaxed);
  const std::size_t count = static_cast<std::size_t>(std::min<std::uint64_t>(rays.capacity(), total_ - first));
  const std::uint32_t spp = image_.samples_per_pixel;
  // Walk (pixel, sample) incrementally: one division per batch, not two per ray.
  auto order_index = static_cast<std::uint32_t>(first / spp);
  auto sample = static_cast<std::uint32_t>(first % spp);
  std::uint32_t pixel = 0;
  float pixel_x = 0.0f, pixel_y = 0.0f;
  const auto enter_pixel = [&] {
    pixel = pixel_order_.empty() ? order_index : pixel_order_[order_index];
    pixel_x = float(pixel % image_.width);
    pixel_y = float(pixel / image_.width);
  };
  enter_pixel();
  const float inverse_width = 1.0f / float(image_.width), inverse_height = 1.0f / float(image_.height);
  for (std::size_t i = 0; i < count; ++i) {
    const UnitPair jitter = unit_pair(random_bits(pixel, sample, 0, RandomPurpose::pixel_jitter));
    const float x = (pixel_x + jitter.first) * inverse_width;
    const float y = 1.0f - (pixel_y + jitter.second) * inverse_height;
    const glm::vec3 direction = glm::normalize(frame_.direction(x, y));
    rays.set_geometry(i, frame_.origin, direction, 0.0f, std::numeric_limits<float>::infinity());
    rays.pixel[i] = pixel;
    rays.sample[i] = sample;
    rays.depth[i] = 0;
    rays.kind[i] = RayKind::camera;
    rays.throughput_r[i] = rays.throughput_g[i] = rays.throughput_b[i] = 1.0f;
    rays.flags[i] = ray_flags::alive;
    if (++sample == spp && i + 1 < count) {
      sample = 0;
      ++order_index;
      enter_pixel();
    }
  }
  rays.count = count;
  next_.store(first + count, std::memory_order_relaxed);
  return count;
}

}  // namespace wavetrace
