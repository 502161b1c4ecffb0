// RplidarDevice: a Slamtec RPLIDAR as the host sees it on the wire (hal/serial's encoder), for
// mml-rplidardev and the pty round-trip tests. It answers STOP (stream off, no answer), RESET (its
// boot banner, then idle), GET_HEALTH, GET_INFO, SCAN / FORCE_SCAN (5-byte samples) and
// EXPRESS_SCAN in the legacy capsule format; SET_MOTOR_PWM is taken silently. samples() turns a
// polar scan into the bytes of `n` samples of the turning head: the head's angle runs on across
// calls (a turn is not locked to the index, like a real unit), the first sample of every turn
// carries the start flag, distances in 1/4 mm, clockwise angles (hal::LaserScan is CCW).
#pragma once

#include <cstdint>
#include <string>

#include "hal_serial/rplidar_protocol.h"
#include "sim/devices/polar_scan.h"

namespace sim {

struct RplidarModel {
  const char* name;            // "a1", "a2", "a3", "s1"
  std::uint8_t model_id;       // GET_INFO model byte
  std::uint8_t firmware_major, firmware_minor, hardware;
  double rate_hz;              // turns per second
  double samples_per_s;        // SCAN mode
  double max_range_m;
};
const RplidarModel* find_rplidar_model(const std::string& name);
const char* rplidar_model_names();

class RplidarDevice {
 public:
  explicit RplidarDevice(const RplidarModel& model) : model_(model) {}
  void receive(const std::uint8_t* bytes, size_t n, std::string* out);
  bool streaming() const { return streaming_; }
  bool express() const { return express_; }
  // Samples per turn in the current mode (express: whole capsules of 32).
  size_t samples_per_turn() const;
  // The next `n` samples (SCAN: n × 5 bytes; express: n / 32 capsules) appended to *out;
  // returns how many turns were completed (start flags sent).
  size_t samples(const PolarScan& scan, size_t n, std::string* out);
  void set_health(std::uint8_t status, std::uint16_t code) { health_ = status; health_code_ = code; }
  void power_cycle(std::string* out);  // RESET / power dip: banner, idle
  const RplidarModel& model() const { return model_; }
  size_t commands() const { return commands_; }

 private:
  void request(std::uint8_t cmd, std::string* out);
  std::uint16_t distance_at(const PolarScan& scan, double cw_deg) const;

  RplidarModel model_;
  std::string pending_;
  bool streaming_ = false, express_ = false, first_ = true;
  std::uint8_t health_ = hal_serial::kRplidarHealthGood;
  std::uint16_t health_code_ = 0;
  double angle_deg_ = 0.37;  // the head's angle, clockwise
  bool have_capsule_ = false;
  size_t commands_ = 0;
};

}  // namespace sim
