// Encoders (message → frames into a caller array) and the decoder (frames → messages with
// counters). Corrupt, missing, duplicated or out-of-order input drops the affected scan/record and
// is counted; it never crashes and never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/status.h"
#include "hal/can_bus.h"
#include "hal/msg/command.h"
#include "hal/msg/health.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"
#include "hal/msg/pose_estimate.h"
#include "hal_can/protocol.h"

namespace hal_can {

// Worst case frames for one scan on classic CAN: 4 start parts + 361 segments + end.
constexpr std::size_t kMaxScanFrames =
    kScanStartParts + (hal::LaserScan::kMaxBeams + kClassicRangesPerSegment - 1) / kClassicRangesPerSegment + 1;

struct EncodeOptions {
  bool fd = false;              // CAN FD frames (fewer, larger) instead of classic
  std::uint32_t range_unit_um = 0;  // metres per range LSB in µm; 0 = choose (1 mm, or 10 mm if range_max > 65 m)
};

// Scan geometry the decoder accepts. A scan whose CRC is right but whose content is impossible
// (range_max 0.01 m, range_min 655 m, angle increment 0, readings of 3000 m, …) was delivered as
// valid; now it is dropped with a named defect and counted (DecoderStats::invalid_scans, HEALTH
// InvalidScans). The encoder refuses to produce such scans.
constexpr float kMinPlausibleRangeM = 0.1f;    // range_max below this: no scanner
constexpr float kMaxPlausibleRangeM = 250.0f;  // beyond any 2-D navigation/safety scanner

enum class ScanDefect : std::uint8_t {
  kNone = 0,
  kRangeMax,            // range_max not in [kMinPlausibleRangeM, kMaxPlausibleRangeM] m
  kRangeMin,            // range_min negative or not below range_max
  kAngleIncrement,      // angle increment zero, not finite, or beyond 2π
  kFieldOfView,         // |increment| · (beams − 1) beyond 2π
  kAngleMin,            // angle_min not finite or beyond ±2π
  kRangeBeyondMax,      // a reading (not "no return") beyond range_max
};
constexpr int kNumScanDefects = 7;
const char* scan_defect_name(ScanDefect d);
// The header checks (all but kRangeBeyondMax) of a scan as it would travel; kNone when valid.
ScanDefect scan_geometry_defect(const hal::LaserScan& scan);

// Health as it travels on the bus: the firmware's counters plus the bus statistics.
struct HealthRecord {
  std::uint32_t uptime_ms = 0;
  std::uint8_t state = 0;  // 0 ok, 1 degraded (counters rising), 2 fault (fault_bits != 0)
  std::uint16_t invalid_scans = 0;  // intact scans/telegrams with impossible content (payload bytes 5..6)
  std::uint16_t crc_errors = 0, lost_segments = 0, dropped_scans = 0;
  std::uint16_t timeouts = 0, deadline_misses = 0, bus_off = 0;
  std::uint32_t scans_processed = 0;
  std::uint16_t rx_dropped = 0, error_frames = 0;
  std::uint32_t fault_bits = 0;
  std::uint8_t hint_status = 0;  // hal::HintStatus (payload byte 34)
};

// Number of frames a scan takes. Classic: 4 + ceil(n/3) + 1; FD: 1 + ceil(n/31) + 1.
std::size_t scan_frame_count(std::uint32_t beam_count, bool fd);

// Each encoder writes frames into out[0..capacity) and sets *count. `tag` is the sequence byte
// the sender increments per record (scans use scan_id).
fw::Status encode_scan(const hal::LaserScan& scan, const EncodeOptions& opt, hal::CanFrame* out,
                       std::size_t capacity, std::size_t* count);
fw::Status encode_odometry(const hal::Odometry& odom, std::uint8_t tag, bool fd, hal::CanFrame* out,
                           std::size_t capacity, std::size_t* count);
fw::Status encode_pose(const hal::PoseEstimate& pose, std::uint8_t tag, bool fd, hal::CanFrame* out,
                       std::size_t capacity, std::size_t* count);
fw::Status encode_health(const HealthRecord& health, std::uint8_t tag, bool fd, hal::CanFrame* out,
                         std::size_t capacity, std::size_t* count);

// Operator commands (robot → fw) and replies (fw → robot), hal/msg/command.h. SET_POSE_HINT (and
// SELECT_MAP with a hint) is a 3-part record whose tag is the command's seq; SELECT_MAP without a
// hint and DUMP_LOG are single classic frames (valid on an FD bus too). The encoder refuses a
// non-finite hint or one beyond the wire's range (±2147 km, σ in (0, 65.534] m and (0, 6.5534] rad)
// with a message naming the field: a hint is never silently clamped into another one.
fw::Status encode_command(const hal::Command& command, bool fd, hal::CanFrame* out, std::size_t capacity,
                          std::size_t* count);
void encode_reply(const hal::CommandReply& reply, hal::CanFrame* out);

// Protection level ↔ u16 wire code (POSE part 5; `lsb_per_unit` = kProtectionXyPerMetre or
// kProtectionThetaPerRad). Encoding rounds up, maps NaN / ≤ 0 to 0 (no bound) and saturates at
// kProtectionSaturated (also +inf); it never wraps. Decoding maps 0 → 0 and the saturated code →
// +infinity (no finite bound is known to hold).
std::uint16_t protection_code(float bound, double lsb_per_unit);
float protection_value(std::uint16_t code, double lsb_per_unit);

struct DecoderStats {
  std::uint32_t frames = 0;
  std::uint32_t unknown_ids = 0;       // frames with an ID outside the message set (ignored)
  std::uint32_t malformed = 0;         // wrong length / impossible field values
  std::uint32_t scans_ok = 0;
  std::uint32_t scans_dropped = 0;     // every scan that started but was not delivered
  std::uint32_t crc_errors = 0;        // scan CRC-32 mismatch at SCAN_END
  std::uint32_t lost_segments = 0;     // segments missing (gaps, missing start/end)
  std::uint32_t duplicate_segments = 0;
  std::uint32_t out_of_order_segments = 0;
  std::uint32_t orphan_segments = 0;   // data segments with no transfer in progress
  std::uint32_t timeouts = 0;          // transfer not finished within the timeout
  std::uint32_t broken_records = 0;    // record parts missing / out of order / wrong tag
  std::uint32_t invalid_scans = 0;     // CRC right but impossible geometry/readings (also in scans_dropped)
  std::uint32_t invalid_by_defect[kNumScanDefects] = {};  // per ScanDefect
  ScanDefect last_defect = ScanDefect::kNone;
  std::uint32_t odometry_ok = 0, poses_ok = 0, health_ok = 0;
  std::uint32_t commands_ok = 0, replies_ok = 0;
  std::uint32_t malformed_commands = 0;  // command frames too short or with impossible fields (also in malformed)
};

enum class Decoded : std::uint8_t { kNothing, kScan, kOdometry, kPose, kHealth, kCommand, kReply };

class Decoder {
 public:
  struct Options {
    std::uint64_t scan_timeout_ns = 500'000'000;  // START..END must fit (frame timestamps)
  };
  Decoder() = default;
  explicit Decoder(const Options& o) : options_(o) {}

  // Feeds one frame. When it completes a message, returns its kind; the message is then in
  // scan() / odometry() / pose() / health() until the next completion of that kind.
  Decoded feed(const hal::CanFrame& frame);

  const hal::LaserScan& scan() const { return scan_; }
  const hal::Odometry& odometry() const { return odom_; }
  const hal::PoseEstimate& pose() const { return pose_; }
  const HealthRecord& health() const { return health_; }
  const hal::Command& command() const { return command_; }
  const hal::CommandReply& reply() const { return reply_; }
  std::uint64_t pose_time_us() const { return pose_time_us_; }
  const DecoderStats& stats() const { return stats_; }
  // Abandons an unfinished transfer older than the timeout (call when the bus is quiet).
  void check_timeout(std::uint64_t now_ns);

 private:
  struct Record {
    bool active = false;
    std::uint8_t tag = 0, next = 0;
    std::uint8_t bytes[kMaxRecordBytes] = {};
  };
  // Returns true when the record of `parts` parts is complete in rec->bytes.
  bool feed_part(Record* rec, std::size_t parts, std::size_t part, const hal::CanFrame& f);
  bool feed_fd_record(Record* rec, std::size_t parts, const hal::CanFrame& f);
  void start_scan(const std::uint8_t* payload, std::uint64_t t_ns);
  void scan_segment(const hal::CanFrame& f, bool fd);
  bool scan_end(const hal::CanFrame& f);
  void drop_scan(std::uint32_t missing_segments);
  // command_codec.cpp: the command and reply frames (kNothing when `id` is none of them).
  Decoded feed_command(std::uint32_t id, bool fd_id, const hal::CanFrame& f);
  Decoded command_malformed();

  Options options_;
  DecoderStats stats_;
  Record odom_rec_, start_rec_, pose_rec_, health_rec_, hint_rec_;

  // Scan transfer in progress.
  bool scan_active_ = false;
  bool scan_broken_ = false;
  bool scan_fd_ = false;
  std::uint64_t scan_started_ns_ = 0;
  std::uint32_t expected_segment_ = 0;
  std::uint32_t beams_received_ = 0;
  std::uint32_t range_unit_um_ = 1000;
  std::uint32_t scan_crc_ = 0;
  ScanDefect scan_defect_ = ScanDefect::kNone;  // decided at END, after the CRC
  hal::LaserScan scan_work_;

  hal::LaserScan scan_;
  hal::Odometry odom_;
  hal::PoseEstimate pose_;
  std::uint64_t pose_time_us_ = 0;
  HealthRecord health_;
  hal::Command command_;
  hal::CommandReply reply_;
};

}  // namespace hal_can
