#include "hal_can/codec.h"

#include "record_frames.h"

#include <cmath>
#include <cstring>
#include <limits>

namespace hal_can {
namespace {

using fw::Errc;
using fw::Status;

constexpr std::size_t kStartPayload = kScanStartParts * kPartBytes;  // 28
constexpr std::size_t kOdomPayload = kOdomParts * kPartBytes;        // 28
constexpr std::size_t kPosePayload = kPoseParts * kPartBytes;        // 42
constexpr std::size_t kHealthPayload = kHealthParts * kPartBytes;    // 35

std::int32_t clamp_i32(double v) {
  if (!(v == v)) return 0;
  if (v > 2147483647.0) return 2147483647;
  if (v < -2147483648.0) return -2147483647 - 1;
  return static_cast<std::int32_t>(std::lround(v));
}
std::uint16_t clamp_u16(double v) {
  if (!(v >= 0.0)) return v != v ? 0xFFFF : 0;  // NaN → saturated ("unknown"), negative → 0
  if (v > 65535.0) return 0xFFFF;
  return static_cast<std::uint16_t>(std::lround(v));
}
std::int16_t clamp_i16(double v) {
  if (!(v == v)) return 0;
  if (v > 32767.0) return 32767;
  if (v < -32768.0) return -32768;
  return static_cast<std::int16_t>(std::lround(v));
}

}  // namespace

// Cuts a record payload into classic parts or one FD frame (record_frames.h).
Status emit_record(std::uint32_t base_id, std::size_t parts, std::uint8_t tag, const std::uint8_t* payload, bool fd,
                   hal::CanFrame* out, std::size_t capacity, std::size_t* count, const char* what) {
  const std::size_t need = fd ? 1 : parts;
  if (capacity < need) {
    return Status::error(Errc::kCapacityExceeded, "encode %s: frame buffer holds %zu frames, need %zu", what,
                         capacity, need);
  }
  if (fd) {
    hal::CanFrame& f = out[0];
    f = hal::CanFrame{};
    f.id = base_id | kFdIdFlag;
    f.fd = true;
    f.brs = true;
    f.len = fd_length_for(1 + parts * kPartBytes);
    f.data[0] = tag;
    std::memcpy(f.data + 1, payload, parts * kPartBytes);
  } else {
    for (std::size_t k = 0; k < parts; ++k) {
      hal::CanFrame& f = out[k];
      f = hal::CanFrame{};
      f.id = base_id + static_cast<std::uint32_t>(k);
      f.len = 8;
      f.data[0] = tag;
      std::memcpy(f.data + 1, payload + k * kPartBytes, kPartBytes);
    }
  }
  *count = need;
  return Status::ok();
}

namespace {

std::uint32_t choose_range_unit_um(float range_max) {
  static const std::uint32_t kUnits[] = {1000, 2000, 5000, 10000, 50000};
  for (std::uint32_t u : kUnits) {
    if (static_cast<double>(range_max) * 1e6 / u < 65000.0) return u;
  }
  return 50000;
}

}  // namespace

const char* scan_defect_name(ScanDefect d) {
  switch (d) {
    case ScanDefect::kNone: return "none";
    case ScanDefect::kRangeMax: return "range_max not in [0.1, 250] m";
    case ScanDefect::kRangeMin: return "range_min negative or not below range_max";
    case ScanDefect::kAngleIncrement: return "angle increment zero, not finite or beyond 2 pi";
    case ScanDefect::kFieldOfView: return "field of view beyond 2 pi";
    case ScanDefect::kAngleMin: return "angle_min beyond +-2 pi";
    case ScanDefect::kRangeBeyondMax: return "reading beyond range_max";
  }
  return "unknown";
}

ScanDefect scan_geometry_defect(const hal::LaserScan& s) {
  constexpr double kTwoPi = 6.283185307179586;
  constexpr double kSlack = 1e-4;  // quantisation of the wire fields (0.1 µrad, 1 µrad)
  if (!(s.range_max >= kMinPlausibleRangeM) || !(s.range_max <= kMaxPlausibleRangeM)) return ScanDefect::kRangeMax;
  if (!(s.range_min >= 0.0f) || !(s.range_min < s.range_max)) return ScanDefect::kRangeMin;
  const double inc = static_cast<double>(s.angle_increment);
  if (!std::isfinite(inc) || inc == 0.0 || std::fabs(inc) > kTwoPi + kSlack) return ScanDefect::kAngleIncrement;
  const double fov = std::fabs(inc) * (s.beam_count > 0 ? s.beam_count - 1 : 0);
  if (fov > kTwoPi + kSlack) return ScanDefect::kFieldOfView;
  if (!std::isfinite(s.angle_min) || std::fabs(static_cast<double>(s.angle_min)) > kTwoPi + kSlack) {
    return ScanDefect::kAngleMin;
  }
  return ScanDefect::kNone;
}

std::uint8_t fd_length_for(std::size_t n) {
  static const std::uint8_t kLens[] = {12, 16, 20, 24, 32, 48, 64};
  if (n <= 8) return static_cast<std::uint8_t>(n);
  for (std::uint8_t l : kLens) {
    if (n <= l) return l;
  }
  return 64;
}

std::uint16_t protection_code(float bound, double lsb_per_unit) {
  // NaN, negative and 0 all mean "no bound": an unusable bound must never reach the robot as a
  // number. +inf and anything beyond the range saturate (the receiver reads "at least the max").
  if (!(bound > 0.0f)) return 0;
  // Round up: the published bound must hold, so it may grow by < 1 LSB but never shrink. The
  // 1e-6 relative slack absorbs the float representation error of the input (0.1f m is
  // 100.0000015 mm and should stay 100 mm, not become 101 mm); it shrinks no bound by more than
  // 1e-6 of itself. Codes start at 1: a tiny positive bound is 1 LSB, not "no bound".
  const double c = std::ceil(static_cast<double>(bound) * lsb_per_unit * (1.0 - 1e-6));
  if (!(c < kProtectionSaturated)) return kProtectionSaturated;  // also +inf
  return static_cast<std::uint16_t>(c < 1.0 ? 1.0 : c);
}

float protection_value(std::uint16_t code, double lsb_per_unit) {
  if (code == 0) return 0.0f;
  // Saturated: the true bound is at least the largest code, so report no finite bound rather
  // than a smaller number that would not hold.
  if (code == kProtectionSaturated) return std::numeric_limits<float>::infinity();
  return static_cast<float>(code / lsb_per_unit);
}

std::size_t scan_frame_count(std::uint32_t beam_count, bool fd) {
  const std::size_t per = fd ? kFdRangesPerSegment : kClassicRangesPerSegment;
  return (fd ? 1 : kScanStartParts) + (beam_count + per - 1) / per + 1;
}

Status encode_scan(const hal::LaserScan& scan, const EncodeOptions& opt, hal::CanFrame* out, std::size_t capacity,
                   std::size_t* count) {
  *count = 0;
  if (scan.beam_count == 0 || scan.beam_count > hal::LaserScan::kMaxBeams) {
    return Status::error(Errc::kInvalidArgument, "encode scan %u: beam_count %u outside 1..%u", scan.scan_id,
                         scan.beam_count, hal::LaserScan::kMaxBeams);
  }
  if (!std::isfinite(scan.angle_min) || !std::isfinite(scan.angle_increment) || !std::isfinite(scan.range_max) ||
      scan.range_max <= 0.0f) {
    return Status::error(Errc::kInvalidArgument, "encode scan %u: non-finite angle or range_max %g", scan.scan_id,
                         static_cast<double>(scan.range_max));
  }
  const ScanDefect defect = scan_geometry_defect(scan);
  if (defect != ScanDefect::kNone) {
    return Status::error(Errc::kInvalidArgument, "encode scan %u: %s (range %g..%g m, increment %g rad, %u beams)",
                         scan.scan_id, scan_defect_name(defect), static_cast<double>(scan.range_min),
                         static_cast<double>(scan.range_max), static_cast<double>(scan.angle_increment),
                         scan.beam_count);
  }
  const std::size_t need = scan_frame_count(scan.beam_count, opt.fd);
  if (capacity < need) {
    return Status::error(Errc::kCapacityExceeded, "encode scan %u: frame buffer holds %zu frames, need %zu",
                         scan.scan_id, capacity, need);
  }
  const std::uint32_t unit = opt.range_unit_um ? opt.range_unit_um : choose_range_unit_um(scan.range_max);
  if (unit > 65535) return Status::error(Errc::kInvalidArgument, "encode scan: range unit %u um > 65535", unit);

  std::uint8_t start[kStartPayload] = {};
  put_u16(start + 0, static_cast<std::uint16_t>(scan.scan_id));
  put_u16(start + 2, static_cast<std::uint16_t>(scan.beam_count));
  put_u16(start + 4, static_cast<std::uint16_t>(unit));
  start[6] = 0;  // flags (reserved)
  put_u32(start + 7, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(scan.angle_min) * 1e6)));
  put_u16(start + 11, clamp_u16(static_cast<double>(scan.range_max) * 100.0));
  put_u32(start + 14, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(scan.angle_increment) * 1e7)));
  put_u16(start + 18, clamp_u16(static_cast<double>(scan.range_min) * 100.0));
  put_u48(start + 21, scan.timestamp_ns / 1000);

  std::size_t n = 0;
  std::size_t k = 0;
  FW_RETURN_IF_ERROR(emit_record(kScanStartId, kScanStartParts, static_cast<std::uint8_t>(scan.scan_id), start,
                                 opt.fd, out, capacity, &k, "scan start"));
  n += k;
  std::uint32_t crc = crc32_update(crc32_begin(), start, sizeof(start));

  const std::size_t per = opt.fd ? kFdRangesPerSegment : kClassicRangesPerSegment;
  const std::uint32_t segments = static_cast<std::uint32_t>((scan.beam_count + per - 1) / per);
  for (std::uint32_t s = 0; s < segments; ++s) {
    hal::CanFrame& f = out[n++];
    f = hal::CanFrame{};
    f.id = kScanDataId | (opt.fd ? kFdIdFlag : 0);
    f.fd = opt.fd;
    f.brs = opt.fd;
    put_u16(f.data, static_cast<std::uint16_t>((s & 0xFFF) | ((scan.scan_id & 0xF) << 12)));
    std::size_t b0 = s * per;
    std::size_t nb = scan.beam_count - b0 < per ? scan.beam_count - b0 : per;
    for (std::size_t i = 0; i < nb; ++i) {
      const float r = scan.ranges[b0 + i];
      std::uint16_t code = kNoReturn;
      if (std::isfinite(r) && r >= 0.0f && r < scan.range_max) {
        const double c = std::round(static_cast<double>(r) * 1e6 / unit);
        if (c < 65535.0) code = static_cast<std::uint16_t>(c);
      }
      put_u16(f.data + 2 + 2 * i, code);
    }
    crc = crc32_update(crc, f.data + 2, 2 * nb);
    const std::size_t bytes = 2 + 2 * nb;
    f.len = opt.fd ? fd_length_for(bytes) : static_cast<std::uint8_t>(bytes);
  }
  hal::CanFrame& e = out[n++];
  e = hal::CanFrame{};
  e.id = kScanEndId;
  e.len = 8;
  put_u16(e.data, static_cast<std::uint16_t>(scan.scan_id));
  put_u16(e.data + 2, static_cast<std::uint16_t>(segments));
  put_u32(e.data + 4, crc32_end(crc));
  *count = n;
  return Status::ok();
}

Status encode_odometry(const hal::Odometry& odom, std::uint8_t tag, bool fd, hal::CanFrame* out, std::size_t capacity,
                       std::size_t* count) {
  std::uint8_t p[kOdomPayload] = {};
  put_u32(p + 0, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(odom.x) * 1000.0)));
  put_u16(p + 4, static_cast<std::uint16_t>(clamp_i16(static_cast<double>(odom.v) * 1000.0)));
  put_u32(p + 7, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(odom.y) * 1000.0)));
  put_u16(p + 11, static_cast<std::uint16_t>(clamp_i16(static_cast<double>(odom.omega) * 1000.0)));
  put_u32(p + 14, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(odom.theta) * 1e6)));
  put_u48(p + 21, odom.timestamp_ns / 1000);
  return emit_record(kOdomId, kOdomParts, tag, p, fd, out, capacity, count, "odometry");
}

Status encode_pose(const hal::PoseEstimate& pose, std::uint8_t tag, bool fd, hal::CanFrame* out, std::size_t capacity,
                   std::size_t* count) {
  std::uint8_t p[kPosePayload] = {};
  put_u16(p + 0, static_cast<std::uint16_t>(pose.scan_id));
  p[2] = static_cast<std::uint8_t>(pose.status);
  p[3] = static_cast<std::uint8_t>(pose.mode);
  put_u16(p + 4, pose.hypothesis_count);
  p[6] = pose.cluster_count > 255 ? 255 : static_cast<std::uint8_t>(pose.cluster_count);
  auto sigma = [](float var) { return var > 0.0f ? std::sqrt(static_cast<double>(var)) : 0.0; };
  put_u32(p + 7, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(pose.x) * 1000.0)));
  put_u16(p + 11, clamp_u16(sigma(pose.cov[0]) * 1000.0));
  const double rating = pose.rating < 0.0f ? 0.0 : (pose.rating > 1.0f ? 1.0 : static_cast<double>(pose.rating));
  p[13] = static_cast<std::uint8_t>(std::lround(rating * 255.0));
  put_u32(p + 14, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(pose.y) * 1000.0)));
  put_u16(p + 18, clamp_u16(sigma(pose.cov[4]) * 1000.0));
  put_u32(p + 21, static_cast<std::uint32_t>(clamp_i32(static_cast<double>(pose.theta) * 1e6)));
  put_u16(p + 25, clamp_u16(sigma(pose.cov[8]) * 1e4));
  put_u48(p + 28, pose.timestamp_ns / 1000);
  p[kPoseLayoutOffset] = kPoseLayout;
  // Part 5 (layout 1): protection level (RAIM-style bound, hal/msg/pose_estimate.h) and the
  // number of scans since one last confirmed the pose; layout 2: the status reason in p[41].
  put_u16(p + 35, protection_code(pose.protection_xy_m, kProtectionXyPerMetre));
  put_u16(p + 37, protection_code(pose.protection_theta_rad, kProtectionThetaPerRad));
  put_u16(p + 39, pose.unsupported_steps);
  p[kPoseReasonOffset] = static_cast<std::uint8_t>(pose.reason);
  return emit_record(kPoseId, kPoseParts, tag, p, fd, out, capacity, count, "pose");
}

Status encode_health(const HealthRecord& h, std::uint8_t tag, bool fd, hal::CanFrame* out, std::size_t capacity,
                     std::size_t* count) {
  std::uint8_t p[kHealthPayload] = {};
  put_u32(p + 0, h.uptime_ms);
  p[4] = h.state;
  put_u16(p + 5, h.invalid_scans);
  put_u16(p + 7, h.crc_errors);
  put_u16(p + 9, h.lost_segments);
  put_u16(p + 11, h.dropped_scans);
  put_u16(p + 14, h.timeouts);
  put_u16(p + 16, h.deadline_misses);
  put_u16(p + 18, h.bus_off);
  put_u32(p + 21, h.scans_processed);
  put_u16(p + 25, h.rx_dropped);
  put_u32(p + 28, h.fault_bits);
  put_u16(p + 32, h.error_frames);
  p[kHealthHintOffset] = h.hint_status;
  return emit_record(kHealthId, kHealthParts, tag, p, fd, out, capacity, count, "health");
}

// ---------------------------------------------------------------------------------------------
// Decoder

bool Decoder::feed_part(Record* rec, std::size_t parts, std::size_t part, const hal::CanFrame& f) {
  if (f.len != 8) {
    ++stats_.malformed;
    if (rec->active) ++stats_.broken_records;
    rec->active = false;
    return false;
  }
  if (part == 0) {
    if (rec->active) ++stats_.broken_records;  // previous record never finished
    rec->active = true;
    rec->tag = f.data[0];
    rec->next = 1;
  } else if (!rec->active || rec->tag != f.data[0] || rec->next != part) {
    // A part of a record whose beginning we missed, or parts out of order: drop it.
    if (rec->active || part + 1 == parts) ++stats_.broken_records;
    rec->active = false;
    return false;
  } else {
    ++rec->next;
  }
  std::memcpy(rec->bytes + part * kPartBytes, f.data + 1, kPartBytes);
  if (part + 1 == parts) {
    rec->active = false;
    return true;
  }
  return false;
}

bool Decoder::feed_fd_record(Record* rec, std::size_t parts, const hal::CanFrame& f) {
  if (f.len < 1 + parts * kPartBytes) {
    ++stats_.malformed;
    return false;
  }
  rec->active = false;
  rec->tag = f.data[0];
  std::memcpy(rec->bytes, f.data + 1, parts * kPartBytes);
  return true;
}

void Decoder::drop_scan(std::uint32_t missing_segments) {
  if (!scan_active_) return;
  scan_active_ = false;
  ++stats_.scans_dropped;
  stats_.lost_segments += missing_segments;
}

void Decoder::check_timeout(std::uint64_t now_ns) {
  if (scan_active_ && now_ns > scan_started_ns_ && now_ns - scan_started_ns_ > options_.scan_timeout_ns) {
    ++stats_.timeouts;
    drop_scan(0);
  }
}

void Decoder::start_scan(const std::uint8_t* p, std::uint64_t t_ns) {
  if (scan_active_) {
    // The previous transfer never ended: its END (and maybe segments) were lost.
    const std::size_t per = scan_fd_ ? kFdRangesPerSegment : kClassicRangesPerSegment;
    const std::uint32_t total = static_cast<std::uint32_t>((scan_work_.beam_count + per - 1) / per);
    drop_scan(total > expected_segment_ ? total - expected_segment_ : 0);
  }
  const std::uint16_t beams = get_u16(p + 2);
  const std::uint16_t unit = get_u16(p + 4);
  if (beams == 0 || beams > hal::LaserScan::kMaxBeams || unit == 0) {
    ++stats_.malformed;
    ++stats_.scans_dropped;
    return;
  }
  scan_work_.scan_id = get_u16(p + 0);
  scan_work_.beam_count = beams;
  range_unit_um_ = unit;
  scan_work_.angle_min = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 7)) * 1e-6);
  scan_work_.range_max = static_cast<float>(get_u16(p + 11) * 0.01);
  scan_work_.angle_increment = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 14)) * 1e-7);
  scan_work_.range_min = static_cast<float>(get_u16(p + 18) * 0.01);
  scan_work_.timestamp_ns = get_u48(p + 21) * 1000;
  scan_defect_ = scan_geometry_defect(scan_work_);
  scan_active_ = true;
  scan_broken_ = false;
  scan_started_ns_ = t_ns;
  expected_segment_ = 0;
  beams_received_ = 0;
  scan_crc_ = crc32_update(crc32_begin(), p, kStartPayload);
}

void Decoder::scan_segment(const hal::CanFrame& f, bool fd) {
  if (f.len < 2) {
    ++stats_.malformed;
    return;
  }
  const std::uint16_t hdr = get_u16(f.data);
  const std::uint32_t seg = hdr & 0xFFF;
  const std::uint32_t tag = hdr >> 12;
  if (!scan_active_) {
    // Data of a scan whose start we missed: that scan is counted at its END (or as a timeout).
    ++stats_.orphan_segments;
    return;
  }
  if (tag != (scan_work_.scan_id & 0xF) || fd != scan_fd_) {
    ++stats_.malformed;
    scan_broken_ = true;
    return;
  }
  if (scan_broken_) return;  // already dropped; wait for END / next START
  if (seg < expected_segment_) {
    ++stats_.duplicate_segments;
    scan_broken_ = true;
    return;
  }
  if (seg > expected_segment_) {
    stats_.lost_segments += seg - expected_segment_;
    ++stats_.out_of_order_segments;
    scan_broken_ = true;
    return;
  }
  const std::size_t per = fd ? kFdRangesPerSegment : kClassicRangesPerSegment;
  const std::uint32_t remaining = scan_work_.beam_count - beams_received_;
  const std::uint32_t nb = remaining < per ? remaining : static_cast<std::uint32_t>(per);
  if (nb == 0 || f.len < 2 + 2 * nb) {
    ++stats_.malformed;
    scan_broken_ = true;
    return;
  }
  const float unit_m = static_cast<float>(range_unit_um_ * 1e-6);
  // The encoder sends readings at/above range_max as "no return"; anything decoded beyond it
  // (more than the quantisation of both fields) cannot come from a sane scan.
  const float beyond = scan_work_.range_max + unit_m + 0.01f;
  for (std::uint32_t i = 0; i < nb; ++i) {
    const std::uint16_t code = get_u16(f.data + 2 + 2 * i);
    const float r = code == kNoReturn ? scan_work_.range_max : code * unit_m;
    if (r > beyond && scan_defect_ == ScanDefect::kNone) scan_defect_ = ScanDefect::kRangeBeyondMax;
    scan_work_.ranges[beams_received_ + i] = r;
  }
  scan_crc_ = crc32_update(scan_crc_, f.data + 2, 2 * nb);
  beams_received_ += nb;
  ++expected_segment_;
}

bool Decoder::scan_end(const hal::CanFrame& f) {
  if (f.len != 8) {
    ++stats_.malformed;
    return false;
  }
  const std::uint16_t id = get_u16(f.data);
  const std::uint16_t segments = get_u16(f.data + 2);
  const std::uint32_t crc = get_u32(f.data + 4);
  if (!scan_active_ || id != static_cast<std::uint16_t>(scan_work_.scan_id)) {
    // END of a scan whose START was lost: everything before it is gone.
    ++stats_.scans_dropped;
    stats_.lost_segments += segments;
    if (scan_active_) drop_scan(0);
    return false;
  }
  if (scan_broken_) {
    drop_scan(0);
    return false;
  }
  if (expected_segment_ != segments || beams_received_ != scan_work_.beam_count) {
    drop_scan(segments > expected_segment_ ? segments - expected_segment_ : 0);
    return false;
  }
  if (crc32_end(scan_crc_) != crc) {
    ++stats_.crc_errors;
    drop_scan(0);
    return false;
  }
  if (scan_defect_ != ScanDefect::kNone) {
    // Intact on the wire, impossible in content: a named decode error, never a valid scan.
    ++stats_.invalid_scans;
    ++stats_.invalid_by_defect[static_cast<int>(scan_defect_)];
    stats_.last_defect = scan_defect_;
    drop_scan(0);
    return false;
  }
  scan_active_ = false;
  ++stats_.scans_ok;
  scan_ = scan_work_;
  return true;
}

Decoded Decoder::feed(const hal::CanFrame& f) {
  ++stats_.frames;
  if (f.extended) {
    ++stats_.unknown_ids;
    return Decoded::kNothing;
  }
  check_timeout(f.timestamp_ns);
  const bool fd_id = (f.id & kFdIdFlag) != 0;
  const std::uint32_t id = f.id & ~kFdIdFlag;
  if (fd_id && !f.fd) {
    ++stats_.malformed;
    return Decoded::kNothing;
  }
  const std::uint8_t* p = nullptr;
  if (id >= kOdomId && id < kOdomId + kOdomParts) {
    const bool done = fd_id ? (id == kOdomId && feed_fd_record(&odom_rec_, kOdomParts, f))
                            : feed_part(&odom_rec_, kOdomParts, id - kOdomId, f);
    if (!done) return Decoded::kNothing;
    p = odom_rec_.bytes;
    odom_.x = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 0)) * 1e-3);
    odom_.v = static_cast<float>(static_cast<std::int16_t>(get_u16(p + 4)) * 1e-3);
    odom_.y = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 7)) * 1e-3);
    odom_.omega = static_cast<float>(static_cast<std::int16_t>(get_u16(p + 11)) * 1e-3);
    odom_.theta = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 14)) * 1e-6);
    odom_.timestamp_ns = get_u48(p + 21) * 1000;
    ++stats_.odometry_ok;
    return Decoded::kOdometry;
  }
  if (id >= kScanStartId && id < kScanStartId + kScanStartParts) {
    const bool done = fd_id ? (id == kScanStartId && feed_fd_record(&start_rec_, kScanStartParts, f))
                            : feed_part(&start_rec_, kScanStartParts, id - kScanStartId, f);
    if (done) {
      start_scan(start_rec_.bytes, f.timestamp_ns);
      scan_fd_ = fd_id;
    }
    return Decoded::kNothing;
  }
  if (id == kScanDataId) {
    scan_segment(f, fd_id);
    return Decoded::kNothing;
  }
  if (id == kScanEndId && !fd_id) {
    return scan_end(f) ? Decoded::kScan : Decoded::kNothing;
  }
  if (id >= kPoseId && id < kPoseId + kPoseParts) {
    // FD: both layouts travel in a 48-byte frame (layout 0 padded with zeros), so the 6-part
    // length check accepts either.
    bool done = fd_id ? (id == kPoseId && feed_fd_record(&pose_rec_, kPoseParts, f))
                      : feed_part(&pose_rec_, kPoseParts, id - kPoseId, f);
    if (!done && !fd_id && id - kPoseId + 1 == kPoseLegacyParts && pose_rec_.active &&
        pose_rec_.next == kPoseLegacyParts && pose_rec_.bytes[kPoseLayoutOffset] == 0) {
      // Part 4 of a layout-0 sender (no protection part) completes its record.
      pose_rec_.active = false;
      done = true;
    }
    if (!done) return Decoded::kNothing;
    p = pose_rec_.bytes;
    pose_ = hal::PoseEstimate{};
    pose_.scan_id = get_u16(p + 0);
    if (p[2] > static_cast<std::uint8_t>(hal::LocalizationStatus::kFault) ||
        p[3] > static_cast<std::uint8_t>(hal::LocalizationMode::kTracking)) {
      ++stats_.malformed;
      return Decoded::kNothing;
    }
    pose_.status = static_cast<hal::LocalizationStatus>(p[2]);
    pose_.mode = static_cast<hal::LocalizationMode>(p[3]);
    pose_.hypothesis_count = get_u16(p + 4);
    pose_.cluster_count = p[6];
    pose_.x = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 7)) * 1e-3);
    const double sx = get_u16(p + 11) * 1e-3, sy = get_u16(p + 18) * 1e-3, st = get_u16(p + 25) * 1e-4;
    pose_.rating = static_cast<float>(p[13] / 255.0);
    pose_.y = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 14)) * 1e-3);
    pose_.theta = static_cast<float>(static_cast<std::int32_t>(get_u32(p + 21)) * 1e-6);
    pose_.cov[0] = static_cast<float>(sx * sx);
    pose_.cov[4] = static_cast<float>(sy * sy);
    pose_.cov[8] = static_cast<float>(st * st);
    pose_time_us_ = get_u48(p + 28);
    pose_.timestamp_ns = pose_time_us_ * 1000;
    if (p[kPoseLayoutOffset] != 0) {  // layouts only append: any layout >= 1 has part 5
      pose_.protection_xy_m = protection_value(get_u16(p + 35), kProtectionXyPerMetre);
      pose_.protection_theta_rad = protection_value(get_u16(p + 37), kProtectionThetaPerRad);
      pose_.unsupported_steps = get_u16(p + 39);
    }
    if (p[kPoseLayoutOffset] >= 2) {
      if (p[kPoseReasonOffset] >= hal::kStatusReasonCount) {
        ++stats_.malformed;
        return Decoded::kNothing;
      }
      pose_.reason = static_cast<hal::StatusReason>(p[kPoseReasonOffset]);
    }
    ++stats_.poses_ok;
    return Decoded::kPose;
  }
  if (id >= kHealthId && id < kHealthId + kHealthParts) {
    const bool done = fd_id ? (id == kHealthId && feed_fd_record(&health_rec_, kHealthParts, f))
                            : feed_part(&health_rec_, kHealthParts, id - kHealthId, f);
    if (!done) return Decoded::kNothing;
    p = health_rec_.bytes;
    health_ = HealthRecord{};
    health_.uptime_ms = get_u32(p + 0);
    health_.state = p[4];
    health_.invalid_scans = get_u16(p + 5);
    health_.crc_errors = get_u16(p + 7);
    health_.lost_segments = get_u16(p + 9);
    health_.dropped_scans = get_u16(p + 11);
    health_.timeouts = get_u16(p + 14);
    health_.deadline_misses = get_u16(p + 16);
    health_.bus_off = get_u16(p + 18);
    health_.scans_processed = get_u32(p + 21);
    health_.rx_dropped = get_u16(p + 25);
    health_.fault_bits = get_u32(p + 28);
    health_.error_frames = get_u16(p + 32);
    health_.hint_status = p[kHealthHintOffset];
    ++stats_.health_ok;
    return Decoded::kHealth;
  }
  if (id >= kPoseHintId && id <= kCommandReplyId) return feed_command(id, fd_id, f);
  ++stats_.unknown_ids;
  return Decoded::kNothing;
}

}  // namespace hal_can
