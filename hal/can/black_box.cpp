#include "hal_can/black_box.h"

#include <cstdio>
#include <cstring>
#include "hal/hex_bytes.h"

namespace hal_can {

void BlackBox::init(BlackBoxEntry* storage, std::size_t capacity) {
  storage_ = storage;
  capacity_ = storage != nullptr ? capacity : 0;
  head_ = count_ = 0;
  recorded_ = 0;
}

BlackBoxEntry& BlackBox::next_slot() {
  BlackBoxEntry& e = storage_[head_];
  head_ = (head_ + 1) % capacity_;
  if (count_ < capacity_) ++count_;
  ++recorded_;
  return e;
}

void BlackBox::record(const hal::CanFrame& f, std::uint64_t t_ns, bool tx) {
  if (capacity_ == 0) return;
  BlackBoxEntry& e = next_slot();
  e.t_ns = t_ns;
  e.id = f.id;
  e.len = f.len <= hal::CanFrame::kMaxData ? f.len : hal::CanFrame::kMaxData;
  e.flags = static_cast<std::uint8_t>((tx ? BlackBoxEntry::kTx : 0) | (f.fd ? BlackBoxEntry::kFd : 0) |
                                      (f.brs ? BlackBoxEntry::kBrs : 0) | (f.extended ? BlackBoxEntry::kExtended : 0));
  std::memcpy(e.data, f.data, e.len);
}

void BlackBox::record_global(const hal::GlobalRecord& r) {
  if (capacity_ == 0) return;
  BlackBoxEntry& e = next_slot();
  e.t_ns = r.scan_ns;
  e.id = 0;
  e.len = 12;
  e.flags = static_cast<std::uint8_t>(BlackBoxEntry::kGlobal | (r.dropped ? BlackBoxEntry::kDropped : 0));
  for (int k = 0; k < 8; ++k) e.data[k] = static_cast<std::uint8_t>(r.job_scan_ns >> (8 * k));
  for (int k = 0; k < 4; ++k) e.data[8 + k] = static_cast<std::uint8_t>(r.deadline_rounds >> (8 * k));
}

hal::GlobalRecord BlackBox::global_of(const BlackBoxEntry& e) {
  hal::GlobalRecord r;
  r.scan_ns = e.t_ns;
  for (int k = 0; k < 8; ++k) r.job_scan_ns |= static_cast<std::uint64_t>(e.data[k]) << (8 * k);
  for (int k = 0; k < 4; ++k) r.deadline_rounds |= static_cast<std::uint32_t>(e.data[8 + k]) << (8 * k);
  r.dropped = (e.flags & BlackBoxEntry::kDropped) != 0;
  return r;
}

// "(SEC.USEC) global take|drop SEC.USEC ROUNDS": the scan the result was taken (dropped) at, the
// scan the job was submitted with, pRANSAM's rounds when its deadline stopped it (0: not stopped).
std::size_t BlackBox::format_global(const BlackBoxEntry& e, char* buf, std::size_t cap) {
  const hal::GlobalRecord r = global_of(e);
  const unsigned long long us = r.scan_ns / 1000, job_us = r.job_scan_ns / 1000;
  const int n = std::snprintf(buf, cap, "(%llu.%06llu) global %s %llu.%06llu %u\n", us / 1000000, us % 1000000,
                              r.dropped ? "drop" : "take", job_us / 1000000, job_us % 1000000,
                              static_cast<unsigned>(r.deadline_rounds));
  return n > 0 && static_cast<std::size_t>(n) < cap ? static_cast<std::size_t>(n) : 0;
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
  if (e.is_global()) return format_global(e, buf, cap);
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
  n += static_cast<int>(hal::write_hex_bytes(e.data, e.len, buf + n));
  buf[n++] = '\n';
  buf[n] = '\0';
  return static_cast<std::size_t>(n);
}

}  // namespace hal_can
