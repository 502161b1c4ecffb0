// SICK LMS2xx telegram protocol as a pure parser/encoder (no I/O), after the LMS2xx telegram
// listing: STX (0x02) | ADR | LEN (u16 little-endian: bytes of CMD + data, status included) |
// CMD | data... | [status] | CRC-16 (little-endian, SICK's CRC over STX..last data byte).
// The parser resynchronises after garbage, impossible lengths and bad CRCs by dropping the STX it
// locked onto and scanning for the next one; every such event is counted.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace hal_serial {

constexpr std::uint8_t kStx = 0x02;
constexpr std::uint8_t kAck = 0x06;
constexpr std::uint8_t kNak = 0x15;
constexpr std::uint8_t kHostAddress = 0x00;       // telegrams to the scanner
constexpr std::uint8_t kDeviceAddressBit = 0x80;  // telegrams from the scanner: ADR | 0x80
// Commands / responses used here.
constexpr std::uint8_t kCmdModeChange = 0x20;      // data: mode (0x24 continuous all values, 0x40.. baud)
constexpr std::uint8_t kRespModeChange = 0xA0;     // data: 0x00 success, status
constexpr std::uint8_t kRespMeasuredValues = 0xB0; // continuous output of measured values
constexpr std::uint8_t kModeContinuousAll = 0x24;
constexpr std::uint8_t kModeBaud38400 = 0x40, kModeBaud19200 = 0x41, kModeBaud9600 = 0x42, kModeBaud500k = 0x48;

constexpr std::size_t kMaxTelegramData = 812;  // CMD + 2-byte count + 401 values + status (LMS2xx max)
constexpr std::size_t kMaxTelegramBytes = 4 + kMaxTelegramData + 2;
constexpr std::uint16_t kSickNoReturn = 0x1FFF;  // 13-bit distance all ones: no echo / dazzled
constexpr std::size_t kMaxMeasuredValues = 401;

std::uint16_t sick_crc16(const std::uint8_t* data, std::size_t len);

struct SickTelegram {
  std::uint8_t address = 0;
  std::uint16_t length = 0;  // CMD + data (+ status)
  std::uint8_t command = 0;
  std::uint8_t data[kMaxTelegramData] = {};  // bytes after CMD (length - 1 of them)
};

struct SickParserStats {
  std::uint32_t telegrams = 0;
  std::uint32_t crc_errors = 0;
  std::uint32_t bad_length = 0;     // LEN 0 or beyond the LMS2xx maximum
  std::uint32_t garbage_bytes = 0;  // bytes skipped while searching for STX
  std::uint32_t acks = 0, naks = 0; // single-byte replies outside telegrams
  std::uint32_t overflow_bytes = 0; // input dropped because the buffer was full
};

class SickParser {
 public:
  // Appends bytes; returns how many were taken (less than n only when the buffer is full:
  // call next() until false, then feed the rest).
  std::size_t feed(const std::uint8_t* bytes, std::size_t n);
  // Extracts the next complete, CRC-checked telegram; false when none is complete yet.
  bool next(SickTelegram* out);
  const SickParserStats& stats() const { return stats_; }
  void reset() { size_ = 0; }

 private:
  void drop_front(std::size_t n);
  std::uint8_t buf_[2 * kMaxTelegramBytes] = {};
  std::size_t size_ = 0;
  SickParserStats stats_;
};

// Encodes a telegram with `payload` = CMD + data (+ status). Returns bytes written (0 if it does
// not fit or the payload is empty/too long).
std::size_t encode_sick_telegram(std::uint8_t address, const std::uint8_t* payload, std::size_t payload_len,
                                 std::uint8_t* out, std::size_t capacity);

// Measured values (response 0xB0): count word (bits 0..9 count, bits 14..15 unit: 0 cm, 1 mm),
// values (u16, low 13 bits distance), status byte.
struct MeasuredValues {
  std::uint16_t count = 0;
  bool unit_mm = false;
  std::uint16_t values[kMaxMeasuredValues] = {};  // raw 13-bit distances in `unit`
  std::uint8_t status = 0;
};
fw::Status decode_measured_values(const SickTelegram& t, MeasuredValues* out);
std::size_t encode_measured_values(const MeasuredValues& v, std::uint8_t* out, std::size_t capacity);

}  // namespace hal_serial
