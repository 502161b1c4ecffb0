// Clock: monotonic time as the firmware sees it. Backends: hal/linux (CLOCK_MONOTONIC) and
// hal/sim (a stepped clock the simulator advances, so replays are deterministic).
#pragma once

#include <cstdint>

namespace hal {

class Clock {
 public:
  virtual ~Clock() = default;
  // Monotonic nanoseconds since an arbitrary epoch.
  virtual std::uint64_t now_ns() const = 0;
};

}  // namespace hal
