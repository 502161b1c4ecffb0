// Minimal PNG output (libpng) for looking at maps: 8-bit grayscale or RGB, row 0 = top of the image.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace sim {

// channels = 1 (gray) or 3 (RGB); pixels.size() == width * height * channels.
bool write_png(const std::string& path, int width, int height, int channels, const std::vector<std::uint8_t>& pixels,
               std::string* error);

}  // namespace sim
