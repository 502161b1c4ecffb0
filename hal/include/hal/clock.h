// hal::Clock: the HAL's clock interface. It is defined in the common layer (firmware/base/clock.h,
// fw::Clock) because perf counters below the HAL need it; this header is the HAL's name for it, so
// backends (hal/linux LinuxClock, hal/sim SteppedClock) and algorithms keep writing hal::Clock.
#pragma once

#include "firmware/base/clock.h"

namespace hal {

using Clock = fw::Clock;

}  // namespace hal
