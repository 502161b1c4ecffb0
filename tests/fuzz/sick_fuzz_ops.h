// The SICK fuzz input: operations on the byte stream a scanner sends (shared by the harness
// fuzz_sick_telegram.cpp and the seed generator). Telegram operations are encoded with a valid
// CRC-16 by the harness so impossible content reaches decode_measured_values and the driver.
#pragma once

#include <cstdint>

namespace fuzz {

enum SickOp : std::uint8_t {
  kSickRaw = 0,        // blob: raw bytes appended to the stream
  kSickTelegram = 1,   // u8 address, blob payload (CMD + data): one telegram with a valid CRC
  kSickMeasured = 2,   // u8 address, u16 count word, n = count & 0x3FF (≤ 410) × u16, u8 status
  kSickPoll = 3,       // u8 chunk: the port hands out at most chunk+1 bytes per read; poll once
  kSickReconnect = 4,  // the port closes and returns: restart()
  kSickNumOps = 5,
};

}  // namespace fuzz
