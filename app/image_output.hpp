// Writing images: linear float OpenEXR (the real output) and a tone-mapped sRGB PNG preview.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace wavetrace {

// `rgb` is linear, rows top to bottom. Throws std::runtime_error naming the file on failure.
void write_exr(const std::string& path, std::uint32_t width, std::uint32_t height, const std::vector<float>& rgb);
void write_png_preview(const std::string& path, std::uint32_t width, std::uint32_t height,
                       const std::vector<float>& rgb);

// The PNG path beside an EXR path: same name, .png extension.
std::string preview_path_for(const std::string& exr_path);

}  // namespace wavetrace
