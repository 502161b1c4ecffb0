// TermiosPort: hal::SerialPort on a Linux tty (termios): raw 8N1, non-blocking, standard rates
// and 500 kBd (B500000) where the driver accepts it; the rate is read back and verified.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/serial_port.h"

namespace hal_serial {

class TermiosPort final : public hal::SerialPort {
 public:
  TermiosPort() = default;
  TermiosPort(const TermiosPort&) = delete;
  TermiosPort& operator=(const TermiosPort&) = delete;
  ~TermiosPort() override { close(); }

  // baud: 9600, 19200, 38400, 57600, 115200, 230400, 500000. Errors name the device.
  fw::Status open(const char* device, std::uint32_t baud);
  // Changes the rate of an open port (after the scanner acknowledged a baud-rate change).
  fw::Status set_baud(std::uint32_t baud);
  void close();
  bool is_open() const { return fd_ >= 0; }
  int native_handle() const { return fd_; }
  std::uint32_t baud() const { return baud_; }

  long read(std::uint8_t* buf, std::size_t len) override;
  long write(const std::uint8_t* buf, std::size_t len) override;
  bool wait_readable(int timeout_ms) const;

 private:
  int fd_ = -1;
  std::uint32_t baud_ = 0;
  char device_[96] = {0};
};

}  // namespace hal_serial
