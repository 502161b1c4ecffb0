// RecordingSerialPort: a hal::SerialPort between a laser driver and its port that records every
// chunk read (stamped with the clock at the read: the time the driver itself stamps a scan with)
// and every chunk written into a SerialBlackBox. Recording at the port, not in each driver, keeps
// the three protocols (SICK, Hokuyo, RPLIDAR) untouched and records exactly the bytes a replay
// must feed back. Either part may be unset (then it only passes through).
#pragma once

#include <cstddef>
#include <cstdint>

#include "hal/clock.h"
#include "hal/serial_port.h"
#include "hal_serial/serial_black_box.h"

namespace hal_serial {

class RecordingSerialPort final : public hal::SerialPort {
 public:
  void init(hal::SerialPort* inner, const hal::Clock* clock, SerialBlackBox* box) {
    inner_ = inner;
    clock_ = clock;
    box_ = box;
  }
  void set_black_box(SerialBlackBox* box) { box_ = box; }
  long read(std::uint8_t* buf, std::size_t len) override;
  long write(const std::uint8_t* buf, std::size_t len) override;
  bool connected() const override { return inner_ != nullptr && inner_->connected(); }

 private:
  std::uint64_t now() const { return clock_ != nullptr ? clock_->now_ns() : 0; }
  hal::SerialPort* inner_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  SerialBlackBox* box_ = nullptr;
};

}  // namespace hal_serial
