// OpenEXR through Imf's FrameBuffer API (32-bit float channels); PNG through libpng's
// simplified API, after a filmic curve and sRGB encoding.
#include "app/image_output.hpp"

#include <cmath>
#include <filesystem>
#include <stdexcept>

#include <OpenEXR/ImfChannelList.h>
#include <OpenEXR/ImfFrameBuffer.h>
#include <OpenEXR/ImfHeader.h>
#include <OpenEXR/ImfOutputFile.h>
#include <fmt/format.h>
#include <png.h>

namespace wavetrace {
namespace {

void ensure_parent_directory(const std::string& path) {
  const std::filesystem::path parent = std::filesystem::path(path).parent_path();
  if (!parent.empty()) {
    std::error_code status;
    std::filesystem::create_directories(parent, status);
  }
}

// ACES-like filmic curve (Narkowicz 2015): keeps highlights from clipping hard.
float tone_map(float x) {
  x = std::fmax(0.0f, x);
  return std::fmin(1.0f, (x * (2.51f * x + 0.03f)) / (x * (2.43f * x + 0.59f) + 0.14f));
}

float srgb_encode(float linear) {
  return linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
}

}  // namespace

void write_exr(const std::string& path, std::uint32_t width, std::uint32_t height, const std::vector<float>& rgb) {
  ensure_parent_directory(path);
  try {
    Imf::Header header(static_cast<int>(width), static_cast<int>(height));
    const char* names[3] = {"R", "G", "B"};
    for (const char* name : names) header.channels().insert(name, Imf::Channel(Imf::FLOAT));
    Imf::OutputFile file(path.c_str(), header);
    Imf::FrameBuffer frame;
    const std::size_t pixel_stride = 3 * sizeof(float);
    for (int c = 0; c < 3; ++c) {
      char* base = reinterpret_cast<char*>(const_cast<float*>(rgb.data())) + c * sizeof(float);
      frame.insert(names[c], Imf::Slice(Imf::FLOAT, base, pixel_stride, pixel_stride * width));
    }
    file.setFrameBuffer(frame);
    file.writePixels(static_cast<int>(height));
  } catch (const std::exception& failure) {
    throw std::runtime_error(fmt::format("{}: could not write EXR ({})", path, failure.what()));
  }
}

void write_png_preview(const std::string& path, std::uint32_t width, std::uint32_t height,
                       const std::vector<float>& rgb) {
  ensure_parent_directory(path);
  std::vector<std::uint8_t> bytes(rgb.size());
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    bytes[i] = static_cast<std::uint8_t>(std::lround(255.0f * srgb_encode(tone_map(rgb[i]))));
  }
  png_image image{};
  image.version = PNG_IMAGE_VERSION;
  image.width = width;
  image.height = height;
  image.format = PNG_FORMAT_RGB;
  if (!png_image_write_to_file(&image, path.c_str(), 0, bytes.data(), 0, nullptr)) {
    throw std::runtime_error(fmt::format("{}: could not write PNG ({})", path, image.message));
  }
}

std::string preview_path_for(const std::string& exr_path) {
  return std::filesystem::path(exr_path).replace_extension(".png").string();
}

}  // namespace wavetrace
