// LinuxClock: CLOCK_MONOTONIC.
#pragma once

#include "hal/clock.h"

namespace hal_linux {

class LinuxClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override;
};

}  // namespace hal_linux
