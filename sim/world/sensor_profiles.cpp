// The four lidar profiles of issue 55 with the figures of their public data sheets (quoted from
// memory of the sheets, no web access when written; each figure named where it is used). What no
// sheet states is said so, with the value chosen:
//   - random dropouts: 1 % per beam for every profile (the dissertation's simulation, Sec. 5.7.1);
//   - glass: no sheet gives a figure. A pane returns an echo near normal incidence and passes the
//     beam otherwise; a 30 % pane return (the working value) for every profile;
//   - systematic (per-unit, fixed) range errors are not modelled; only the statistical part is;
//   - scans are taken at one instant (no motion skew over a revolution), at the period the caller
//     sets (SyntheticRunOptions::scan_period_s); rate_hz is the sensor's own rate for that choice.
// No return is reported as range_max for every profile, the convention of hal::LaserScan.
#include "sim/world/sensor_profiles.h"

namespace sim {

namespace {

// SICK LMS200-30106 (Technical Description "LMS200/211/221/291 Laser Measurement Systems",
// 8008970): 180°, angular resolution 1°/0.5°/0.25° (181/361/721 values), mirror at 75 Hz with a
// response time of 13/26/53 ms: 0.5° interlaces two mirror turns, so 361 beams come at 37.5 Hz.
// Range 80 m max (cm mode), 10 m at 10 % remission (the LMS291 reaches 30 m). mm mode: 8 m, 1 mm
// resolution, statistical error 5 mm (1σ), systematic ±15 mm; cm mode: 10 mm resolution,
// systematic ±4 cm. The bench logs (../shared/data/README.md) are cm mode: every range a multiple
// of 0.01 m, a missing echo stored as 81.83–81.91 m (8191 cm, the largest value of the 13-bit
// field): max_range 81.91 m, 1 cm quantum, σ 5 mm. Reflectivity: hits fade from 10 m (10 %
// remission) to all lost at the maximum range (far_dropout ramp).
SensorProfile lms200() {
  SensorProfile p;
  p.name = "lms200";
  p.source = "SICK LMS200-30106 technical description 8008970: 180 deg, 0.5 deg, 75 Hz mirror (37.5 Hz at 0.5 deg), "
             "80 m max / 10 m at 10 % remission, cm mode 10 mm resolution, 5 mm (1 sigma) statistical error";
  p.rate_hz = 37.5;
  LaserModelOptions& l = p.laser;
  l.beams = 361;
  l.fov_deg = 180.0;
  l.max_range = 81.91;
  l.min_range = 0.02;
  l.sigma_range = 0.005;
  l.range_quantum_m = 0.01;
  l.dropout_rate = 0.01;
  l.glass_return_probability = 0.3;
  l.far_dropout_from = 10.0 / 81.91;
  l.far_dropout_max = 1.0;
  return p;
}

// Hokuyo UTM-30LX (specification sheet UTM-30LX, C-42-3615): 270°, 0.25° (1081 steps), 25 ms per
// scan (40 Hz), 0.1–30 m guaranteed on white Kent sheet (60 m max), accuracy ±30 mm for 0.1–10 m
// and ±50 mm for 10–30 m, 1 mm resolution. Taken as σ (no better than the sheet):
// σ = 20 mm + 1 mm/m meets both, 30 mm at 10 m and 50 mm at 30 m. max_range 30 m, the guaranteed
// range; the sheet gives no range at low remission, so no far-dropout ramp.
SensorProfile utm30lx() {
  SensorProfile p;
  p.name = "utm30lx";
  p.source = "Hokuyo UTM-30LX specification C-42-3615: 270 deg, 0.25 deg (1081), 40 Hz, 0.1-30 m, "
             "+-30 mm to 10 m / +-50 mm to 30 m, 1 mm resolution";
  p.rate_hz = 40.0;
  LaserModelOptions& l = p.laser;
  l.beams = 1081;
  l.fov_deg = 270.0;
  l.max_range = 30.0;
  l.min_range = 0.1;
  l.sigma_range = 0.02;
  l.sigma_range_per_m = 0.001;
  l.range_quantum_m = 0.001;
  l.dropout_rate = 0.01;
  l.glass_return_probability = 0.3;
  return p;
}

// SICK TiM571-2050101 (product data sheet): 270°, 0.33° (811 values), 15 Hz, 0.05–25 m, 8 m at
// 10 % remission (25 m at 90 %), systematic error ±60 mm, statistical error 20 mm (1σ), 1 mm
// resolution. Hits fade from 8 m (= 0.32 of 25 m) to all lost at 25 m.
SensorProfile tim571() {
  SensorProfile p;
  p.name = "tim571";
  p.source = "SICK TiM571-2050101 data sheet: 270 deg, 0.33 deg (811), 15 Hz, 0.05-25 m (8 m at 10 % remission), "
             "systematic +-60 mm, statistical 20 mm, 1 mm resolution";
  p.rate_hz = 15.0;
  LaserModelOptions& l = p.laser;
  l.beams = 811;
  l.fov_deg = 270.0;
  l.max_range = 25.0;
  l.min_range = 0.05;
  l.sigma_range = 0.02;
  l.range_quantum_m = 0.001;
  l.dropout_rate = 0.01;
  l.glass_return_probability = 0.3;
  l.far_dropout_from = 8.0 / 25.0;
  l.far_dropout_max = 1.0;
  return p;
}

// Slamtec RPLIDAR A1 (A1M8 data sheet v2.x): 360°, angular resolution ≤ 1°, 5.5 Hz typical
// (1–10 Hz), 2000 samples/s in standard mode, 0.15–12 m (white object), accuracy ≈1 % of the
// range (≤ 3 m; 2–2.5 % beyond), range resolution 0.25 mm (the wire's Q2 millimetres). 2000 / 5.5
// = 364 samples a turn, 0.99° apart and not locked to the index: each turn starts at another
// phase and the motor's speed wavers, so the angles are irregular (a per-revolution offset and a
// 0.2° jitter, resampled onto the 1° grid, laser_model.cpp). σ = 1 mm + 1 %·r (the sheet's 1 %;
// its 2–2.5 % beyond 3 m is left to the glass and dropout terms). No range at low remission is
// given, so no far-dropout ramp.
SensorProfile rplidar_a1() {
  SensorProfile p;
  p.name = "rplidar-a1";
  p.source = "Slamtec RPLIDAR A1M8 data sheet: 360 deg, <=1 deg, 5.5 Hz, 2 kHz samples, 0.15-12 m, "
             "accuracy 1 % of range, 0.25 mm resolution, irregular sample angles";
  p.rate_hz = 5.5;
  LaserModelOptions& l = p.laser;
  l.beams = 360;
  l.fov_deg = 360.0;
  l.max_range = 12.0;
  l.min_range = 0.15;
  l.sigma_range = 0.001;
  l.sigma_range_per_m = 0.01;
  l.range_quantum_m = 0.00025;
  l.dropout_rate = 0.01;
  l.glass_return_probability = 0.3;
  l.angle_jitter_deg = 0.2;
  l.revolution_offset = true;
  return p;
}

}  // namespace

const std::vector<SensorProfile>& sensor_profiles() {
  static const std::vector<SensorProfile> all = {lms200(), utm30lx(), tim571(), rplidar_a1()};
  return all;
}

const SensorProfile* find_sensor_profile(const std::string& name) {
  for (const SensorProfile& p : sensor_profiles()) {
    if (p.name == name) return &p;
  }
  return nullptr;
}

}  // namespace sim
