#include "hal_sim/sim_serial_port.h"

namespace hal_sim {

long SimSerialPort::read(std::uint8_t* buf, std::size_t len) {
  std::size_t n = 0;
  while (n < len && to_host_.pop(&buf[n])) ++n;
  stats_.read_bytes += n;
  return static_cast<long>(n);
}

long SimSerialPort::write(const std::uint8_t*, std::size_t len) {
  stats_.written_bytes += len;
  return static_cast<long>(len);
}

bool SimSerialPort::device_send(const std::uint8_t* bytes, std::size_t n) {
  if (to_host_.capacity() - to_host_.size() < n) {
    stats_.refused_bytes += n;
    return false;
  }
  for (std::size_t i = 0; i < n; ++i) (void)to_host_.push(bytes[i]);
  stats_.device_bytes += n;
  return true;
}

}  // namespace hal_sim
