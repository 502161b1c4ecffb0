#include "hal_can/black_box.h"

#include <cstdio>
#include <cstring>

namespace hal_can {

void BlackBox::init(BlackBoxEntry* storage, std::size_t capacity) {
  storage_ = storage;
  capacity_ = storage != nullptr ? capacity : 0;
  head_ = count_ = 0;
  recorded_ = 0;
}

void BlackBox::record(const hal::CanFrame& f, std::uint64_t t_ns, bool tx) {
  if (capacity_ == 0) return;
  BlackBoxEntry& e = storage_[head_];
  e.t_ns = t_ns;
  e.id = f.id;
  e.len = f.len <= hal::CanFrame::kMaxData ? f.len : hal::CanFrame::kMaxData;
  e.flags = static_cast<std::uint8_t>((tx ? BlackBoxEntry::kTx : 0) | (f.fd ? BlackBoxEntry::kFd : 0) |
                                      (f.brs ? BlackBoxEntry::kBrs : 0) | (f.extended ? BlackBoxEntry::kExtended : 0));
  std::memcpy(e.data, f.data, e.len);
  head_ = (head_ + 1) % capacity_;
  if (count_ < capacity_) ++count_;
  ++recorded_;
}

hal::CanFrame BlackBox::frame_of(const BlackBoxEntry& e) {
  hal::CanFrame f;
  f.id = e.id;
  f.len = e.len;
  f.fd = (e.flags & BlackBoxEntry::kFd) != 0;
  f.brs = (e.flags & BlackBoxEntry::kBrs) != 0;
  f.extended = (e.flags & BlackBoxEntry::kExtended) != 0;
  std::memcpy(f.data, e.data, e.len);
  f.timestamp_ns = e.t_ns;
  return f;
}

std::size_t BlackBox::format_line(std::size_t i, char* buf, std::size_t cap) const {
  if (i >= count_ || cap < kMaxLineBytes) return 0;
  const BlackBoxEntry& e = entry(i);
  const unsigned long long us = e.t_ns / 1000;
  int n = std::snprintf(buf, cap, "(%llu.%06llu) %s ", us / 1000000, us % 1000000,
                        (e.flags & BlackBoxEntry::kTx) ? "tx" : "rx");
  if (e.flags & BlackBoxEntry::kExtended) {
    n += std::snprintf(buf + n, cap - n, "%08X", static_cast<unsigned>(e.id & 0x1FFFFFFFu));
  } else {
    n += std::snprintf(buf + n, cap - n, "%03X", static_cast<unsigned>(e.id & 0x7FFu));
  }
  if (e.flags & BlackBoxEntry::kFd) {
    n += std::snprintf(buf + n, cap - n, "##%X", (e.flags & BlackBoxEntry::kBrs) ? 1 : 0);
  } else {
    buf[n++] = '#';
  }
  static const char kHex[] = "0123456789ABCDEF";
  for (std::uint8_t k = 0; k < e.len; ++k) {
    buf[n++] = kHex[e.data[k] >> 4];
    buf[n++] = kHex[e.data[k] & 0xF];
  }
  buf[n++] = '\n';
  buf[n] = '\0';
  return static_cast<std::size_t>(n);
}

}  // namespace hal_can
