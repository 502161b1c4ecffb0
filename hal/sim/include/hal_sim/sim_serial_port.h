// SimSerialPort: the simulation backend of hal::SerialPort, a pty pair in memory. The simulated
// device (sim/devices/sensor_transport) puts the bytes a real scanner would send with
// device_send(); the firmware's driver (hal_serial::SickLaser) reads them with read(). What the
// firmware writes (requests) is counted and discarded: the simulated device streams anyway.
// Fixed capacity, no heap: bytes that do not fit are refused and counted, as a full tty buffer.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "hal/serial_port.h"

namespace hal_sim {

struct SimSerialStats {
  std::uint64_t device_bytes = 0, read_bytes = 0, written_bytes = 0, refused_bytes = 0;
};

class SimSerialPort final : public hal::SerialPort {
 public:
  // Several LMS2xx telegrams (at most 812 data bytes + 6 framing each).
  static constexpr std::size_t kCapacity = 8192;

  long read(std::uint8_t* buf, std::size_t len) override;
  long write(const std::uint8_t* buf, std::size_t len) override;
  // Device side: queues n bytes for the firmware; false (nothing queued, counted) if they do not fit.
  bool device_send(const std::uint8_t* bytes, std::size_t n);
  const SimSerialStats& stats() const { return stats_; }

 private:
  fw::RingBuffer<std::uint8_t, kCapacity> to_host_;
  SimSerialStats stats_;
};

}  // namespace hal_sim
