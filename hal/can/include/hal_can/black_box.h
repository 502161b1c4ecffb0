// BlackBox (issue 60): the last minutes of the CAN traffic the firmware received (with their
// receive times) and sent, in a fixed ring the start-up arena holds, so a fault, an operator's
// DUMP_LOG or the exit can write what the robot saw as a candump log (hal/can/README.md "Black
// box"): "(SEC.USEC) rx ID#DATA" for received frames, "... tx ..." for sent ones, CAN FD as "##F".
// canplayer replays it (`canplayer -I FILE vcan0=rx`), `mml-sim --replay-blackbox FILE` feeds the rx
// frames back through CanNode in lockstep and compares its POSE frames with the tx ones.
// The same ring keeps the global search's records (hal/msg/global_record.h; a robot with
// global_context = thread): "(SEC.USEC) global take|drop SEC.USEC ROUNDS", one entry each, so they
// are kept and overwritten with the frames around them.
// Not thread-safe: recorded and formatted from the sensor context only. Never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/can_bus.h"
#include "hal/global_record_sink.h"

namespace hal_can {

struct BlackBoxEntry {
  std::uint64_t t_ns = 0;  // receive time (rx) or send time (tx), local monotonic clock
  std::uint32_t id = 0;
  std::uint8_t len = 0;
  std::uint8_t flags = 0;  // kTx | kFd | kBrs | kExtended, or kGlobal (| kDropped)
  std::uint8_t data[hal::CanFrame::kMaxData] = {};
  static constexpr std::uint8_t kTx = 1, kFd = 2, kBrs = 4, kExtended = 8;
  // A global record, not a frame: t_ns = the scan it was taken at, data = the job's scan time (8
  // bytes, little-endian) and pRANSAM's deadline rounds (4 bytes); kDropped = thrown away.
  static constexpr std::uint8_t kGlobal = 16, kDropped = 32;
  bool is_global() const { return (flags & kGlobal) != 0; }
};

class BlackBox final : public hal::GlobalRecordSink {
 public:
  // Longest line format_line() writes: "(" 20 digits "." 6 ") tx " 8 "##F" 128 hex "\n" + NUL.
  static constexpr std::size_t kMaxLineBytes = 192;

  // `storage` of `capacity` entries (the start-up arena's); capacity 0 = off (record() ignores).
  void init(BlackBoxEntry* storage, std::size_t capacity);
  bool enabled() const { return capacity_ > 0; }
  void record(const hal::CanFrame& frame, std::uint64_t t_ns, bool tx);
  // One entry for a global result taken or dropped (issue 60), stamped with its scan's time.
  void record_global(const hal::GlobalRecord& r) override;
  // The record of a kGlobal entry.
  static hal::GlobalRecord global_of(const BlackBoxEntry& e);

  std::size_t size() const { return count_; }
  std::size_t capacity() const { return capacity_; }
  std::uint64_t recorded() const { return recorded_; }        // since init
  std::uint64_t overwritten() const { return recorded_ - count_; }
  // i = 0 is the oldest entry kept.
  const BlackBoxEntry& entry(std::size_t i) const { return storage_[(head_ + capacity_ - count_ + i) % capacity_]; }
  // The i-th oldest entry as one candump -L line with its newline; returns its length (0 if it
  // does not fit in `cap` bytes).
  std::size_t format_line(std::size_t i, char* buf, std::size_t cap) const;
  // The frame of an entry (timestamp_ns = t_ns), as CanNode received or sent it (not for kGlobal).
  static hal::CanFrame frame_of(const BlackBoxEntry& e);

 private:
  BlackBoxEntry& next_slot();
  static std::size_t format_global(const BlackBoxEntry& e, char* buf, std::size_t cap);
  BlackBoxEntry* storage_ = nullptr;
  std::size_t capacity_ = 0, head_ = 0, count_ = 0;
  std::uint64_t recorded_ = 0;
};

}  // namespace hal_can
