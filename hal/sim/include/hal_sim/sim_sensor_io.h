// In-memory sensor rings of the simulation backend: the simulator (host side) pushes scans and
// odometry in, the firmware polls them through hal::LaserScanSource / hal::OdometrySource exactly
// as it would poll a driver; estimates the firmware publishes land in a ring the host reads.
// Fixed capacity, no heap: a push into a full ring is dropped and counted (as a driver drops a
// frame when its queue is full), never a reallocation.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "hal/sensor_io.h"

namespace hal_sim {

// Counters every ring keeps; `dropped` counts pushes refused because the ring was full.
struct RingStats {
  std::uint64_t pushed = 0;
  std::uint64_t polled = 0;
  std::uint64_t dropped = 0;
};

class SimLaserSource final : public hal::LaserScanSource {
 public:
  // A LaserScan is ~4.4 KiB; 16 scans cover 1.6 s of a 10 Hz scanner while the firmware is busy.
  static constexpr std::size_t kCapacity = 16;

  // Host side: false (and counted) when the ring is full.
  bool push(const hal::LaserScan& scan);
  // Firmware side.
  bool poll(hal::LaserScan* out) override;

  std::size_t pending() const { return ring_.size(); }
  const RingStats& stats() const { return stats_; }
  // Scans the sensor produced while the ring was full are lost to the firmware: HEALTH counts them
  // (as CanNode counts its ring overflows), so a soak can account for every scan in HEALTH alone.
  std::uint32_t skipped_scans() const override { return static_cast<std::uint32_t>(stats_.dropped); }

 private:
  fw::RingBuffer<hal::LaserScan, kCapacity> ring_;
  RingStats stats_;
};

class SimOdometrySource final : public hal::OdometrySource {
 public:
  // Odometry arrives at 10–100 Hz; 256 samples are several seconds.
  static constexpr std::size_t kCapacity = 256;

  bool push(const hal::Odometry& odom);
  bool poll(hal::Odometry* out) override;

  std::size_t pending() const { return ring_.size(); }
  const RingStats& stats() const { return stats_; }

 private:
  fw::RingBuffer<hal::Odometry, kCapacity> ring_;
  RingStats stats_;
};

// Records what the firmware publishes. The host drains estimates with pop(); when it does not keep
// up, the oldest estimate is overwritten and counted in stats().dropped (the newest is what a
// robot's consumer wants). The latest health frame is kept separately.
class SimPoseSink final : public hal::PoseSink {
 public:
  static constexpr std::size_t kCapacity = 64;

  void publish(const hal::PoseEstimate& estimate) override;
  void publish_health(const hal::Health& health) override;

  bool pop(hal::PoseEstimate* out);
  std::size_t pending() const { return ring_.size(); }
  bool has_health() const { return health_count_ > 0; }
  const hal::Health& last_health() const { return health_; }
  std::uint64_t health_count() const { return health_count_; }
  const RingStats& stats() const { return stats_; }

 private:
  fw::RingBuffer<hal::PoseEstimate, kCapacity> ring_;
  hal::Health health_;
  std::uint64_t health_count_ = 0;
  RingStats stats_;
};

}  // namespace hal_sim
