#include "hal_serial/recording_serial_port.h"

namespace hal_serial {

long RecordingSerialPort::read(std::uint8_t* buf, std::size_t len) {
  if (inner_ == nullptr) return -1;
  const long n = inner_->read(buf, len);
  if (n > 0 && box_ != nullptr) box_->record(buf, static_cast<std::size_t>(n), now(), false);
  return n;
}

long RecordingSerialPort::write(const std::uint8_t* buf, std::size_t len) {
  if (inner_ == nullptr) return -1;
  const long n = inner_->write(buf, len);
  // Only what went out: a refused or short write is recorded as far as the port took it.
  if (n > 0 && box_ != nullptr) box_->record(buf, static_cast<std::size_t>(n), now(), true);
  return n;
}

}  // namespace hal_serial
