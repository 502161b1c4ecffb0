// SerialPort: a byte stream (termios on Linux, a pty or in-memory pipe in tests/simulation).
#pragma once

#include <cstddef>
#include <cstdint>

namespace hal {

class SerialPort {
 public:
  virtual ~SerialPort() = default;
  // Non-blocking: returns bytes read (0 if none), or -1 on error.
  virtual long read(std::uint8_t* buf, std::size_t len) = 0;
  // Returns bytes written, or -1 on error.
  virtual long write(const std::uint8_t* buf, std::size_t len) = 0;
  // False while the port is gone (peer closed, device unplugged) and not yet reopened.
  virtual bool connected() const { return true; }
};

}  // namespace hal
