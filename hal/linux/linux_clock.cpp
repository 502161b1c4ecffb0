#include "hal_linux/linux_clock.h"

#include <time.h>

namespace hal_linux {

std::uint64_t LinuxClock::now_ns() const {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::uint64_t>(ts.tv_sec) * 1000000000ull + static_cast<std::uint64_t>(ts.tv_nsec);
}

}  // namespace hal_linux
