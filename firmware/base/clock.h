// Clock: monotonic time as the firmware sees it. The interface lives in the common layer
// (firmware/base) so that perf counters and deadlines can use it without including hal/; the HAL
// re-exports it as hal::Clock (hal/clock.h) and its backends implement it: hal/linux
// (CLOCK_MONOTONIC) and hal/sim (a stepped clock the simulator advances, so replays are deterministic).
#pragma once

#include <cstdint>

namespace fw {

class Clock {
 public:
  virtual ~Clock() = default;
  // Monotonic nanoseconds since an arbitrary epoch.
  virtual std::uint64_t now_ns() const = 0;
};

}  // namespace fw
