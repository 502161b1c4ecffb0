// SocketCanBus: hal::CanBus over a Linux raw CAN socket (the only code that includes
// <linux/can.h>). Classic CAN and CAN FD (CAN_RAW_FD_FRAMES when the interface MTU is 72),
// receive filters, kernel timestamps (SO_TIMESTAMPNS, converted to CLOCK_MONOTONIC), kernel queue
// drop counts (SO_RXQ_OVFL), error frames (CAN_RAW_ERR_FILTER) counted by class with bus-off
// separately. Non-blocking; nothing is allocated after open().
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/can_bus.h"

namespace hal_socketcan {

struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;  // 0 = accept all
  bool extended = false;
};

struct SocketCanOptions {
  static constexpr std::size_t kMaxFilters = 16;
  bool want_fd = true;          // enable FD frames if the interface supports them (MTU 72)
  bool require_fd = false;      // fail open() if it does not
  bool receive_own = false;     // CAN_RAW_RECV_OWN_MSGS (tests)
  int rcvbuf_bytes = 1 << 20;   // SO_RCVBUF request (bursts on slow hosts)
  CanFilter filters[kMaxFilters];
  std::size_t num_filters = 0;  // 0 = receive everything
};

class SocketCanBus final : public hal::CanBus {
 public:
  SocketCanBus() = default;
  SocketCanBus(const SocketCanBus&) = delete;
  SocketCanBus& operator=(const SocketCanBus&) = delete;
  ~SocketCanBus() override { close(); }

  fw::Status open(const char* iface, const SocketCanOptions& options = {});
  void close();
  bool is_open() const { return fd_ >= 0; }
  bool fd_enabled() const { return fd_frames_; }
  int native_handle() const { return fd_; }
  const char* interface_name() const { return iface_; }

  bool receive(hal::CanFrame* out) override;
  bool send(const hal::CanFrame& frame) override;
  const hal::CanBusStats& stats() const override { return stats_; }

  // Blocks up to timeout_ms until a frame is readable (poll(2)); false on timeout/signal.
  bool wait_readable(int timeout_ms) const;
  // Error-frame detail beyond the generic stats.
  std::uint64_t error_frames_controller() const { return err_ctrl_; }
  std::uint64_t error_frames_protocol() const { return err_prot_; }
  // Last errno-style failure of send(), for logs.
  int last_errno() const { return last_errno_; }

 private:
  int fd_ = -1;
  bool fd_frames_ = false;
  char iface_[16] = {0};
  std::int64_t realtime_to_mono_ns_ = 0;
  std::uint32_t last_ovfl_ = 0;
  std::uint64_t err_ctrl_ = 0, err_prot_ = 0;
  int last_errno_ = 0;
  hal::CanBusStats stats_;
  alignas(8) unsigned char cmsg_buf_[128];
};

}  // namespace hal_socketcan
