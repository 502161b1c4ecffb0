// The single adapter file that sees <linux/can.h> (Zephyr style). Socket setup follows the usual
// SocketCAN sequence (ArduPilot's AP_HAL_Linux CAN driver does the same): socket → ifindex → MTU
// → options → bind, non-blocking.
#include "hal_socketcan/socketcan_bus.h"

#include <errno.h>
#include <fcntl.h>
#include <linux/can.h>
#include <linux/can/error.h>
#include <linux/can/raw.h>
#include <net/if.h>
#include <poll.h>
#include <string.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

#include <cstring>

namespace hal_socketcan {
namespace {

using fw::Errc;
using fw::Status;

std::int64_t ts_ns(const timespec& t) { return static_cast<std::int64_t>(t.tv_sec) * 1000000000ll + t.tv_nsec; }

std::int64_t realtime_minus_mono() {
  timespec r{}, m{};
  clock_gettime(CLOCK_REALTIME, &r);
  clock_gettime(CLOCK_MONOTONIC, &m);
  return ts_ns(r) - ts_ns(m);
}

}  // namespace

Status SocketCanBus::open(const char* iface, const SocketCanOptions& o) {
  close();
  if (!iface || !*iface || std::strlen(iface) >= sizeof(iface_) || std::strlen(iface) >= IFNAMSIZ) {
    return Status::error(Errc::kInvalidArgument, "socketcan: interface name '%s' empty or too long", iface ? iface : "");
  }
  std::strncpy(iface_, iface, sizeof(iface_) - 1);
  stats_ = hal::CanBusStats{};
  int s = ::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW);
  if (s < 0) {
    const int e = errno;
    return Status::error(e == EAFNOSUPPORT ? Errc::kUnsupported : Errc::kIoError,
                         "socketcan '%s': socket(PF_CAN): %s%s", iface, strerror(e),
                         e == EAFNOSUPPORT ? " (kernel without CAN support; run inside UML, see tests/hil)" : "");
  }
  ifreq ifr{};
  std::strncpy(ifr.ifr_name, iface, IFNAMSIZ - 1);
  if (::ioctl(s, SIOCGIFINDEX, &ifr) < 0) {
    const int e = errno;
    ::close(s);
    return Status::error(Errc::kNotFound, "socketcan '%s': no such interface: %s", iface, strerror(e));
  }
  const int ifindex = ifr.ifr_ifindex;
  int mtu = CAN_MTU;
  if (::ioctl(s, SIOCGIFMTU, &ifr) == 0) mtu = ifr.ifr_mtu;
  fd_frames_ = false;
  if (o.want_fd && mtu == CANFD_MTU) {
    const int on = 1;
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FD_FRAMES, &on, sizeof(on)) == 0) fd_frames_ = true;
  }
  if (o.require_fd && !fd_frames_) {
    ::close(s);
    return Status::error(Errc::kUnsupported, "socketcan '%s': CAN FD required but interface MTU is %d (need %d)",
                         iface, mtu, static_cast<int>(CANFD_MTU));
  }
  if (o.num_filters > SocketCanOptions::kMaxFilters) {
    ::close(s);
    return Status::error(Errc::kInvalidArgument, "socketcan '%s': %zu filters > max %zu", iface, o.num_filters,
                         SocketCanOptions::kMaxFilters);
  }
  if (o.num_filters > 0) {
    can_filter f[SocketCanOptions::kMaxFilters];
    for (std::size_t i = 0; i < o.num_filters; ++i) {
      f[i].can_id = o.filters[i].id | (o.filters[i].extended ? CAN_EFF_FLAG : 0);
      f[i].can_mask = o.filters[i].mask | CAN_EFF_FLAG | CAN_RTR_FLAG;
    }
    if (::setsockopt(s, SOL_CAN_RAW, CAN_RAW_FILTER, f, static_cast<socklen_t>(sizeof(can_filter) * o.num_filters)) < 0) {
      const int e = errno;
      ::close(s);
      return Status::error(Errc::kIoError, "socketcan '%s': CAN_RAW_FILTER: %s", iface, strerror(e));
    }
  }
  // All error classes: bus-off, controller problems, protocol violations, transceiver, ...
  const can_err_mask_t err_mask = CAN_ERR_MASK;
  ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &err_mask, sizeof(err_mask));
  if (o.receive_own) {
    const int on = 1;
    ::setsockopt(s, SOL_CAN_RAW, CAN_RAW_RECV_OWN_MSGS, &on, sizeof(on));
  }
  const int on = 1;
  ::setsockopt(s, SOL_SOCKET, SO_TIMESTAMPNS, &on, sizeof(on));
  ::setsockopt(s, SOL_SOCKET, SO_RXQ_OVFL, &on, sizeof(on));
  if (o.rcvbuf_bytes > 0) ::setsockopt(s, SOL_SOCKET, SO_RCVBUF, &o.rcvbuf_bytes, sizeof(o.rcvbuf_bytes));

  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = ifindex;
  if (::bind(s, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) < 0) {
    const int e = errno;
    ::close(s);
    return Status::error(Errc::kIoError, "socketcan '%s': bind: %s", iface, strerror(e));
  }
  fd_ = s;
  last_ovfl_ = 0;
  realtime_to_mono_ns_ = realtime_minus_mono();
  return Status::ok();
}

void SocketCanBus::close() {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
}

bool SocketCanBus::wait_readable(int timeout_ms) const {
  if (fd_ < 0) return false;
  pollfd p{fd_, POLLIN, 0};
  return ::poll(&p, 1, timeout_ms) > 0 && (p.revents & POLLIN);
}

bool SocketCanBus::receive(hal::CanFrame* out) {
  if (fd_ < 0) return false;
  for (;;) {
    canfd_frame cf{};
    iovec iov{&cf, sizeof(cf)};
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = cmsg_buf_;
    msg.msg_controllen = sizeof(cmsg_buf_);
    const ssize_t n = ::recvmsg(fd_, &msg, MSG_DONTWAIT);
    if (n < 0) return false;  // EAGAIN: nothing pending (other errors: also nothing to deliver)
    std::uint64_t t_ns = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level != SOL_SOCKET) continue;
      if (c->cmsg_type == SO_TIMESTAMPNS) {
        timespec t{};
        std::memcpy(&t, CMSG_DATA(c), sizeof(t));
        t_ns = static_cast<std::uint64_t>(ts_ns(t) - realtime_to_mono_ns_);
      } else if (c->cmsg_type == SO_RXQ_OVFL) {
        std::uint32_t ovfl = 0;
        std::memcpy(&ovfl, CMSG_DATA(c), sizeof(ovfl));
        // Cumulative count of frames the kernel dropped for this socket.
        stats_.rx_dropped += static_cast<std::uint32_t>(ovfl - last_ovfl_);
        last_ovfl_ = ovfl;
      }
    }
    if (n != static_cast<ssize_t>(CAN_MTU) && n != static_cast<ssize_t>(CANFD_MTU)) continue;  // not a CAN frame
    if (cf.can_id & CAN_ERR_FLAG) {
      ++stats_.error_frames;
      const canid_t cls = cf.can_id & CAN_ERR_MASK;
      if (cls & CAN_ERR_BUSOFF) ++stats_.bus_off;
      if (cls & CAN_ERR_CRTL) ++err_ctrl_;
      if (cls & CAN_ERR_PROT) ++err_prot_;
      continue;  // error frames are counted, never delivered as data
    }
    if (cf.can_id & CAN_RTR_FLAG) continue;  // our protocol uses no remote frames
    if (cf.len > (n == static_cast<ssize_t>(CANFD_MTU) ? CANFD_MAX_DLEN : CAN_MAX_DLEN)) continue;
    out->extended = (cf.can_id & CAN_EFF_FLAG) != 0;
    out->id = cf.can_id & (out->extended ? CAN_EFF_MASK : CAN_SFF_MASK);
    out->fd = n == static_cast<ssize_t>(CANFD_MTU);
    out->brs = out->fd && (cf.flags & CANFD_BRS);
    out->len = cf.len;
    std::memcpy(out->data, cf.data, cf.len);
    if (cf.len < hal::CanFrame::kMaxData) std::memset(out->data + cf.len, 0, hal::CanFrame::kMaxData - cf.len);
    if (t_ns == 0) {
      timespec m{};
      clock_gettime(CLOCK_MONOTONIC, &m);
      t_ns = static_cast<std::uint64_t>(ts_ns(m));
    }
    out->timestamp_ns = t_ns;
    ++stats_.rx_frames;
    return true;
  }
}

bool SocketCanBus::send(const hal::CanFrame& f) {
  if (fd_ < 0 || (f.fd && !fd_frames_) || f.len > (f.fd ? CANFD_MAX_DLEN : CAN_MAX_DLEN)) {
    ++stats_.tx_failed;
    last_errno_ = fd_ < 0 ? EBADF : EINVAL;
    return false;
  }
  canfd_frame cf{};
  cf.can_id = f.extended ? ((f.id & CAN_EFF_MASK) | CAN_EFF_FLAG) : (f.id & CAN_SFF_MASK);
  cf.len = f.len;
  if (f.fd) cf.flags = f.brs ? CANFD_BRS : 0;
  std::memcpy(cf.data, f.data, f.len);
  const std::size_t size = f.fd ? CANFD_MTU : CAN_MTU;
  const ssize_t n = ::write(fd_, &cf, size);
  if (n != static_cast<ssize_t>(size)) {
    last_errno_ = n < 0 ? errno : EIO;
    ++stats_.tx_failed;
    return false;
  }
  ++stats_.tx_frames;
  return true;
}

}  // namespace hal_socketcan
