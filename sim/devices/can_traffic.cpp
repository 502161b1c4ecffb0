#include "sim/devices/can_traffic.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include "sim/devices/candump_log.h"
#include "sim/io/log_replay.h"

namespace sim {

namespace {

// range_max 0.01 m in the start payload, then the END frame's CRC recomputed over what is sent: a
// scan intact on the wire whose content no scanner produces (the decoder must refuse it by name).
void make_scan_impossible(std::vector<hal::CanFrame>* frames, bool fd) {
  using namespace hal_can;
  std::uint8_t start[kScanStartParts * kPartBytes];
  const size_t first_data = fd ? 1 : kScanStartParts;
  if (fd) {
    put_u16((*frames)[0].data + 1 + 11, 1);
    std::memcpy(start, (*frames)[0].data + 1, sizeof start);
  } else {
    put_u16((*frames)[1].data + 1 + (11 - kPartBytes), 1);  // offset 11 lies in part 1
    for (size_t p = 0; p < kScanStartParts; ++p) std::memcpy(start + p * kPartBytes, (*frames)[p].data + 1, kPartBytes);
  }
  const size_t beams = get_u16(start + 2);
  const size_t per = fd ? kFdRangesPerSegment : kClassicRangesPerSegment;
  std::uint32_t crc = crc32_update(crc32_begin(), start, sizeof start);
  for (size_t i = first_data, b0 = 0; i + 1 < frames->size(); ++i, b0 += per) {
    const size_t nb = beams - b0 < per ? beams - b0 : per;
    crc = crc32_update(crc, (*frames)[i].data + 2, 2 * nb);
  }
  put_u32(frames->back().data + 4, crc32_end(crc));
}

}  // namespace

bool build_can_traffic(const CarmenLog& log, const CanTrafficOptions& o, std::vector<TimedFrame>* out,
                       CanTrafficSummary* summary, std::string* error) {
  *summary = CanTrafficSummary{};
  out->clear();
  if (o.first_scan >= log.scans.size()) {
    *error = log.path + ": first scan " + std::to_string(o.first_scan) + " beyond the " +
             std::to_string(log.scans.size()) + " scans of the log";
    return false;
  }
  if (!(o.speed > 0) || !std::isfinite(o.speed)) {
    *error = "speed must be a positive number";
    return false;
  }
  const size_t last = o.num_scans ? std::min(log.scans.size(), o.first_scan + o.num_scans) : log.scans.size();
  const double t0 = log.scans[o.first_scan].ipc_timestamp - 1.0;
  const double t_end = log.scans[last - 1].ipc_timestamp;
  summary->sensor_t0 = t0;
  // Log time of scan k (counted from first_scan): where the campaign's faults begin.
  auto scan_time = [&](size_t k, bool enabled) {
    return enabled && o.first_scan + k < last ? log.scans[o.first_scan + k].ipc_timestamp : 1e300;
  };
  const double jump_t = scan_time(o.time_jump_at, o.time_jump_s != 0);
  const double jump_base = o.time_jump_s < 0 ? -o.time_jump_s : 0.0;  // keeps the sensor clock positive
  auto sensor_ns = [&](double ipc) {
    return seconds_to_ns(ipc - t0 + jump_base + (ipc >= jump_t ? o.time_jump_s : 0.0));
  };
  auto replay_t = [&](double ipc) { return o.start_time + (ipc - t0) / o.speed; };
  const double silence_t = scan_time(o.silence_at, o.silence_s > 0);
  const double odom_jump_t = scan_time(o.odom_jump_at, o.odom_jump_m != 0);
  const double odom_reset_t = scan_time(o.odom_reset_at, o.odom_reset_at > 0);
  bool have_reset_origin = false;
  fw::Se2d reset_origin;

  struct Item {
    double ipc;
    int kind;  // 0 odom, 1 scan
    size_t index;
  };
  std::vector<Item> items;
  for (size_t i = 0; i < log.odom.size(); ++i) {
    const double t = log.odom[i].ipc_timestamp;
    if (t >= t0 && t <= t_end) items.push_back({t, 0, i});
  }
  const bool odom_from_scans = items.empty();  // e.g. mit-killian: no ODOM records
  for (size_t i = o.first_scan; i < last; ++i) {
    if (odom_from_scans) items.push_back({log.scans[i].ipc_timestamp - 1e-6, 2, i});
    items.push_back({log.scans[i].ipc_timestamp, 1, i});
  }
  std::stable_sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.ipc < b.ipc; });

  std::vector<hal::CanFrame> buf(hal_can::kMaxScanFrames);
  std::uint8_t odom_tag = 0;
  hal_can::EncodeOptions eo;
  eo.fd = o.fd;
  for (const Item& it : items) {
    double t = replay_t(it.ipc);
    size_t n = 0;
    if (it.kind == 0 || it.kind == 2) {
      hal::Odometry od;
      od.timestamp_ns = sensor_ns(it.ipc);
      if (it.kind == 0) {
        const CarmenOdom& c = log.odom[it.index];
        od.x = static_cast<float>(c.pose.x);
        od.y = static_cast<float>(c.pose.y);
        od.theta = static_cast<float>(c.pose.theta);
        od.v = static_cast<float>(c.tv);
        od.omega = static_cast<float>(c.rv);
      } else {
        const CarmenScan& s = log.scans[it.index];
        od.x = static_cast<float>(s.odom.x);
        od.y = static_cast<float>(s.odom.y);
        od.theta = static_cast<float>(s.odom.theta);
      }
      if (it.ipc >= odom_reset_t) {
        const fw::Se2d pose(od.x, od.y, od.theta);
        if (!have_reset_origin) { reset_origin = pose; have_reset_origin = true; }
        const fw::Se2d rel = reset_origin.inverse().compose(pose);
        od.x = static_cast<float>(rel.x);
        od.y = static_cast<float>(rel.y);
        od.theta = static_cast<float>(rel.theta);
      }
      if (it.ipc >= odom_jump_t) od.x += static_cast<float>(o.odom_jump_m);
      fw::Status st = hal_can::encode_odometry(od, odom_tag++, o.fd, buf.data(), buf.size(), &n);
      if (!st.is_ok()) { *error = st.message(); return false; }
      for (size_t i = 0; i < n; ++i) out->push_back({t + i * 1e-6, buf[i], false});
      ++summary->odometry_sent;
      continue;
    }
    const size_t k = it.index - o.first_scan;
    if (it.ipc >= silence_t && it.ipc < silence_t + o.silence_s) {
      ++summary->scans_silenced;  // the laser says nothing (never sent)
      continue;
    }
    // Swapped pair: each scan travels at the other's time, keeping its own sensor timestamp.
    if (o.swap_every && k % o.swap_every == o.swap_every - 1 && it.index + 1 < last) {
      t = replay_t(log.scans[it.index + 1].ipc_timestamp) + 1e-4;
      ++summary->scans_swapped;
    } else if (o.swap_every && k >= 1 && (k - 1) % o.swap_every == o.swap_every - 1) {
      t = replay_t(log.scans[it.index - 1].ipc_timestamp) - 1e-4;
    }
    if (o.bus_off_burst && o.bus_off_at && k == o.bus_off_at) {
      for (size_t b = 0; b < o.bus_off_burst; ++b) {
        TimedFrame ef;
        ef.t = t - 0.002 + b * 1e-5;
        ef.error_frame = true;
        ef.frame.id = kCanErrBusOff;
        ef.frame.len = 8;
        out->push_back(ef);
        ++summary->error_frames;
      }
    }
    hal::LaserScan scan = to_laser_scan(log.scans[it.index], sensor_ns(it.ipc));
    scan.scan_id = static_cast<std::uint32_t>(it.index & 0xFFFF);
    fw::Status st = hal_can::encode_scan(scan, eo, buf.data(), buf.size(), &n);
    if (!st.is_ok()) { *error = log.path + ": scan " + std::to_string(it.index) + ": " + st.message(); return false; }
    std::vector<hal::CanFrame> frames(buf.begin(), buf.begin() + static_cast<long>(n));
    const size_t first_data = o.fd ? 1 : hal_can::kScanStartParts;
    const size_t data_frames = n - first_data - 1;
    const size_t victim = first_data + (k * 7) % data_frames;
    bool faulty = false;
    if (o.corrupt_every && k % o.corrupt_every == o.corrupt_every - 1) {
      frames[victim].data[2] ^= 0x5A;  // a range byte: only the CRC can notice
      ++summary->scans_corrupted;
      faulty = true;
    } else if (o.drop_every && k % o.drop_every == o.drop_every / 2) {
      frames.erase(frames.begin() + static_cast<long>(victim));
      ++summary->scans_missing_segment;
      faulty = true;
    } else if (o.duplicate_every && k % o.duplicate_every == o.duplicate_every / 3) {
      frames.insert(frames.begin() + static_cast<long>(victim), frames[victim]);
      ++summary->scans_duplicated;
      faulty = true;
    }
    if (!faulty && o.invalid_every && k % o.invalid_every == o.invalid_every - 1) {
      make_scan_impossible(&frames, o.fd);
      ++summary->scans_invalid;
      faulty = true;
    }
    for (size_t i = 0; i < frames.size(); ++i) out->push_back({t + i * 1e-6, frames[i], false});
    ++summary->scans_sent;
    if (!faulty) ++summary->scans_intact;
  }
  std::stable_sort(out->begin(), out->end(), [](const TimedFrame& a, const TimedFrame& b) { return a.t < b.t; });
  summary->frames = out->size();
  summary->duration_s = out->empty() ? 0 : out->back().t - out->front().t;
  return true;
}

bool write_candump_log(const std::string& path, const std::string& iface, const std::vector<TimedFrame>& frames,
                       std::string* error) {
  std::ofstream f(path);
  if (!f) { *error = path + ": cannot write"; return false; }
  for (const TimedFrame& tf : frames) {
    f << (tf.error_frame ? format_error_frame_line(tf.t, iface, tf.frame.id) : format_candump_line(tf.t, iface, tf.frame))
      << '\n';
  }
  if (!f) { *error = path + ": write failed"; return false; }
  return true;
}

PoseScore score_pose_frames(const std::vector<hal::CanFrame>& frames, const std::vector<fw::Se2d>& reference,
                            const PoseScoreOptions& o) {
  PoseScore s;
  hal_can::Decoder d;
  const size_t last = o.num_scans ? o.first_scan + o.num_scans : SIZE_MAX;
  long long prev_index = -1;
  bool have_health = false;
  hal_can::HealthRecord prev_h;
  double sum = 0, sum_loc = 0;
  for (const hal::CanFrame& f : frames) {
    ++s.frames;
    const hal_can::Decoded k = d.feed(f);
    if (k == hal_can::Decoded::kPose) {
      const hal::PoseEstimate& p = d.pose();
      // scan_id is the log index modulo 2^16: recover the index among the sent scans.
      size_t base = o.first_scan & ~static_cast<size_t>(0xFFFF);
      size_t index = base + p.scan_id;
      if (index < o.first_scan) index += 0x10000;
      if (static_cast<long long>(index) == prev_index && p.status == hal::LocalizationStatus::kFault) {
        // The firmware's laser-timeout: the last pose repeated with status `fault` (no new scan).
        ++s.fault_updates;
        continue;
      }
      ++s.poses;
      ++s.status_counts[static_cast<int>(p.status)];
      if (index < o.first_scan || index >= last) {
        s.violations.push_back("pose for scan id " + std::to_string(p.scan_id) + " that was never sent");
        continue;
      }
      if (static_cast<long long>(index) <= prev_index) {
        s.violations.push_back("pose scan ids not increasing: " + std::to_string(index) + " after " +
                               std::to_string(prev_index));
      }
      prev_index = static_cast<long long>(index);
      const bool loc = p.status == hal::LocalizationStatus::kLocalized;
      if (loc) {
        ++s.localized;
        if (s.localized == 1) s.first_localized_scan = index - o.first_scan;
        if (!(p.cov[0] >= 0 && p.cov[4] >= 0 && p.cov[8] >= 0)) s.violations.push_back("localized pose without covariance");
      }
      if (index < reference.size()) {
        const fw::Se2d& r = reference[index];
        const double e = std::hypot(p.x - r.x, p.y - r.y);
        if (o.dump) {
          std::fprintf(o.dump, "%zu %s %.3f %.3f %.3f %.3f %.3f\n", index, hal::status_name(p.status),
                       static_cast<double>(p.x), static_cast<double>(p.y), r.x, r.y, e);
        }
        ++s.scored;
        sum += e;
        s.max_err_m = std::max(s.max_err_m, e);
        if (loc) {
          sum_loc += e;
          s.max_err_localized_m = std::max(s.max_err_localized_m, e);
          if (e > o.localized_bound_m) ++s.wrong_localized;
        }
      }
    } else if (k == hal_can::Decoded::kHealth) {
      const hal_can::HealthRecord& h = d.health();
      ++s.health;
      if (have_health) {
        if (h.uptime_ms < prev_h.uptime_ms) s.violations.push_back("health uptime went backwards");
        if (h.crc_errors < prev_h.crc_errors || h.lost_segments < prev_h.lost_segments ||
            h.dropped_scans < prev_h.dropped_scans || h.bus_off < prev_h.bus_off ||
            h.scans_processed < prev_h.scans_processed) {
          s.violations.push_back("health counters decreased");
        }
      }
      if (h.state > 2) s.violations.push_back("health state " + std::to_string(h.state) + " unknown");
      s.health_fault_bits_seen |= h.fault_bits;
      if (have_health && prev_h.fault_bits != 0 && h.fault_bits == 0) ++s.health_fault_clears;
      prev_h = h;
      have_health = true;
    }
  }
  s.decoder = d.stats();
  s.last_health = prev_h;
  if (s.scored) s.mean_err_m = sum / static_cast<double>(s.scored);
  size_t scored_loc = 0;
  (void)scored_loc;
  if (s.localized) s.mean_err_localized_m = sum_loc / static_cast<double>(s.localized);
  if (s.decoder.broken_records || s.decoder.malformed) {
    s.violations.push_back("firmware output has " + std::to_string(s.decoder.broken_records) + " broken records and " +
                           std::to_string(s.decoder.malformed) + " malformed frames");
  }
  return s;
}

}  // namespace sim
