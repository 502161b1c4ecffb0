// SerialBlackBox (issue 60): the serial counterpart of hal_can::BlackBox — the last minutes of the
// bytes the firmware read from the laser port (each chunk as read(2) returned it, with its receive
// time) and wrote to it (requests, handshakes), in a fixed ring the start-up arena holds. A fault,
// DUMP_LOG or the exit writes it (hal_linux/black_box_file.h) as lines
//   (SEC.USEC) rx laser 02800506B0...     bytes read, in hex, at most kChunkBytes per line
//   (SEC.USEC) tx laser 0200020020244334   bytes written
// beside the CAN lines of the same file (hal/serial/README.md "Black box"). A chunk longer than
// kChunkBytes takes several entries of the same time, so the ring's unit is fixed (no heap, no
// variable-length records to walk) and a line stays short. Not thread-safe: the sensor context
// records and formats. Never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

namespace hal_serial {

struct SerialBlackBoxEntry {
  static constexpr std::size_t kChunkBytes = 64;
  std::uint64_t t_ns = 0;  // receive time (rx) or write time (tx), the HAL clock
  std::uint8_t len = 0;
  std::uint8_t flags = 0;  // kTx
  std::uint8_t data[kChunkBytes] = {};
  static constexpr std::uint8_t kTx = 1;
};

class SerialBlackBox {
 public:
  static constexpr std::size_t kChunkBytes = SerialBlackBoxEntry::kChunkBytes;
  // "(" 20 digits "." 6 ") tx laser " + 128 hex + "\n" + NUL.
  static constexpr std::size_t kMaxLineBytes = 192;

  // `storage` of `capacity` entries (the start-up arena's); capacity 0 = off (record() ignores).
  void init(SerialBlackBoxEntry* storage, std::size_t capacity);
  bool enabled() const { return capacity_ > 0; }
  // Records n bytes (split into kChunkBytes entries, all stamped t_ns).
  void record(const std::uint8_t* bytes, std::size_t n, std::uint64_t t_ns, bool tx);

  std::size_t size() const { return count_; }
  std::size_t capacity() const { return capacity_; }
  std::uint64_t recorded() const { return recorded_; }  // entries since init
  std::uint64_t overwritten() const { return recorded_ - count_; }
  std::uint64_t bytes_recorded() const { return bytes_; }
  // i = 0 is the oldest entry kept.
  const SerialBlackBoxEntry& entry(std::size_t i) const {
    return storage_[(head_ + capacity_ - count_ + i) % capacity_];
  }
  // The i-th oldest entry as one line with its newline; its length (0 if it does not fit in cap).
  std::size_t format_line(std::size_t i, char* buf, std::size_t cap) const;

 private:
  SerialBlackBoxEntry* storage_ = nullptr;
  std::size_t capacity_ = 0, head_ = 0, count_ = 0;
  std::uint64_t recorded_ = 0, bytes_ = 0;
};

}  // namespace hal_serial
