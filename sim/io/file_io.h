// Whole-file reads and writes for the host tools, safe against hostile paths: only regular files are
// read (checked with stat before opening, so a FIFO blocks nothing, /dev/zero is not read forever and
// a directory is an error, not an exception), the size is capped before anything is allocated, and
// outputs are written to a temporary file next to the target and renamed over it only when complete
// (a failed run leaves no half-written or rejected output behind). Every message starts with the path.
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace sim {

// Caps (bytes) used by the readers of sim/io and sim/map; each is far above the real inputs
// (../shared/data: logs ≤ 18 MB inflated, maps ≤ a few MB).
constexpr std::uint64_t kMaxTextConfigBytes = std::uint64_t(1) << 20;  // YAML map descriptions
constexpr std::uint64_t kMaxMapFileBytes = std::uint64_t(1) << 30;     // PGM images, compiled map images

// "regular file", "directory", "FIFO", "character device", … for messages.
std::string file_type_name(unsigned mode);

// Stats `path`: a regular file of at most max_bytes bytes; *size (optional) gets its size.
bool check_regular_file(const std::string& path, std::uint64_t max_bytes, std::uint64_t* size, std::string* error);

// Reads the whole regular file `path` (at most max_bytes bytes; a file that grows past the cap while
// being read is an error too).
bool read_regular_file(const std::string& path, std::uint64_t max_bytes, std::string* data, std::string* error);
bool read_regular_file(const std::string& path, std::uint64_t max_bytes, std::vector<std::uint8_t>* data,
                       std::string* error);

// Writes `size` bytes to a temporary file in the directory of `path` and renames it to `path` once it
// is complete and flushed; on any failure the temporary is removed and `path` is left untouched.
bool write_file_atomic(const std::string& path, const void* data, std::size_t size, std::string* error);
inline bool write_file_atomic(const std::string& path, const std::string& data, std::string* error) {
  return write_file_atomic(path, data.data(), data.size(), error);
}

}  // namespace sim
