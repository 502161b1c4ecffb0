#include "hal_serial/termios_port.h"

#include <errno.h>
#include <fcntl.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <termios.h>
#include <unistd.h>

#include <cstring>

#include "termios_custom_rate.h"

namespace hal_serial {
namespace {
using fw::Errc;
using fw::Status;

bool speed_of(std::uint32_t baud, speed_t* out) {
  switch (baud) {
    case 9600: *out = B9600; return true;
    case 19200: *out = B19200; return true;
    case 38400: *out = B38400; return true;
    case 57600: *out = B57600; return true;
    case 115200: *out = B115200; return true;
    case 230400: *out = B230400; return true;
    case 460800: *out = B460800; return true;
    case 500000: *out = B500000; return true;
    case 921600: *out = B921600; return true;
    case 1000000: *out = B1000000; return true;
    default: return false;
  }
}
}  // namespace

Status TermiosPort::open(const char* device, std::uint32_t baud) {
  close();
  if (!device || !*device || std::strlen(device) >= sizeof(device_)) {
    return Status::error(Errc::kInvalidArgument, "serial: device path '%s' empty or too long", device ? device : "");
  }
  std::strncpy(device_, device, sizeof(device_) - 1);
  const int fd = ::open(device, O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC);
  if (fd < 0) {
    const int e = errno;
    return Status::error(Errc::kIoError, "serial '%s': open: %s", device, strerror(e));
  }
  termios t{};
  if (::tcgetattr(fd, &t) != 0) {
    const int e = errno;
    ::close(fd);
    return Status::error(Errc::kIoError, "serial '%s': not a tty (tcgetattr: %s)", device, strerror(e));
  }
  cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~(CSTOPB | PARENB | CRTSCTS);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (::tcsetattr(fd, TCSANOW, &t) != 0) {
    const int e = errno;
    ::close(fd);
    return Status::error(Errc::kIoError, "serial '%s': tcsetattr: %s", device, strerror(e));
  }
  fd_ = fd;
  Status s = set_baud(baud);
  if (!s.is_ok()) close();
  return s;
}

Status TermiosPort::set_baud(std::uint32_t baud) {
  speed_t sp;
  if (baud == 256000) {  // RPLIDAR A3/S1: no B256000, the kernel's termios2 rate instead
    if (fd_ < 0) return Status::error(Errc::kIoError, "serial '%s': not open", device_);
    std::uint32_t actual = 0;
    const int e = set_custom_rate(fd_, baud, &actual);
    if (e != 0) return Status::error(Errc::kUnsupported, "serial '%s': %u Bd refused: %s", device_, baud, strerror(e));
    if (actual != baud) return Status::error(Errc::kUnsupported, "serial '%s': %u Bd not kept (%u)", device_, baud, actual);
    baud_ = baud;
    return Status::ok();
  }
  if (!speed_of(baud, &sp)) {
    return Status::error(Errc::kInvalidArgument, "serial '%s': baud %u not supported (%s)", device_, baud,
                         kSupportedBauds);
  }
  termios t{};
  if (fd_ < 0 || ::tcgetattr(fd_, &t) != 0) return Status::error(Errc::kIoError, "serial '%s': not open", device_);
  cfsetispeed(&t, sp);
  cfsetospeed(&t, sp);
  if (::tcsetattr(fd_, TCSANOW, &t) != 0) {
    const int e = errno;
    return Status::error(Errc::kUnsupported, "serial '%s': %u Bd refused: %s", device_, baud, strerror(e));
  }
  termios back{};
  if (::tcgetattr(fd_, &back) != 0 || cfgetospeed(&back) != sp) {
    return Status::error(Errc::kUnsupported, "serial '%s': %u Bd not kept by the driver", device_, baud);
  }
  baud_ = baud;
  return Status::ok();
}

Status TermiosPort::set_dtr(bool asserted) {
  if (fd_ < 0) return Status::error(Errc::kIoError, "serial '%s': not open", device_);
  int bits = TIOCM_DTR;
  if (::ioctl(fd_, asserted ? TIOCMBIS : TIOCMBIC, &bits) != 0) {
    const int e = errno;
    return Status::error(Errc::kUnsupported, "serial '%s': DTR cannot be set: %s", device_, strerror(e));
  }
  return Status::ok();
}

void TermiosPort::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

long TermiosPort::read(std::uint8_t* buf, std::size_t len) {
  if (fd_ < 0) return -1;
  const ssize_t n = ::read(fd_, buf, len);
  if (n < 0) {
    const int e = errno;
    if (e == EAGAIN || e == EWOULDBLOCK || e == EINTR) return 0;
    // The device is gone (pty peer closed: EIO; adapter unplugged: ENODEV/ENXIO): a dead
    // descriptor polls readable forever, so drop it; the owner reopens the device.
    if (e == EIO || e == ENODEV || e == ENXIO || e == EBADF) hang_up(e);
    return -1;
  }
  return static_cast<long>(n);
}

void TermiosPort::hang_up(int err) {
  if (fd_ < 0) return;
  ++hangups_;
  last_error_ = err;
  close();
}

long TermiosPort::write(const std::uint8_t* buf, std::size_t len) {
  if (fd_ < 0) return -1;
  std::size_t done = 0;
  int spins = 0;
  while (done < len) {
    const ssize_t n = ::write(fd_, buf + done, len - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return -1;
    if (++spins > 200) break;  // ~2 s of a full output queue: give up, report a short write
    pollfd p{fd_, POLLOUT, 0};
    ::poll(&p, 1, 10);
  }
  return static_cast<long>(done);
}

bool TermiosPort::wait_readable(int timeout_ms) const {
  if (fd_ < 0) return false;
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN);
}

}  // namespace hal_serial
