#include "hal_serial/serial_black_box.h"

#include <cstdio>
#include <cstring>
#include "hal/hex_bytes.h"

namespace hal_serial {

void SerialBlackBox::init(SerialBlackBoxEntry* storage, std::size_t capacity) {
  storage_ = storage;
  capacity_ = storage != nullptr ? capacity : 0;
  head_ = count_ = 0;
  recorded_ = bytes_ = 0;
}

void SerialBlackBox::record(const std::uint8_t* bytes, std::size_t n, std::uint64_t t_ns, bool tx) {
  if (capacity_ == 0 || bytes == nullptr) return;
  bytes_ += n;
  while (n > 0) {
    const std::size_t k = n < kChunkBytes ? n : kChunkBytes;
    SerialBlackBoxEntry& e = storage_[head_];
    e.t_ns = t_ns;
    e.len = static_cast<std::uint8_t>(k);
    e.flags = tx ? SerialBlackBoxEntry::kTx : 0;
    std::memcpy(e.data, bytes, k);
    bytes += k;
    n -= k;
    head_ = (head_ + 1) % capacity_;
    if (count_ < capacity_) ++count_;
    ++recorded_;
  }
}

std::size_t SerialBlackBox::format_line(std::size_t i, char* buf, std::size_t cap) const {
  if (i >= count_ || cap < kMaxLineBytes) return 0;
  const SerialBlackBoxEntry& e = entry(i);
  // The µs of the HAL clock, as the CAN lines: the replay sets its clock to them, so the recording
  // side keeps times on whole µs (the simulation's are; a robot's lose < 1 µs).
  const unsigned long long us = e.t_ns / 1000;
  int n = std::snprintf(buf, cap, "(%llu.%06llu) %s laser ", us / 1000000, us % 1000000,
                        (e.flags & SerialBlackBoxEntry::kTx) ? "tx" : "rx");
  n += static_cast<int>(hal::write_hex_bytes(e.data, e.len, buf + n));
  buf[n++] = '\n';
  buf[n] = '\0';
  return static_cast<std::size_t>(n);
}

}  // namespace hal_serial
