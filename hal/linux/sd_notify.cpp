#include "hal_linux/sd_notify.h"

#include <errno.h>
#include <fcntl.h>
#include <stdlib.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

namespace hal_linux {

namespace {
// Strict unsigned decimal (no sign, no spaces, no trailing text); false on overflow.
bool parse_u64(const char* s, std::uint64_t* out) {
  if (s == nullptr || *s == '\0') return false;
  std::uint64_t v = 0;
  for (; *s; ++s) {
    if (*s < '0' || *s > '9') return false;
    const std::uint64_t d = static_cast<std::uint64_t>(*s - '0');
    if (v > (~std::uint64_t(0) - d) / 10) return false;
    v = v * 10 + d;
  }
  *out = v;
  return true;
}
}  // namespace

fw::Status SdNotify::open_from_env() {
  return open(getenv("NOTIFY_SOCKET"), getenv("WATCHDOG_USEC"), getenv("WATCHDOG_PID"), static_cast<long>(getpid()));
}

fw::Status SdNotify::open(const char* notify_socket, const char* watchdog_usec, const char* watchdog_pid, long pid) {
  close();
  watchdog_ns_ = 0;
  if (notify_socket == nullptr || notify_socket[0] == '\0') return fw::Status::ok();
  const std::size_t len = std::strlen(notify_socket);
  if ((notify_socket[0] != '/' && notify_socket[0] != '@') || len < 2 || len > sizeof(addr_.sun_path) - 1) {
    return fw::Status::error(fw::Errc::kInvalidArgument,
                             "NOTIFY_SOCKET '%.120s': not an absolute socket path or @abstract name of at most %zu "
                             "characters",
                             notify_socket, sizeof(addr_.sun_path) - 1);
  }
  if (watchdog_usec != nullptr && watchdog_usec[0] != '\0') {
    std::uint64_t usec = 0;
    if (!parse_u64(watchdog_usec, &usec) || usec == 0 || usec > (~std::uint64_t(0)) / 1000) {
      return fw::Status::error(fw::Errc::kInvalidArgument, "WATCHDOG_USEC '%.40s': not a positive number of microseconds",
                               watchdog_usec);
    }
    std::uint64_t owner = 0;
    // WATCHDOG_PID names the process the watchdog is meant for; another process's watchdog
    // (inherited through a wrapper) is not ours to feed.
    const bool pid_set = watchdog_pid != nullptr && watchdog_pid[0] != '\0';
    if (pid_set && !parse_u64(watchdog_pid, &owner)) {
      return fw::Status::error(fw::Errc::kInvalidArgument, "WATCHDOG_PID '%.40s': not a process id", watchdog_pid);
    }
    if (!pid_set || owner == static_cast<std::uint64_t>(pid)) watchdog_ns_ = usec * 1000;
  }
  std::memset(&addr_, 0, sizeof(addr_));
  addr_.sun_family = AF_UNIX;
  std::memcpy(addr_.sun_path, notify_socket, len);
  if (notify_socket[0] == '@') addr_.sun_path[0] = '\0';  // abstract namespace
  addr_len_ = static_cast<socklen_t>(offsetof(sockaddr_un, sun_path) + len);
  std::memcpy(name_, notify_socket, len);
  name_[len] = '\0';
  fd_ = ::socket(AF_UNIX, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd_ < 0) {
    return fw::Status::error(fw::Errc::kIoError, "NOTIFY_SOCKET '%s': socket(AF_UNIX, SOCK_DGRAM): %s", name_,
                             std::strerror(errno));
  }
  return fw::Status::ok();
}

void SdNotify::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

fw::Status SdNotify::send(const char* message) {
  if (fd_ < 0) return fw::Status::ok();
  const std::size_t len = std::strlen(message);
  ssize_t n;
  do {
    n = ::sendto(fd_, message, len, MSG_NOSIGNAL | MSG_DONTWAIT, reinterpret_cast<const sockaddr*>(&addr_), addr_len_);
  } while (n < 0 && errno == EINTR);
  if (n != static_cast<ssize_t>(len)) {
    ++failed_;
    return fw::Status::error(fw::Errc::kIoError, "NOTIFY_SOCKET '%s': sending '%.40s' failed: %s", name_, message,
                             n < 0 ? std::strerror(errno) : "short write");
  }
  ++sent_;
  return fw::Status::ok();
}

}  // namespace hal_linux
