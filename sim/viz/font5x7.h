// A 5×7 bitmap font (the classic HD44780-style glyphs, column-major, bit 0 = top row) for text
// in PNG pictures. ASCII 32..126; characters without a glyph render as '?'.
#pragma once

#include <cstdint>

namespace sim {

// Five column bytes of the glyph for `c`.
const std::uint8_t* font5x7_glyph(char c);

}  // namespace sim
