// SimCanBus: the simulation backend of hal::CanBus, a loopback bus in memory. What the simulated
// device sends (sim/devices/sensor_transport) is what the firmware's CanNode receives, in order,
// with the receive time stamp the sender put on it (the simulation clock: zero latency in
// lockstep). Fixed capacity, no heap: a send into a full bus is refused and counted in
// stats().tx_failed, as a full socket queue would be.
#pragma once

#include <cstddef>

#include "firmware/base/ring_buffer.h"
#include "hal/can_bus.h"

namespace hal_sim {

class SimCanBus final : public hal::CanBus {
 public:
  // One classic-CAN scan of 1081 beams is 366 frames; a lockstep step sends one scan and its
  // odometry, so 2048 frames leave room for several steps of backlog.
  static constexpr std::size_t kCapacity = 2048;

  bool receive(hal::CanFrame* out) override;
  bool send(const hal::CanFrame& frame) override;
  const hal::CanBusStats& stats() const override { return stats_; }
  std::size_t pending() const { return frames_.size(); }

 private:
  fw::RingBuffer<hal::CanFrame, kCapacity> frames_;
  hal::CanBusStats stats_;
};

}  // namespace hal_sim
