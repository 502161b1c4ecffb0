#include "firmware/base/memory_report.h"

#include <cstring>

namespace fw {

MemoryReport& MemoryReport::instance() {
  static MemoryReport report;
  return report;
}

Status MemoryReport::add(const MemoryRegion& region) {
  for (std::size_t i = 0; i < count_; ++i) {
    if (std::strcmp(regions_[i].module, region.module) == 0 &&
        std::strcmp(regions_[i].name, region.name) == 0) {
      regions_[i] = region;
      return Status::ok();
    }
  }
  if (count_ == kMaxRegions) {
    return Status::error(Errc::kCapacityExceeded, "memory report: table full (%zu regions), cannot add %s/%s",
                         kMaxRegions, region.module, region.name);
  }
  regions_[count_++] = region;
  return Status::ok();
}

void MemoryReport::remove(const void* high_water_ptr) {
  for (std::size_t i = 0; i < count_; ++i) {
    if (regions_[i].high_water == high_water_ptr) {
      regions_[i] = regions_[count_ - 1];
      --count_;
      return;
    }
  }
}

std::size_t MemoryReport::total_bytes() const {
  std::size_t total = 0;
  for (std::size_t i = 0; i < count_; ++i) total += regions_[i].bytes;
  return total;
}

std::size_t MemoryReport::module_bytes(const char* module) const {
  std::size_t total = 0;
  for (std::size_t i = 0; i < count_; ++i) {
    if (std::strcmp(regions_[i].module, module) == 0) total += regions_[i].bytes;
  }
  return total;
}

void MemoryReport::print(std::FILE* out) const {
  std::fprintf(out, "%-12s %-28s %14s %10s %10s\n", "module", "region", "bytes", "capacity", "high-water");
  // Modules in first-registration order, regions grouped under them.
  for (std::size_t i = 0; i < count_; ++i) {
    bool seen = false;
    for (std::size_t j = 0; j < i; ++j) {
      if (std::strcmp(regions_[j].module, regions_[i].module) == 0) { seen = true; break; }
    }
    if (seen) continue;
    for (std::size_t k = i; k < count_; ++k) {
      const MemoryRegion& r = regions_[k];
      if (std::strcmp(r.module, regions_[i].module) != 0) continue;
      if (r.high_water != nullptr) {
        std::fprintf(out, "%-12s %-28s %14zu %10zu %10zu\n", r.module, r.name, r.bytes, r.capacity, *r.high_water);
      } else {
        std::fprintf(out, "%-12s %-28s %14zu %10zu %10s\n", r.module, r.name, r.bytes, r.capacity, "-");
      }
    }
    const std::size_t mb = module_bytes(regions_[i].module);
    std::fprintf(out, "%-12s %-28s %14zu   (%.3f MiB)\n", regions_[i].module, "= module total", mb,
                 static_cast<double>(mb) / (1024.0 * 1024.0));
  }
  const std::size_t total = total_bytes();
  std::fprintf(out, "%-12s %-28s %14zu   (%.3f MiB)\n", "TOTAL", "", total,
               static_cast<double>(total) / (1024.0 * 1024.0));
}

}  // namespace fw
