// SteppedClock: simulated monotonic time that only moves when the simulator says so, so replays
// are deterministic and independent of host speed.
#pragma once

#include <atomic>
#include <cstdint>

#include "hal/clock.h"

namespace hal_sim {

class SteppedClock final : public hal::Clock {
 public:
  std::uint64_t now_ns() const override { return now_ns_.load(std::memory_order_acquire); }
  void set_ns(std::uint64_t t) { now_ns_.store(t, std::memory_order_release); }
  void advance_ns(std::uint64_t dt);

 private:
  std::atomic<std::uint64_t> now_ns_{0};
};

}  // namespace hal_sim
