#include "firmware/map/map_image_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>

#include "firmware/map/map_image.h"

namespace fw {

Status MapImageFile::open(const char* path) {
  close();
  // O_NONBLOCK: a FIFO given as the map would block open() until a writer appears; this way open
  // returns at once and the regular-file check below refuses it (no effect on regular files).
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
  const std::size_t size = static_cast<std::size_t>(st.st_size);
  void* p = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, fd, 0);
  const int e = errno;
  ::close(fd);
  if (p == MAP_FAILED) return Status::error(Errc::kIoError, "map image '%s': mmap failed: %s", path, std::strerror(e));
  data_ = static_cast<const std::uint8_t*>(p);
  size_ = size;
  return Status::ok();
}

void MapImageFile::close() {
  if (data_ != nullptr) ::munmap(const_cast<std::uint8_t*>(data_), size_);
  data_ = nullptr;
  size_ = 0;
}

Status load_map_image_file(const char* path, StartupArena& arena, GlobalMap* out) {
  MapImageFile file;
  FW_RETURN_IF_ERROR(file.open(path));
  return load_map_image(file.data(), file.size(), arena, out, path);
}

}  // namespace fw
