// MapImageFile: read-only mapping of a compiled map image file for the start-up load (one mmap
// system call, no heap). Typical use:
//   MapImageFile f; FW_RETURN_IF_ERROR(f.open(path));
//   FW_RETURN_IF_ERROR(load_map_image(f.data(), f.size(), arena, &map, path));
//   // other modules: find_section(f.data(), f.size(), MapSectionType::kRelationTable2D, &len) …
//   f.close();  // the map now lives in the arena
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

class MapImageFile {
 public:
  MapImageFile() = default;
  MapImageFile(const MapImageFile&) = delete;
  MapImageFile& operator=(const MapImageFile&) = delete;
  ~MapImageFile() { close(); }

  // Errors name the path (missing file, empty file, mmap failure).
  Status open(const char* path);
  void close();
  const std::uint8_t* data() const { return data_; }
  std::size_t size() const { return size_; }

 private:
  const std::uint8_t* data_ = nullptr;
  std::size_t size_ = 0;
};

// Convenience: open + load_map_image + close.
struct GlobalMap;
class StartupArena;
Status load_map_image_file(const char* path, StartupArena& arena, GlobalMap* out);

}  // namespace fw
