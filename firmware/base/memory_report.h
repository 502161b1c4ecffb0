// MemoryReport: every pool, arena and static table registers its bytes here, so the binaries can
// print the static memory budget by module (`--memory-report`). The registry itself is a fixed
// table; registration happens at start-up only.
#pragma once

#include <cstddef>
#include <cstdio>

#include "firmware/base/status.h"

namespace fw {

struct MemoryRegion {
  const char* module = nullptr;     // e.g. "rbsm"
  const char* name = nullptr;       // e.g. "particles"
  std::size_t bytes = 0;            // bytes reserved (static or arena)
  std::size_t capacity = 0;         // element capacity (0 if not a container)
  const std::size_t* high_water = nullptr;  // live high-water mark in elements (may be null)
};

class MemoryReport {
 public:
  static constexpr std::size_t kMaxRegions = 256;

  static MemoryReport& instance();

  // Registers (or, for the same module+name, updates) a region. Full table => status.
  Status add(const MemoryRegion& region);
  void remove(const void* high_water_ptr);
  std::size_t region_count() const { return count_; }
  const MemoryRegion& region(std::size_t i) const { return regions_[i]; }
  std::size_t total_bytes() const;
  std::size_t module_bytes(const char* module) const;
  // Prints a table: region rows, per-module subtotals and the total.
  void print(std::FILE* out) const;
  void clear() { count_ = 0; }

 private:
  MemoryRegion regions_[kMaxRegions];
  std::size_t count_ = 0;
};

}  // namespace fw
