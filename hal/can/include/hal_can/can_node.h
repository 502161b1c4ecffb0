// CanNode: the firmware side of the CAN message set over any hal::CanBus (SocketCAN on the robot,
// an in-memory bus in tests). Decodes scans and odometry into fixed rings and encodes pose and
// health frames. Exposes the HAL source/sink interfaces the localization loop uses.
#pragma once

#include <cstdint>

#include "firmware/base/ring_buffer.h"
#include "hal/can_bus.h"
#include "hal/clock.h"
#include "hal/sensor_io.h"
#include "hal_can/black_box.h"
#include "hal_can/codec.h"

namespace hal_can {

class CanNode {
 public:
  static constexpr std::size_t kScanQueue = 4;
  static constexpr std::size_t kOdomQueue = 256;
  static constexpr int kMaxFramesPerPump = 4096;
  static constexpr std::size_t kCommandQueue = 4;

  CanNode() : laser_(this), odom_(this), sink_(this), commands_(this) {}
  CanNode(const CanNode&) = delete;
  CanNode& operator=(const CanNode&) = delete;

  // `fd`: send pose/health as CAN FD frames (the bus must support FD).
  void init(hal::CanBus* bus, const hal::Clock* clock, bool fd);

  // Drains pending frames (bounded) into the decoder; returns frames read.
  int pump();

  hal::LaserScanSource& laser() { return laser_; }
  hal::OdometrySource& odometry() { return odom_; }
  hal::PoseSink& pose_sink() { return sink_; }
  // Operator commands (SET_POSE_HINT, SELECT_MAP, DUMP_LOG); replies go out through pose_sink().
  hal::CommandSource& commands() { return commands_; }
  // Every frame received (receive time, kept to the µs as candump logs it) and sent from now on is
  // recorded in `box` (black_box.h); null = none.
  void attach_black_box(BlackBox* box) { black_box_ = box; }
  std::uint32_t commands_overflowed() const { return commands_overflowed_; }

  const DecoderStats& decoder_stats() const { return decoder_.stats(); }
  // Current estimate of (local monotonic ns − sender ns), see map_time().
  std::int64_t clock_offset_ns() const { return offset_ns_; }
  std::uint32_t scans_overflowed() const { return scans_overflowed_; }
  std::uint32_t odometry_overflowed() const { return odom_overflowed_; }
  std::uint32_t tx_failed() const { return tx_failed_; }
  std::uint32_t poses_sent() const { return poses_sent_; }

 private:
  class Laser final : public hal::LaserScanSource {
   public:
    explicit Laser(CanNode* n) : node_(n) {}
    bool poll(hal::LaserScan* out) override;
    std::uint32_t invalid_scans() const override { return node_->decoder_.stats().invalid_scans; }
   private:
    CanNode* node_;
  };
  class Odom final : public hal::OdometrySource {
   public:
    explicit Odom(CanNode* n) : node_(n) {}
    bool poll(hal::Odometry* out) override;
   private:
    CanNode* node_;
  };
  class Sink final : public hal::PoseSink {
   public:
    explicit Sink(CanNode* n) : node_(n) {}
    void publish(const hal::PoseEstimate& estimate) override;
    void publish_health(const hal::Health& health) override;
    void publish_reply(const hal::CommandReply& reply) override;
   private:
    CanNode* node_;
  };
  class Commands final : public hal::CommandSource {
   public:
    explicit Commands(CanNode* n) : node_(n) {}
    bool poll(hal::Command* out) override;
   private:
    CanNode* node_;
  };
  void send_frames(const hal::CanFrame* frames, std::size_t n);
  // The frames carry the sender's clock; the firmware's messages use the local monotonic clock
  // (hal/msg/laser_scan.h). One-way synchronisation by minimum delay: offset = min over records
  // of (kernel receive time − sender time), relaxed slowly upwards by odometry samples (short
  // records) to follow drift, and reset when the sender's clock jumps (restart) by more than 10 s.
  std::uint64_t map_time(std::uint64_t sender_ns, std::uint64_t rx_ns, bool relax);
  bool have_offset_ = false;
  std::int64_t offset_ns_ = 0;

  hal::CanBus* bus_ = nullptr;
  const hal::Clock* clock_ = nullptr;
  bool fd_ = false;
  std::uint64_t start_ns_ = 0;
  Decoder decoder_;
  fw::RingBuffer<hal::LaserScan, kScanQueue> scans_;
  fw::RingBuffer<hal::Odometry, kOdomQueue> odoms_;
  fw::RingBuffer<hal::Command, kCommandQueue> commands_queue_;
  std::uint32_t commands_overflowed_ = 0;
  BlackBox* black_box_ = nullptr;
  std::uint32_t scans_overflowed_ = 0, odom_overflowed_ = 0, tx_failed_ = 0, poses_sent_ = 0;
  std::uint8_t pose_tag_ = 0, health_tag_ = 0;
  hal::CanFrame tx_[kMaxParts];
  Laser laser_;
  Odom odom_;
  Sink sink_;
  Commands commands_;
};

}  // namespace hal_can
