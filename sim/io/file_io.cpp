#include "sim/common/fail.h"
#include "sim/io/file_io.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace sim {
namespace {

std::string bytes_text(std::uint64_t n) {
  std::string s = std::to_string(n) + " bytes";
  if (n >= (std::uint64_t(1) << 20) && n % (std::uint64_t(1) << 20) == 0) {
    s += " (" + std::to_string(n >> 20) + " MiB)";
  }
  return s;
}

bool check_stat(const std::string& path, const struct stat& st, std::uint64_t max_bytes, std::string* error) {
  if (!S_ISREG(st.st_mode)) {
    return fail(error, path + ": not a regular file (" + file_type_name(st.st_mode) + ")");
  }
  const std::uint64_t size = static_cast<std::uint64_t>(st.st_size);
  if (size > max_bytes) {
    return fail(error, path + ": " + std::to_string(size) + " bytes, more than the limit of " + bytes_text(max_bytes));
  }
  return true;
}

// Opens a regular file for reading without blocking (O_NONBLOCK: should the path be swapped for a
// FIFO between stat and open, open returns at once and fstat refuses it).
int open_regular(const std::string& path, std::uint64_t max_bytes, std::uint64_t* size, std::string* error) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) {
    fail(error, path + ": cannot open: " + std::strerror(errno));
    return -1;
  }
  if (!check_stat(path, st, max_bytes, error)) return -1;
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) {
    fail(error, path + ": cannot open: " + std::strerror(errno));
    return -1;
  }
  if (::fstat(fd, &st) != 0) {
    fail(error, path + ": cannot stat: " + std::strerror(errno));
    ::close(fd);
    return -1;
  }
  if (!check_stat(path, st, max_bytes, error)) {
    ::close(fd);
    return -1;
  }
  *size = static_cast<std::uint64_t>(st.st_size);
  return fd;
}

template <typename Buffer>
bool read_into(const std::string& path, std::uint64_t max_bytes, Buffer* data, std::string* error) {
  data->clear();
  std::uint64_t size = 0;
  const int fd = open_regular(path, max_bytes, &size, error);
  if (fd < 0) return false;
  data->resize(static_cast<std::size_t>(size));
  std::size_t got = 0;
  for (;;) {
    if (got == data->size()) {
      // The file may have grown since fstat: keep reading, in bounded steps, up to the cap.
      if (got > max_bytes) break;
      const std::size_t step = static_cast<std::size_t>(
          std::min<std::uint64_t>(std::uint64_t(1) << 16, max_bytes + 1 - static_cast<std::uint64_t>(got)));
      data->resize(got + step);
    }
    const ssize_t n = ::read(fd, reinterpret_cast<char*>(data->data()) + got, data->size() - got);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int e = errno;
      ::close(fd);
      data->clear();
      return fail(error, path + ": read error: " + std::strerror(e));
    }
    if (n == 0) break;
    got += static_cast<std::size_t>(n);
  }
  ::close(fd);
  data->resize(got);
  if (static_cast<std::uint64_t>(got) > max_bytes) {
    data->clear();
    return fail(error, path + ": grew past the limit of " + bytes_text(max_bytes) + " while being read");
  }
  return true;
}

}  // namespace

std::string file_type_name(unsigned mode) {
  if (S_ISREG(mode)) return "regular file";
  if (S_ISDIR(mode)) return "a directory";
  if (S_ISFIFO(mode)) return "a FIFO";
  if (S_ISCHR(mode)) return "a character device";
  if (S_ISBLK(mode)) return "a block device";
  if (S_ISSOCK(mode)) return "a socket";
  return "not a plain file";
}

bool check_regular_file(const std::string& path, std::uint64_t max_bytes, std::uint64_t* size, std::string* error) {
  struct stat st {};
  if (::stat(path.c_str(), &st) != 0) return fail(error, path + ": cannot open: " + std::strerror(errno));
  if (!check_stat(path, st, max_bytes, error)) return false;
  if (size != nullptr) *size = static_cast<std::uint64_t>(st.st_size);
  return true;
}

bool read_regular_file(const std::string& path, std::uint64_t max_bytes, std::string* data, std::string* error) {
  return read_into(path, max_bytes, data, error);
}

bool read_regular_file(const std::string& path, std::uint64_t max_bytes, std::vector<std::uint8_t>* data,
                       std::string* error) {
  return read_into(path, max_bytes, data, error);
}

bool write_file_atomic(const std::string& path, const void* data, std::size_t size, std::string* error) {
  if (path.empty()) return fail(error, "(empty output path): cannot create");
  struct stat st {};
  if (::stat(path.c_str(), &st) == 0 && !S_ISREG(st.st_mode)) {
    // Renaming over a FIFO or device would replace it; writing into it is not what a tool's output is for.
    return fail(error, path + ": cannot write: not a regular file (" + file_type_name(st.st_mode) + ")");
  }
  std::string tmp = path + ".tmp.XXXXXX";
  const int fd = ::mkstemp(tmp.data());
  if (fd < 0) return fail(error, path + ": cannot create: " + std::strerror(errno));
  const char* p = static_cast<const char*>(data);
  std::size_t left = size;
  int e = 0;
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      e = errno;
      break;
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  // mkstemp creates 0600; outputs get the usual 0666 & ~umask.
  const mode_t mask = ::umask(0);
  ::umask(mask);
  if (e == 0 && ::fchmod(fd, 0666 & ~mask) != 0) e = errno;
  if (e == 0 && ::fsync(fd) != 0 && errno != EINVAL) e = errno;
  if (::close(fd) != 0 && e == 0) e = errno;
  if (e == 0 && ::rename(tmp.c_str(), path.c_str()) != 0) e = errno;
  if (e != 0) {
    ::unlink(tmp.c_str());
    return fail(error, path + ": write failed: " + std::strerror(e));
  }
  return true;
}

}  // namespace sim
