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

}  // namespace

fw::Status write_black_box_file(const hal_can::BlackBox& box, const char* path, std::size_t* written) {
  if (written != nullptr) *written = 0;
  if (path == nullptr || !path[0]) return fw::Status::error(fw::Errc::kInvalidArgument, "black box: no path");
  char tmp[300];
  if (std::snprintf(tmp, sizeof(tmp), "%s.tmp", path) >= static_cast<int>(sizeof(tmp))) {
    return fw::Status::error(fw::Errc::kInvalidArgument, "black box '%s': path too long", path);
  }
  const int fd = ::open(tmp, O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) return fw::Status::error(fw::Errc::kIoError, "black box '%s': cannot create: %s", tmp, std::strerror(errno));
  static char buf[65536];  // sensor context only (BlackBox is not thread-safe either)
  std::size_t used = 0, total = 0;
  bool ok = true;
  for (std::size_t i = 0; i < box.size() && ok; ++i) {
    if (sizeof(buf) - used < hal_can::BlackBox::kMaxLineBytes) {
      ok = write_all(fd, buf, used);
      total += used;
      used = 0;
    }
    used += box.format_line(i, buf + used, sizeof(buf) - used);
  }
  ok = ok && write_all(fd, buf, used);
  total += used;
  ok = ok && ::fsync(fd) == 0;
  const int err = errno;
  ::close(fd);
  if (!ok) {
    ::unlink(tmp);
    return fw::Status::error(fw::Errc::kIoError, "black box '%s': write failed: %s", tmp, std::strerror(err));
  }
  if (::rename(tmp, path) != 0) {
    const int e = errno;
    ::unlink(tmp);
    return fw::Status::error(fw::Errc::kIoError, "black box '%s': cannot replace: %s", path, std::strerror(e));
  }
  if (written != nullptr) *written = total;
  return fw::Status::ok();
}

}  // namespace hal_linux
