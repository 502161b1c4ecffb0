// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320, init/xorout 0xFFFFFFFF): the same value as
// zlib's crc32(), which the host writer uses. The firmware cannot link zlib (it must stay free of
// third-party code paths that may allocate), so this is a small table-driven version with the
// table built at compile time; crc32_test checks it against zlib byte for byte.
#pragma once

#include <cstddef>
#include <cstdint>

namespace fw {

// Continues a running CRC: crc32_update(crc32_update(0, a), b) == crc of a followed by b.
std::uint32_t crc32_update(std::uint32_t crc, const std::uint8_t* data, std::size_t size);
inline std::uint32_t crc32(const std::uint8_t* data, std::size_t size) { return crc32_update(0u, data, size); }

}  // namespace fw
