#include "firmware/map/map_image_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "firmware/map/le_fields.h"
#include "firmware/map/map_image.h"

namespace fw {
namespace {

std::size_t page_size() {
  const long p = ::sysconf(_SC_PAGESIZE);
  return p > 0 ? static_cast<std::size_t>(p) : 4096u;
}

// pread until `len` bytes or end of file; returns bytes read or -1 (errno set).
long long read_fully(int fd, std::uint8_t* out, std::size_t len, std::uint64_t offset) {
  std::size_t done = 0;
  while (done < len) {
    const ssize_t n = ::pread(fd, out + done, len - done, static_cast<off_t>(offset + done));
    if (n < 0) {
      if (errno == EINTR) continue;
      return -1;
    }
    if (n == 0) break;
    done += static_cast<std::size_t>(n);
  }
  return static_cast<long long>(done);
}

}  // namespace

Status MapImageFile::open(const char* path) {
  close();
  if (path == nullptr || path[0] == '\0') return Status::error(Errc::kInvalidArgument, "map image: empty path");
  // O_NONBLOCK: a FIFO or device given by mistake must not block the start-up in open(); it is
  // refused below as not a regular file (O_NONBLOCK has no effect on regular files).
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return Status::error(Errc::kIoError, "map image '%s': cannot open: %s", path, std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0) {
    const int e = errno;
    ::close(fd);
    return Status::error(Errc::kIoError, "map image '%s': cannot stat: %s", path, std::strerror(e));
  }
  if (!S_ISREG(st.st_mode)) {
    ::close(fd);
    return Status::error(Errc::kIoError, "map image '%s': not a regular file", path);
  }
  if (st.st_size <= 0) {
    ::close(fd);
    return Status::error(Errc::kCorruptData, "map image '%s': empty file", path);
  }
  const std::uint64_t file_size = static_cast<std::uint64_t>(st.st_size);
  // Header first: the size it declares must be the size on disk before anything big is read.
  std::uint8_t header[kMapImageHeaderBytes];
  const long long got = file_size < kMapImageHeaderBytes ? static_cast<long long>(file_size)
                                                         : read_fully(fd, header, kMapImageHeaderBytes, 0);
  if (got < 0) {
    const int e = errno;
    ::close(fd);
    return Status::error(Errc::kIoError, "map image '%s': read failed: %s", path, std::strerror(e));
  }
  if (got < static_cast<long long>(kMapImageHeaderBytes)) {
    ::close(fd);
    return Status::error(Errc::kCorruptData, "map image '%s': truncated: %lld bytes, the header needs %zu", path, got,
                         kMapImageHeaderBytes);
  }
  if (std::memcmp(header, kMapImageMagic, sizeof(kMapImageMagic)) != 0) {
    ::close(fd);
    return Status::error(Errc::kCorruptData, "map image '%s': bad magic (not a compiled map image)", path);
  }
  const std::uint64_t declared = read_le_u64(header + 16);
  if (declared != file_size) {
    ::close(fd);
    return Status::error(Errc::kCorruptData,
                         "map image '%s': header says %llu bytes, the file has %llu (truncated, padded or still "
                         "being written)",
                         path, static_cast<unsigned long long>(declared), static_cast<unsigned long long>(file_size));
  }
  if (file_size > kMaxImageBytes) {
    ::close(fd);
    return Status::error(Errc::kCapacityExceeded, "map image '%s': %llu bytes, at most %llu supported", path,
                         static_cast<unsigned long long>(file_size), static_cast<unsigned long long>(kMaxImageBytes));
  }
  const std::size_t size = static_cast<std::size_t>(file_size);
  const std::size_t page = page_size();
  const std::size_t map_len = (size + page - 1) / page * page;
  void* p = ::mmap(nullptr, map_len, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (p == MAP_FAILED) {
    const int e = errno;
    ::close(fd);
    return Status::error(Errc::kIoError, "map image '%s': cannot reserve %zu bytes for the image: %s", path, size,
                         std::strerror(e));
  }
  std::uint8_t* buf = static_cast<std::uint8_t*>(p);
  const long long n = read_fully(fd, buf, size, 0);
  const int e = errno;
  ::close(fd);
  if (n < 0 || static_cast<std::size_t>(n) != size) {
    ::munmap(p, map_len);
    if (n < 0) return Status::error(Errc::kIoError, "map image '%s': read failed: %s", path, std::strerror(e));
    return Status::error(Errc::kCorruptData,
                         "map image '%s': file shrank while it was read (%lld of %zu bytes): truncated or replaced "
                         "on disk during start-up",
                         path, n, size);
  }
  // Read-only from here on, as the mapped file was (a stray write faults instead of corrupting).
  ::mprotect(p, map_len, PROT_READ);
  map_ = buf;
  map_len_ = map_len;
  data_ = buf;
  size_ = size;
  return Status::ok();
}

Status MapImageFile::retain(const std::uint8_t* section, std::size_t len) {
  if (map_ == nullptr) return Status::error(Errc::kNotInitialized, "map image: retain() without an open image");
  if (section == nullptr || section < data_ || len > size_ || static_cast<std::size_t>(section - data_) > size_ - len) {
    return Status::error(Errc::kOutOfRange, "map image: retain(): range [%p, +%zu) is not inside the image",
                         static_cast<const void*>(section), len);
  }
  if (len == 0) {
    close();
    return Status::ok();
  }
  const std::size_t page = page_size();
  const std::size_t first = static_cast<std::size_t>(section - map_);
  const std::size_t begin = first / page * page;
  const std::size_t end = (first + len + page - 1) / page * page;  // ≤ map_len_ (map_len_ is page rounded)
  if (begin > 0) ::munmap(map_, begin);
  if (end < map_len_) ::munmap(map_ + end, map_len_ - end);
  map_ += begin;
  map_len_ = end - begin;
  data_ = section;
  size_ = len;
  return Status::ok();
}

void MapImageFile::close() {
  if (map_ != nullptr) ::munmap(map_, map_len_);
  map_ = nullptr;
  map_len_ = 0;
  data_ = nullptr;
  size_ = 0;
}

Status load_map_image_file(const char* path, StartupArena& arena, GlobalMap* out) {
  MapImageFile file;
  FW_RETURN_IF_ERROR(file.open(path));
  return load_map_image(file.data(), file.size(), arena, out, path);
}

}  // namespace fw
