// Upper-case hex of a byte run, as candump writes a frame's data: the CAN and serial black boxes'
// lines share it. Header-only: no heap, no locale, two characters per byte, no terminator.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hal {

// Writes 2 × len characters at `out` and returns how many.
inline std::size_t write_hex_bytes(const std::uint8_t* data, std::size_t len, char* out) {
  static constexpr char kHex[] = "0123456789ABCDEF";
  for (std::size_t k = 0; k < len; ++k) {
    out[2 * k] = kHex[data[k] >> 4];
    out[2 * k + 1] = kHex[data[k] & 0xF];
  }
  return 2 * len;
}

}  // namespace hal
