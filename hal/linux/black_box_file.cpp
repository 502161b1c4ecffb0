#include "hal_linux/black_box_file.h"

#include <errno.h>
#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstring>

namespace hal_linux {
namespace {

bool write_all(int fd, const char* p, std::size_t n) {
  while (n > 0) {
    const ssize_t w = ::write(fd, p, n);
    if (w < 0 && errno == EINTR) continue;
    if (w <= 0) return false;
    p += w;
    n -= static_cast<std::size_t>(w);
  }
  return true;
}

// The next line of the two rings in time order (CAN first at equal times: on the robot a frame
// and a serial chunk of the same µs were both pending before the loop cycle that read them).
class MergedLines {
 public:
  MergedLines(const hal_can::BlackBox* can, const hal_serial::SerialBlackBox* serial)
      : can_(can), serial_(serial), nc_(can ? can->size() : 0), ns_(serial ? serial->size() : 0) {}
  bool done() const { return ic_ >= nc_ && is_ >= ns_; }
  std::size_t next(char* buf, std::size_t cap) {
    const bool take_can =
        is_ >= ns_ || (ic_ < nc_ && can_->entry(ic_).t_ns / 1000 <= serial_->entry(is_).t_ns / 1000);
    return take_can ? can_->format_line(ic_++, buf, cap) : serial_->format_line(is_++, buf, cap);
  }

 private:
  const hal_can::BlackBox* can_;
  const hal_serial::SerialBlackBox* serial_;
  std::size_t nc_, ns_, ic_ = 0, is_ = 0;
};

constexpr std::size_t kMaxLine = hal_can::BlackBox::kMaxLineBytes > hal_serial::SerialBlackBox::kMaxLineBytes
                                     ? hal_can::BlackBox::kMaxLineBytes
                                     : hal_serial::SerialBlackBox::kMaxLineBytes;

fw::Status fail_write(int fd, const char* tmp, int err) {
  ::close(fd);
  ::unlink(tmp);
  return fw::Status::error(fw::Errc::kIoError, "black box '%s': write failed: %s", tmp, std::strerror(err));
}

}  // namespace

fw::Status write_black_box_file(const hal_can::BlackBox& box, const char* path, std::size_t* written) {
  return write_black_box_file(&box, nullptr, path, written);
}

fw::Status write_black_box_file(const hal_can::BlackBox* can, const hal_serial::SerialBlackBox* serial,
                                const char* path, std::size_t* written) {
  if (written != nullptr) *written = 0;
  if (path == nullptr || !path[0]) return fw::Status::error(fw::Errc::kInvalidArgument, "black box: no path");
  char tmp[300];
  if (std::snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= static_cast<int>(sizeof(tmp))) {
    return fw::Status::error(fw::Errc::kInvalidArgument, "black box '%s': path too long", path);
  }
  const int fd = ::open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fw::Status::error(fw::Errc::kIoError, "black box '%s': cannot create: %s", tmp, std::strerror(errno));
  static char buf[65536];  // sensor context only (the rings are not thread-safe either)
  std::size_t used = 0, total = 0;
  MergedLines lines(can, serial);
  while (!lines.done()) {
    if (sizeof(buf) - used < kMaxLine) {
      if (!write_all(fd, buf, used)) return fail_write(fd, tmp, errno);
      total += used;
      used = 0;
    }
    used += lines.next(buf + used, sizeof(buf) - used);
  }
  if (!write_all(fd, buf, used) || ::fsync(fd) != 0) return fail_write(fd, tmp, errno);
  total += used;
  ::close(fd);
  if (::rename(tmp, path) != 0) {
    const int e = errno;
    ::unlink(tmp);
    return fw::Status::error(fw::Errc::kIoError, "black box '%s': cannot replace: %s", path, std::strerror(e));
  }
  if (written != nullptr) *written = total;
  return fw::Status::ok();
}

}  // namespace hal_linux
