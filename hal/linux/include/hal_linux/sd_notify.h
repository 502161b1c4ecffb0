// SdNotify: the sender side of systemd's service notification protocol (sd_notify(3)), written
// here so that the firmware needs no library: one AF_UNIX datagram socket, opened once at
// start-up, each message one sendto(2) of a short text ("READY=1", "WATCHDOG=1", "STATUS=...").
// The service manager names its socket in NOTIFY_SOCKET (a path, or "@name" for the abstract
// namespace) and, with WatchdogSec=, the watchdog period in WATCHDOG_USEC (for WATCHDOG_PID, if
// set). Without NOTIFY_SOCKET (started by hand) every send is a no-op that succeeds.
// No heap: the address is a member, messages are formatted by the caller into its own buffer.
#pragma once

#include <sys/socket.h>
#include <sys/un.h>

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace hal_linux {

class SdNotify {
 public:
  SdNotify() = default;
  SdNotify(const SdNotify&) = delete;
  SdNotify& operator=(const SdNotify&) = delete;
  ~SdNotify() { close(); }

  // Reads NOTIFY_SOCKET / WATCHDOG_USEC / WATCHDOG_PID and opens the socket. A malformed
  // variable is an error naming it (a unit whose watchdog cannot be fed must not start quietly).
  fw::Status open_from_env();
  // The same with explicit values (tests; nullptr = unset). `pid` is this process's id.
  fw::Status open(const char* notify_socket, const char* watchdog_usec, const char* watchdog_pid, long pid);
  void close();

  bool enabled() const { return fd_ >= 0; }
  // Watchdog period the manager expects (0 = no watchdog for this process).
  std::uint64_t watchdog_period_ns() const { return watchdog_ns_; }
  // Sends one message (no trailing newline needed). Fails naming the socket when sendto fails;
  // a manager that went away is not the firmware's fault, so callers count, never stop, on it.
  fw::Status send(const char* message);
  std::uint64_t sent() const { return sent_; }
  std::uint64_t failed() const { return failed_; }
  const char* socket_name() const { return name_; }

 private:
  int fd_ = -1;
  sockaddr_un addr_{};
  socklen_t addr_len_ = 0;
  std::uint64_t watchdog_ns_ = 0;
  std::uint64_t sent_ = 0;
  std::uint64_t failed_ = 0;
  char name_[sizeof(sockaddr_un::sun_path) + 1] = {0};
};

}  // namespace hal_linux
