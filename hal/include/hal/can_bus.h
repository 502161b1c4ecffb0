// CanBus: classic CAN and CAN FD frames without <linux/can.h> (only hal/socketcan includes it).
#pragma once

#include <cstdint>

namespace hal {

struct CanFrame {
  static constexpr std::uint8_t kMaxData = 64;
  std::uint32_t id = 0;        // 11- or 29-bit identifier
  bool extended = false;
  bool fd = false;             // CAN FD frame (up to 64 data bytes)
  bool brs = false;            // FD bit-rate switch
  std::uint8_t len = 0;        // data length in bytes
  std::uint8_t data[kMaxData] = {};
  std::uint64_t timestamp_ns = 0;  // receive time (kernel timestamp when available)
};

struct CanBusStats {
  std::uint64_t rx_frames = 0, tx_frames = 0;
  std::uint64_t rx_dropped = 0;     // kernel queue overflows (SO_RXQ_OVFL)
  std::uint64_t error_frames = 0;
  std::uint64_t bus_off = 0;
  std::uint64_t tx_failed = 0;
};

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Non-blocking receive: true and *out filled if a frame was pending.
  virtual bool receive(CanFrame* out) = 0;
  // Non-blocking send: false if the queue is full or the bus is off (counted in stats).
  virtual bool send(const CanFrame& frame) = 0;
  virtual const CanBusStats& stats() const = 0;
};

}  // namespace hal
