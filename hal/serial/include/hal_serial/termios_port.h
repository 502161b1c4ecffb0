// TermiosPort: hal::SerialPort on a Linux tty (termios): raw 8N1, non-blocking, standard rates,
// 460800/500000/921600/1000000 Bd where the driver accepts them and 256000 Bd (RPLIDAR A3/S1)
// through termios2; the rate is read back and verified. DTR can be set (the RPLIDAR A1 adapter's
// motor enable).
// A port whose peer went away (pty master closed: EIO; USB adapter unplugged: ENODEV/ENXIO; a
// hang-up seen by poll) is closed by read()/hang_up() and reports connected() == false, so the
// caller stops polling a dead descriptor (it used to spin ~7000 reads a second) and reopens it.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/serial_port.h"

namespace hal_serial {

constexpr const char* kSupportedBauds = "9600, 19200, 38400, 57600, 115200, 230400, 256000, 460800, 500000, 921600, 1000000";

class TermiosPort final : public hal::SerialPort {
 public:
  TermiosPort() = default;
  TermiosPort(const TermiosPort&) = delete;
  TermiosPort& operator=(const TermiosPort&) = delete;
  ~TermiosPort() override { close(); }

  // baud: one of kSupportedBauds. Errors name the device.
  fw::Status open(const char* device, std::uint32_t baud);
  // Changes the rate of an open port (after the scanner acknowledged a baud-rate change).
  fw::Status set_baud(std::uint32_t baud);
  // Asserts or clears DTR (TIOCMBIS/TIOCMBIC); a port without modem lines (a pty) refuses.
  fw::Status set_dtr(bool asserted);
  void close();
  bool is_open() const { return fd_ >= 0; }
  int native_handle() const { return fd_; }
  std::uint32_t baud() const { return baud_; }

  long read(std::uint8_t* buf, std::size_t len) override;
  long write(const std::uint8_t* buf, std::size_t len) override;
  bool connected() const override { return fd_ >= 0; }
  bool wait_readable(int timeout_ms) const;
  // Closes the port after a hang-up (poll reported POLLHUP/POLLERR/POLLNVAL); `err` is the errno
  // to report (0: "hang-up").
  void hang_up(int err);
  // Times the port was lost (read error or hang-up) and the errno of the last loss.
  std::uint32_t hangups() const { return hangups_; }
  int last_error() const { return last_error_; }

 private:
  int fd_ = -1;
  std::uint32_t baud_ = 0;
  std::uint32_t hangups_ = 0;
  int last_error_ = 0;
  char device_[128] = {0};
};

}  // namespace hal_serial
