// Memory the firmware may use on this machine: the smallest of the physical memory, the process's
// address-space limit (RLIMIT_AS) and the memory limit of its cgroup (v2 memory.max). mmlfw
// --memory-report checks its footprint against it, so a configuration whose budget the hardware
// cannot hold fails the pre-flight check instead of passing it (issue 13).
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"

namespace fw {

struct MemoryLimits {
  static constexpr std::uint64_t kNone = ~std::uint64_t(0);
  std::uint64_t physical_bytes = kNone;  // sysconf(_SC_PHYS_PAGES) · page size
  std::uint64_t address_space_bytes = kNone;  // RLIMIT_AS
  std::uint64_t cgroup_bytes = kNone;    // /sys/fs/cgroup/<own cgroup>/memory.max
};

// Reads the limits of the running process (start-up only: a few system calls and small files).
MemoryLimits read_memory_limits();

// Error naming the limit when `footprint_bytes` does not fit (`what` names the footprint, e.g.
// "arena_mib + static objects"). (Locking for realtime = true is checked by mlockall itself.)
Status check_memory_fits(std::uint64_t footprint_bytes, const MemoryLimits& limits, const char* what);

}  // namespace fw
