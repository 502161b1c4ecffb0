#include "sim/devices/rplidar_device.h"

#include <cmath>

namespace sim {

using namespace hal_serial;

namespace {

const RplidarModel kRplidarModels[] = {
    // A1M8: 5.5 Hz, 2000 samples/s (SCAN), 12 m; GET_INFO model 0x18, firmware 1.29, hardware 7.
    {"a1", 0x18, 1, 29, 7, 5.5, 2000.0, 12.0},
    // A2M8: 10 Hz, 4000 samples/s (SCAN), 16 m.
    {"a2", 0x28, 1, 27, 5, 10.0, 4000.0, 16.0},
    // A3M1: 10 Hz, SCAN at 8000 samples/s, 25 m.
    {"a3", 0x31, 1, 26, 6, 10.0, 8000.0, 25.0},
    // S1: 10 Hz, 9200 samples/s, 40 m.
    {"s1", 0x41, 1, 2, 18, 10.0, 9200.0, 40.0},
};

void append_bytes(std::string* out, const std::uint8_t* b, size_t n) { out->append(reinterpret_cast<const char*>(b), n); }

}  // namespace

const RplidarModel* find_rplidar_model(const std::string& name) {
  for (const RplidarModel& m : kRplidarModels)
    if (name == m.name) return &m;
  return nullptr;
}

const char* rplidar_model_names() { return "a1, a2, a3, s1"; }

size_t RplidarDevice::samples_per_turn() const {
  const double n = model_.samples_per_s / model_.rate_hz;
  if (!express_) return static_cast<size_t>(std::lround(n));
  // Express: twice the SCAN rate in 32-sample capsules (the legacy mode doubles an A1's 2 kHz).
  return static_cast<size_t>(std::lround(2.0 * n / 32.0)) * 32;
}

void RplidarDevice::power_cycle(std::string* out) {
  streaming_ = false;
  have_capsule_ = false;
  pending_.clear();
  const char banner[] = "RP LIDAR System.\r\nFirmware Ver 1.29 - rtm, HW Ver 7\r\nModel: 24\r\n";
  out->append(banner, sizeof(banner) - 1);
}

void RplidarDevice::receive(const std::uint8_t* bytes, size_t n, std::string* out) {
  pending_.append(reinterpret_cast<const char*>(bytes), n);
  while (!pending_.empty()) {
    if (static_cast<std::uint8_t>(pending_[0]) != kRplidarSync) {
      pending_.erase(0, 1);
      continue;
    }
    if (pending_.size() < 2) return;
    const std::uint8_t cmd = static_cast<std::uint8_t>(pending_[1]);
    size_t used = 2;
    if (cmd & 0x80) {  // a payload: size, bytes, checksum
      if (pending_.size() < 3) return;
      used = 4 + static_cast<std::uint8_t>(pending_[2]);
      if (pending_.size() < used) return;
    }
    pending_.erase(0, used);
    request(cmd, out);
  }
}

void RplidarDevice::request(std::uint8_t cmd, std::string* out) {
  ++commands_;
  std::uint8_t d[7];
  switch (cmd) {
    case kRplidarCmdStop: streaming_ = false; return;
    case kRplidarCmdReset:
      streaming_ = false;
      health_ = kRplidarHealthGood;
      power_cycle(out);
      return;
    case kRplidarCmdGetHealth: {
      encode_rplidar_descriptor(kRplidarHealthSize, 0, kRplidarAnsHealth, d);
      append_bytes(out, d, 7);
      const std::uint8_t h[3] = {health_, static_cast<std::uint8_t>(health_code_),
                                 static_cast<std::uint8_t>(health_code_ >> 8)};
      append_bytes(out, h, 3);
      return;
    }
    case kRplidarCmdGetInfo: {
      encode_rplidar_descriptor(kRplidarInfoSize, 0, kRplidarAnsInfo, d);
      append_bytes(out, d, 7);
      std::uint8_t info[20] = {model_.model_id, model_.firmware_minor, model_.firmware_major, model_.hardware};
      for (int i = 0; i < 16; ++i) info[4 + i] = static_cast<std::uint8_t>(0x59 + i);
      append_bytes(out, info, 20);
      return;
    }
    case kRplidarCmdScan:
    case kRplidarCmdForceScan:
    case kRplidarCmdExpressScan:
      express_ = cmd == kRplidarCmdExpressScan;
      encode_rplidar_descriptor(express_ ? kRplidarCapsuleSize : kRplidarSampleSize, 1,
                                express_ ? kRplidarAnsCapsule : kRplidarAnsSample, d);
      append_bytes(out, d, 7);
      streaming_ = true;
      first_ = true;
      have_capsule_ = false;
      return;
    default: return;  // SET_MOTOR_PWM and others: no answer
  }
}

std::uint16_t RplidarDevice::distance_at(const PolarScan& scan, double cw_deg) const {
  double r = 0.0;
  double a = -cw_deg * M_PI / 180.0;  // clockwise → counter-clockwise, in [-π, π)
  while (a < -M_PI) a += 2.0 * M_PI;
  while (a >= M_PI) a -= 2.0 * M_PI;
  if (!scan.at(a, &r) || r > model_.max_range_m) return 0;  // 0: no measurement
  const double q2 = std::round(r * 4000.0);
  return static_cast<std::uint16_t>(q2 > 65535.0 ? 0 : q2);
}

size_t RplidarDevice::samples(const PolarScan& scan, size_t n, std::string* out) {
  if (!streaming_) return 0;
  const double step = 360.0 / static_cast<double>(samples_per_turn());
  size_t turns = 0;
  if (!express_) {
    for (size_t k = 0; k < n; ++k) {
      const double next = angle_deg_ + step;
      RplidarSample s;
      s.start = first_;
      first_ = false;
      s.angle_q6 = static_cast<std::uint16_t>(std::lround(angle_deg_ * 64.0)) % (360 * 64);
      s.distance_q2 = distance_at(scan, angle_deg_);
      s.quality = s.distance_q2 != 0 ? 47 : 0;
      std::uint8_t b[5];
      encode_rplidar_sample(s, b);
      append_bytes(out, b, 5);
      angle_deg_ = next;
      if (angle_deg_ >= 360.0) {
        angle_deg_ -= 360.0;
        first_ = true;  // the next sample begins a new turn
        ++turns;
      }
    }
    return turns;
  }
  // Express: capsules of 32 samples at offsets 0 from the linear interpolation between this
  // capsule's start angle and the next's (the host decodes a capsule when the next arrives).
  for (size_t k = 0; k + 32 <= n; k += 32) {
    RplidarCapsule c;
    c.start = !have_capsule_;
    have_capsule_ = true;
    c.start_angle_q6 = static_cast<std::uint16_t>(std::lround(angle_deg_ * 64.0)) % (360 * 64);
    for (int j = 0; j < 32; ++j) {
      c.distance_mm[j] = static_cast<std::uint16_t>(distance_at(scan, std::fmod(angle_deg_ + j * step, 360.0)) / 4);
      c.offset_q3[j] = 0;
    }
    std::uint8_t raw[84];
    encode_rplidar_capsule(c, raw);
    append_bytes(out, raw, 84);
    angle_deg_ += 32 * step;
    if (angle_deg_ >= 360.0) {
      angle_deg_ -= 360.0;
      ++turns;
    }
  }
  return turns;
}

}  // namespace sim
