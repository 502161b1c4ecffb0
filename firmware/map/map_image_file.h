// MapImageFile: a compiled map image file read ONCE at start-up into memory the firmware owns (one
// anonymous mapping: a system call, not the heap). Typical use:
//   MapImageFile f; FW_RETURN_IF_ERROR(f.open(path));
//   FW_RETURN_IF_ERROR(load_map_image(f.data(), f.size(), arena, &map, path));
//   // other modules: find_section(f.data(), f.size(), MapSectionType::kRelationTable2D, &len) …
//   f.close();  // the map now lives in the arena
//
// Why a copy and not a file mapping: a MAP_SHARED/MAP_PRIVATE mapping of a file that is truncated
// or rewritten on disk (`truncate`, `cp` over it, a deploy script) delivers SIGBUS on the next
// access to a page past the new end, which killed the firmware during the CRC check at start-up and
// later while a relation table was read in place. The copy is immune: once open() returned, the
// file may be changed, truncated or removed without any effect on the running firmware. open()
// checks the size on disk against the header before reading (truncated, padded or still being
// written: a clear error naming the file) and refuses a file that shrinks while it is read.
// When only one section is still needed after the load (pRANSAM's relation table, read in place),
// retain() gives the other pages of the copy back to the system.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

class MapImageFile {
 public:
  // Largest image open() accepts (the firmware's address space, not a format limit).
  static constexpr std::uint64_t kMaxImageBytes = std::uint64_t(1) << 31;

  MapImageFile() = default;
  MapImageFile(const MapImageFile&) = delete;
  MapImageFile& operator=(const MapImageFile&) = delete;
  ~MapImageFile() { close(); }

  // Errors name the path (missing, not a regular file, empty, header size and file size differ,
  // shrank while reading, read or mapping failure).
  Status open(const char* path);
  void close();
  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

  // Keeps only the pages holding [section, section + len) (a range inside data()) and unmaps the
  // rest of the copy; data()/size() then describe that range. Call after load_map_image() and
  // find_section() — pointers into other parts of the image become invalid.
  Status retain(const std::uint8_t* section, std::size_t len);
  // Bytes of the copy still mapped (whole pages).
  std::size_t mapped_bytes() const { return map_len_; }

 private:
  std::uint8_t* map_ = nullptr;  // the anonymous mapping (page aligned)
  std::size_t map_len_ = 0;
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

// Convenience: open + load_map_image + close.
struct GlobalMap;
class StartupArena;
Status load_map_image_file(const char* path, StartupArena& arena, GlobalMap* out);

}  // namespace fw
