#include "hal_sim/stepped_clock.h"

namespace hal_sim {

void SteppedClock::advance_ns(std::uint64_t dt) { now_ns_.fetch_add(dt, std::memory_order_acq_rel); }

}  // namespace hal_sim
