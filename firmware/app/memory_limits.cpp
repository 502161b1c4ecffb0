#include "firmware/app/memory_limits.h"

#include <fcntl.h>
#include <sys/resource.h>
#include <unistd.h>

#include <cstdlib>
#include <cstring>

namespace fw {
namespace {

// Reads a small text file into buf (NUL-terminated); false when missing or empty.
bool read_small(const char* path, char* buf, std::size_t cap) {
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC | O_NONBLOCK);
  if (fd < 0) return false;
  std::size_t len = 0;
  while (len + 1 < cap) {
    const ssize_t n = ::read(fd, buf + len, cap - 1 - len);
    if (n <= 0) break;
    len += static_cast<std::size_t>(n);
  }
  ::close(fd);
  buf[len] = '\0';
  return len > 0;
}

std::uint64_t rlimit_bytes(int resource) {
  struct rlimit r {};
  if (::getrlimit(resource, &r) != 0 || r.rlim_cur == RLIM_INFINITY) return MemoryLimits::kNone;
  return static_cast<std::uint64_t>(r.rlim_cur);
}

double mib(std::uint64_t b) { return static_cast<double>(b) / 1048576.0; }

}  // namespace

MemoryLimits read_memory_limits() {
  MemoryLimits m;
  const long pages = ::sysconf(_SC_PHYS_PAGES), page = ::sysconf(_SC_PAGESIZE);
  if (pages > 0 && page > 0) m.physical_bytes = static_cast<std::uint64_t>(pages) * static_cast<std::uint64_t>(page);
  m.address_space_bytes = rlimit_bytes(RLIMIT_AS);
  // cgroup v2: "0::/path" in /proc/self/cgroup, the limit in /sys/fs/cgroup/path/memory.max ("max" = none).
  char cg[512];
  if (read_small("/proc/self/cgroup", cg, sizeof(cg))) {
    const char* p = std::strstr(cg, "0::");
    if (p != nullptr) {
      p += 3;
      char path[768];
      std::size_t n = 0;
      const char* prefix = "/sys/fs/cgroup";
      for (const char* c = prefix; *c && n + 1 < sizeof(path); ++c) path[n++] = *c;
      for (; *p && *p != '\n' && n + 1 < sizeof(path); ++p) path[n++] = *p;
      if (n > 0 && path[n - 1] == '/') --n;
      const char* leaf = "/memory.max";
      for (const char* c = leaf; *c && n + 1 < sizeof(path); ++c) path[n++] = *c;
      path[n] = '\0';
      char v[64];
      if (read_small(path, v, sizeof(v)) && v[0] >= '0' && v[0] <= '9') {
        m.cgroup_bytes = std::strtoull(v, nullptr, 10);
      }
    }
  }
  return m;
}

Status check_memory_fits(std::uint64_t footprint, const MemoryLimits& l, const char* what) {
  struct Limit {
    std::uint64_t bytes;
    const char* name;
  } const limits[] = {{l.physical_bytes, "the machine's physical memory"},
                      {l.cgroup_bytes, "the cgroup's memory.max"},
                      {l.address_space_bytes, "the address-space limit (ulimit -v)"}};
  for (const Limit& lim : limits) {
    if (lim.bytes != MemoryLimits::kNone && footprint > lim.bytes) {
      return Status::error(Errc::kCapacityExceeded, "%s need %.1f MiB but %s is %.1f MiB", what, mib(footprint),
                           lim.name, mib(lim.bytes));
    }
  }
  return Status::ok();
}

}  // namespace fw
