// Little-endian fields of the map image format (map_image.h), read byte by byte so that a field may
// sit at any alignment inside the mapped file. Shared by the image parser, the file loader and the distance field's image source.
#pragma once

#include <cstdint>
#include <cstring>

namespace fw {

inline std::uint32_t read_le_u32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}

inline std::uint64_t read_le_u64(const std::uint8_t* p) {
  return static_cast<std::uint64_t>(read_le_u32(p)) | (static_cast<std::uint64_t>(read_le_u32(p + 4)) << 32);
}

inline float read_le_f32(const std::uint8_t* p) {
  const std::uint32_t u = read_le_u32(p);
  float f;
  std::memcpy(&f, &u, sizeof(f));
  return f;
}

}  // namespace fw
