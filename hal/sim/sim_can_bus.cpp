#include "hal_sim/sim_can_bus.h"

namespace hal_sim {

bool SimCanBus::receive(hal::CanFrame* out) {
  if (!frames_.pop(out)) return false;
  ++stats_.rx_frames;
  return true;
}

bool SimCanBus::send(const hal::CanFrame& frame) {
  if (frames_.full()) {
    ++stats_.tx_failed;
    return false;
  }
  (void)frames_.push(frame);
  ++stats_.tx_frames;
  return true;
}

}  // namespace hal_sim
