#include "hal_serial/rplidar_revolution.h"

#include <cmath>

namespace hal_serial {

namespace {
constexpr double kRevolutionPi = 3.141592653589793;
}  // namespace

void RplidarRevolution::init(const RplidarRevolutionOptions& options) {
  options_ = options;
  if (options_.beams == 0 || options_.beams > hal::LaserScan::kMaxBeams) options_.beams = 360;
  if (options_.min_samples == 0) options_.min_samples = 1;
  reset();
}

void RplidarRevolution::reset() {
  if (started_ && count_ > 0) ++stats_.partial;  // a turn cut off by a restart
  started_ = false;
  count_ = 0;
}

void RplidarRevolution::begin(std::uint64_t t_ns) {
  started_ = true;
  count_ = 0;
  t0_ns_ = t_ns;
  for (std::uint32_t j = 0; j < options_.beams; ++j) {
    best_[j] = 1.0f;
    ranges_[j] = options_.range_max_m;
  }
}

void RplidarRevolution::place(const RplidarSample& s) {
  ++count_;
  if (s.distance_q2 == 0 || s.quality == 0) {
    ++stats_.invalid;
    return;
  }
  const double n = static_cast<double>(options_.beams);
  // Clockwise θ → counter-clockwise −θ; slots from −π, 2π/n apart.
  const double theta = static_cast<double>(s.angle_q6) / 64.0 * kRevolutionPi / 180.0;
  double slots = (-theta + kRevolutionPi) / (2.0 * kRevolutionPi) * n;  // in (-∞, n]: wrap
  slots = std::fmod(slots, n);
  if (slots < 0) slots += n;
  const double k = std::floor(slots + 0.5);
  const float off = static_cast<float>(std::fabs(slots - k));
  std::uint32_t j = static_cast<std::uint32_t>(k);
  if (j >= options_.beams) j -= options_.beams;
  ++stats_.samples;
  if (off >= best_[j]) {
    ++stats_.collisions;
    return;
  }
  if (best_[j] <= 0.5f) ++stats_.collisions;
  best_[j] = off;
  float r = static_cast<float>(s.distance_q2) * 0.00025f;
  if (r > options_.range_max_m) r = options_.range_max_m;
  ranges_[j] = r;
}

bool RplidarRevolution::add(const RplidarSample& s, std::uint64_t t_ns, hal::LaserScan* out) {
  bool closed = false;
  if (s.start) {
    if (started_ && count_ >= options_.min_samples) {
      hal::LaserScan& o = *out;
      o.timestamp_ns = t0_ns_;
      o.scan_id = next_id_++;
      o.beam_count = options_.beams;
      o.angle_min = static_cast<float>(-kRevolutionPi);
      o.angle_increment = static_cast<float>(2.0 * kRevolutionPi / static_cast<double>(options_.beams));
      o.range_min = options_.range_min_m;
      o.range_max = options_.range_max_m;
      for (std::uint32_t j = 0; j < options_.beams; ++j) o.ranges[j] = ranges_[j];
      ++stats_.revolutions;
      closed = true;
    } else if (started_) {
      ++stats_.partial;  // too few samples: the motor spinning up or stalling, data lost
    }
    begin(t_ns);
  } else if (!started_) {
    ++stats_.leading;  // before the first start flag: the rest of a turn we did not see begin
    return false;
  } else if (count_ >= options_.max_samples) {
    ++stats_.overlong;
    started_ = false;
    return false;
  }
  place(s);
  return closed;
}

}  // namespace hal_serial
