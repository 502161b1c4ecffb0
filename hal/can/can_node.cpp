#include "hal_can/can_node.h"

namespace hal_can {
namespace {
std::uint16_t sat16(std::uint64_t v) { return v > 0xFFFF ? 0xFFFF : static_cast<std::uint16_t>(v); }
}  // namespace

void CanNode::init(hal::CanBus* bus, const hal::Clock* clock, bool fd) {
  bus_ = bus;
  clock_ = clock;
  fd_ = fd;
  start_ns_ = clock_ ? clock_->now_ns() : 0;
}

std::uint64_t CanNode::map_time(std::uint64_t sender_ns, std::uint64_t rx_ns, bool relax) {
  if (rx_ns == 0) return sender_ns;  // no receive time (tests without a clock): keep the sender's
  const std::int64_t sample = static_cast<std::int64_t>(rx_ns) - static_cast<std::int64_t>(sender_ns);
  constexpr std::int64_t kJump = 10'000'000'000;
  if (!have_offset_ || sample < offset_ns_ || sample - offset_ns_ > kJump) {
    offset_ns_ = sample;
    have_offset_ = true;
  } else if (relax) {
    offset_ns_ += (sample - offset_ns_) / 1024;  // slow upward relaxation (clock drift)
  }
  const std::int64_t local = static_cast<std::int64_t>(sender_ns) + offset_ns_;
  return local > 0 ? static_cast<std::uint64_t>(local) : 0;
}

int CanNode::pump() {
  if (!bus_) return 0;
  int n = 0;
  hal::CanFrame f;
  while (n < kMaxFramesPerPump && bus_->receive(&f)) {
    ++n;
    f.timestamp_ns = f.timestamp_ns / 1000 * 1000;  // µs, as the black box and candump keep it
    if (black_box_ != nullptr) black_box_->record(f, f.timestamp_ns, false);
    switch (decoder_.feed(f)) {
      case Decoded::kScan: {
        // Keep the newest scans: a late localizer should see the present, not the past.
        if (scans_.push_overwrite(decoder_.scan())) ++scans_overflowed_;
        hal::LaserScan& s = scans_[scans_.size() - 1];
        s.timestamp_ns = map_time(s.timestamp_ns, f.timestamp_ns, false);  // includes the scan's own duration
        break;
      }
      case Decoded::kOdometry: {
        hal::Odometry o = decoder_.odometry();
        o.timestamp_ns = map_time(o.timestamp_ns, f.timestamp_ns, true);
        if (odoms_.push_overwrite(o)) ++odom_overflowed_;
        break;
      }
      case Decoded::kCommand:
        if (commands_queue_.push_overwrite(decoder_.command())) ++commands_overflowed_;
        break;
      default:
        break;
    }
  }
  return n;
}

bool CanNode::Commands::poll(hal::Command* out) {
  node_->pump();
  return node_->commands_queue_.pop(out);
}

void CanNode::Sink::publish_reply(const hal::CommandReply& reply) {
  encode_reply(reply, &node_->tx_[0]);
  node_->send_frames(node_->tx_, 1);
}

bool CanNode::Laser::poll(hal::LaserScan* out) {
  node_->pump();
  return node_->scans_.pop(out);
}

bool CanNode::Odom::poll(hal::Odometry* out) {
  node_->pump();
  return node_->odoms_.pop(out);
}

void CanNode::send_frames(const hal::CanFrame* frames, std::size_t n) {
  const std::uint64_t now = black_box_ != nullptr && clock_ != nullptr ? clock_->now_ns() / 1000 * 1000 : 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (!bus_ || !bus_->send(frames[i])) ++tx_failed_;
    if (black_box_ != nullptr) black_box_->record(frames[i], now, true);
  }
}

void CanNode::Sink::publish(const hal::PoseEstimate& estimate) {
  std::size_t n = 0;
  // Back to the sender's clock, so the robot can relate the pose to its own sensor data.
  hal::PoseEstimate e = estimate;
  if (node_->have_offset_) {
    const std::int64_t t = static_cast<std::int64_t>(e.timestamp_ns) - node_->offset_ns_;
    e.timestamp_ns = t > 0 ? static_cast<std::uint64_t>(t) : 0;
  }
  if (encode_pose(e, node_->pose_tag_++, node_->fd_, node_->tx_, kMaxParts, &n).is_ok()) {
    node_->send_frames(node_->tx_, n);
    ++node_->poses_sent_;
  }
}

void CanNode::Sink::publish_health(const hal::Health& h) {
  const DecoderStats& d = node_->decoder_.stats();
  const hal::CanBusStats* b = node_->bus_ ? &node_->bus_->stats() : nullptr;
  HealthRecord r;
  const std::uint64_t now = node_->clock_ ? node_->clock_->now_ns() : 0;
  r.uptime_ms = static_cast<std::uint32_t>((now - node_->start_ns_) / 1000000);
  r.crc_errors = sat16(std::uint64_t{h.crc_errors} + d.crc_errors);
  r.lost_segments = sat16(std::uint64_t{h.lost_segments} + d.lost_segments + d.duplicate_segments);
  r.dropped_scans = sat16(std::uint64_t{h.dropped_scans} + d.scans_dropped + node_->scans_overflowed_);
  r.timeouts = sat16(std::uint64_t{h.timeouts} + d.timeouts);
  r.deadline_misses = sat16(h.deadline_misses);
  r.bus_off = sat16(std::uint64_t{h.bus_off_count} + (b ? b->bus_off : 0));
  r.scans_processed = h.scans_processed;
  r.invalid_scans = sat16(h.invalid_scans);  // the laser source's count (CanNode::Laser: decoder's)
  r.rx_dropped = sat16(b ? b->rx_dropped : 0);
  r.error_frames = sat16(b ? b->error_frames : 0);
  r.fault_bits = h.fault_bits;
  r.hint_status = h.hint_status;
  r.state = h.fault_bits ? 2
            : ((r.crc_errors || r.lost_segments || r.dropped_scans || r.bus_off || r.invalid_scans) ? 1 : 0);
  std::size_t n = 0;
  if (encode_health(r, node_->health_tag_++, node_->fd_, node_->tx_, kMaxParts, &n).is_ok()) {
    node_->send_frames(node_->tx_, n);
  }
}

}  // namespace hal_can
