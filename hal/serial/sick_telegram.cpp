#include "hal_serial/sick_telegram.h"

#include <cstring>

namespace hal_serial {

using fw::Errc;
using fw::Status;

// The CRC of the LMS2xx telegram listing (generator 0x8005, the previous byte folded in).
std::uint16_t sick_crc16(const std::uint8_t* data, std::size_t len) {
  std::uint16_t crc = 0;
  std::uint8_t ab[2] = {0, 0};
  for (std::size_t i = 0; i < len; ++i) {
    ab[1] = ab[0];
    ab[0] = data[i];
    if (crc & 0x8000) {
      crc = static_cast<std::uint16_t>((crc & 0x7FFF) << 1);
      crc ^= 0x8005;
    } else {
      crc = static_cast<std::uint16_t>(crc << 1);
    }
    crc ^= static_cast<std::uint16_t>(ab[0] | (ab[1] << 8));
  }
  return crc;
}

std::size_t SickParser::feed(const std::uint8_t* bytes, std::size_t n) {
  const std::size_t room = sizeof(buf_) - size_;
  const std::size_t take = n < room ? n : room;
  std::memcpy(buf_ + size_, bytes, take);
  size_ += take;
  return take;
}

void SickParser::drop_front(std::size_t n) {
  if (n >= size_) {
    size_ = 0;
    return;
  }
  std::memmove(buf_, buf_ + n, size_ - n);
  size_ -= n;
}

bool SickParser::next(SickTelegram* out) {
  for (;;) {
    // Search STX; single ACK/NAK bytes between telegrams are replies to our requests.
    std::size_t skip = 0;
    while (skip < size_ && buf_[skip] != kStx) {
      if (buf_[skip] == kAck) ++stats_.acks;
      else if (buf_[skip] == kNak) ++stats_.naks;
      else ++stats_.garbage_bytes;
      ++skip;
    }
    drop_front(skip);
    if (size_ < 4) return false;
    const std::uint16_t len = static_cast<std::uint16_t>(buf_[2] | (buf_[3] << 8));
    if (len == 0 || len > kMaxTelegramData) {
      ++stats_.bad_length;
      ++stats_.garbage_bytes;
      drop_front(1);  // that STX was not a telegram start
      continue;
    }
    const std::size_t total = 4u + len + 2u;
    if (size_ < total) {
      if (size_ == sizeof(buf_)) {  // cannot happen (buffer holds two maximal telegrams), but never stall
        ++stats_.overflow_bytes;
        drop_front(1);
        continue;
      }
      return false;
    }
    const std::uint16_t crc = static_cast<std::uint16_t>(buf_[4 + len] | (buf_[5 + len] << 8));
    if (sick_crc16(buf_, 4u + len) != crc) {
      ++stats_.crc_errors;
      drop_front(1);  // resync: the next STX may be inside what we took for this telegram
      continue;
    }
    out->address = buf_[1];
    out->length = len;
    out->command = buf_[4];
    std::memcpy(out->data, buf_ + 5, len - 1u);
    drop_front(total);
    ++stats_.telegrams;
    return true;
  }
}

std::size_t encode_sick_telegram(std::uint8_t address, const std::uint8_t* payload, std::size_t payload_len,
                                 std::uint8_t* out, std::size_t capacity) {
  if (payload_len == 0 || payload_len > kMaxTelegramData || capacity < payload_len + 6) return 0;
  out[0] = kStx;
  out[1] = address;
  out[2] = static_cast<std::uint8_t>(payload_len & 0xFF);
  out[3] = static_cast<std::uint8_t>(payload_len >> 8);
  std::memcpy(out + 4, payload, payload_len);
  const std::uint16_t crc = sick_crc16(out, 4 + payload_len);
  out[4 + payload_len] = static_cast<std::uint8_t>(crc & 0xFF);
  out[5 + payload_len] = static_cast<std::uint8_t>(crc >> 8);
  return payload_len + 6;
}

Status decode_measured_values(const SickTelegram& t, MeasuredValues* out) {
  if (t.command != kRespMeasuredValues) {
    return Status::error(Errc::kInvalidArgument, "SICK telegram 0x%02X is not measured values (0xB0)", t.command);
  }
  if (t.length < 4) return Status::error(Errc::kCorruptData, "SICK 0xB0 telegram too short (LEN %u)", t.length);
  const std::uint16_t word = static_cast<std::uint16_t>(t.data[0] | (t.data[1] << 8));
  const std::uint16_t count = word & 0x3FF;
  const unsigned unit = (word >> 14) & 0x3;
  if (count == 0 || count > kMaxMeasuredValues) {
    return Status::error(Errc::kCorruptData, "SICK 0xB0: %u measured values outside 1..%zu", count, kMaxMeasuredValues);
  }
  if (unit > 1) return Status::error(Errc::kUnsupported, "SICK 0xB0: measured value unit %u not cm/mm", unit);
  // LEN = CMD + count word + 2*count + status.
  if (t.length != 1u + 2u + 2u * count + 1u) {
    return Status::error(Errc::kCorruptData, "SICK 0xB0: LEN %u does not match %u values", t.length, count);
  }
  out->count = count;
  out->unit_mm = unit == 1;
  for (std::uint16_t i = 0; i < count; ++i) {
    out->values[i] = static_cast<std::uint16_t>((t.data[2 + 2 * i] | (t.data[3 + 2 * i] << 8)) & 0x1FFF);
  }
  out->status = t.data[2 + 2 * count];
  return Status::ok();
}

std::size_t encode_measured_values(const MeasuredValues& v, std::uint8_t* out, std::size_t capacity) {
  if (v.count == 0 || v.count > kMaxMeasuredValues) return 0;
  std::uint8_t payload[kMaxTelegramData];
  std::size_t n = 0;
  payload[n++] = kRespMeasuredValues;
  const std::uint16_t word = static_cast<std::uint16_t>(v.count | (v.unit_mm ? 0x4000 : 0));
  payload[n++] = static_cast<std::uint8_t>(word & 0xFF);
  payload[n++] = static_cast<std::uint8_t>(word >> 8);
  for (std::uint16_t i = 0; i < v.count; ++i) {
    const std::uint16_t d = v.values[i] & 0x1FFF;
    payload[n++] = static_cast<std::uint8_t>(d & 0xFF);
    payload[n++] = static_cast<std::uint8_t>(d >> 8);
  }
  payload[n++] = v.status;
  return encode_sick_telegram(kDeviceAddressBit, payload, n, out, capacity);
}

}  // namespace hal_serial
