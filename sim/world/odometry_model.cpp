#include "sim/world/odometry_model.h"

#include <algorithm>
#include <cmath>

namespace sim {

namespace {
bool odom_in_range(double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; }

// The issue-55 fields (every message names its field).
std::string validate_wheel_errors(const OdometryNoiseOptions& o) {
  if (!odom_in_range(o.sigma_trans_per_m, 0, 1)) return "odometry sigma_trans_per_m must be in [0, 1]";
  if (!odom_in_range(o.sigma_rot_per_rad, 0, 1)) return "odometry sigma_rot_per_rad must be in [0, 1]";
  if (!odom_in_range(o.sigma_rot_deg_per_m, 0, 90)) return "odometry sigma_rot_deg_per_m must be in [0, 90]";
  if (!odom_in_range(o.scale_dist, -0.5, 0.5)) return "odometry scale_dist must be in [-0.5, 0.5]";
  if (!odom_in_range(o.scale_turn, -0.5, 0.5)) return "odometry scale_turn must be in [-0.5, 0.5]";
  if (!odom_in_range(o.turn_slip_min, 0, 0.5)) return "odometry turn_slip_min must be in [0, 0.5]";
  if (!odom_in_range(o.turn_slip_max, o.turn_slip_min, 0.5)) {
    return "odometry turn_slip_max must be in [turn_slip_min, 0.5]";
  }
  if (!odom_in_range(o.sigma_lateral_per_m, 0, 1)) return "odometry sigma_lateral_per_m must be in [0, 1]";
  if (!odom_in_range(o.slip_events_per_100m, 0, 100)) return "odometry slip_events_per_100m must be in [0, 100]";
  if (!odom_in_range(o.slip_min_m, 0, 10)) return "odometry slip_min_m must be in [0, 10] m";
  if (!odom_in_range(o.slip_max_m, o.slip_min_m, 10)) return "odometry slip_max_m must be in [slip_min_m, 10] m";
  if (!odom_in_range(o.turn_spin_events_per_rad, 0, 10)) return "odometry turn_spin_events_per_rad must be in [0, 10]";
  if (!odom_in_range(o.turn_spin_min_deg, 0, 90)) return "odometry turn_spin_min_deg must be in [0, 90]";
  if (!odom_in_range(o.turn_spin_max_deg, o.turn_spin_min_deg, 90)) {
    return "odometry turn_spin_max_deg must be in [turn_spin_min_deg, 90]";
  }
  return {};
}
}  // namespace

std::string OdometryNoiseOptions::validate() const {
  if (!(sigma_trans >= 0 && std::isfinite(sigma_trans))) return "odometry sigma_trans must be a number ≥ 0";
  if (!(sigma_rot_deg >= 0 && std::isfinite(sigma_rot_deg))) return "odometry sigma_rot_deg must be a number ≥ 0";
  return validate_wheel_errors(*this);
}

// Stream index 2 of the run's seed: odometry noise has its own generator; the issue-55 wheel errors
// another one (index 6), so the white model's draws are the same with or without them.
OdometrySimulator::OdometrySimulator(const OdometryNoiseOptions& opt, std::uint64_t seed)
    : opt_(opt), rng_(seed, 2), wheel_rng_(seed, 6) {}

hal::Odometry OdometrySimulator::start(const fw::Se2d& truth, std::uint64_t t_ns) {
  last_truth_ = truth;
  odom_ = opt_.odom_origin;
  last_t_ns_ = t_ns;
  hal::Odometry o;
  o.timestamp_ns = t_ns;
  o.x = static_cast<float>(odom_.x);
  o.y = static_cast<float>(odom_.y);
  o.theta = static_cast<float>(odom_.theta);
  return o;
}

// The proportional terms are per scan step, as the tracker's α model: over a scan interval of
// |Δs| metres and |Δθ| radians σ = a·|Δs| (+ …). A sample covering a fraction f of the step gets
// σ·√f of its step, i.e. a·(|Δs_sample| / f)·√f = a·|Δs_sample|/√f, so the samples of one step add
// up to a·|Δs| whatever the odometry rate (f = 0, a sample of no length in time, counts as a step).
fw::Se2d OdometrySimulator::wheel_motion(const fw::Se2d& u, double fraction_of_scan_step) {
  const double f = fraction_of_scan_step > 1e-9 ? fraction_of_scan_step : 1.0;
  const double d = std::hypot(u.x, u.y);
  const double step_m = d / std::sqrt(f), step_rad = std::fabs(u.theta) / std::sqrt(f);
  double turn = u.theta;
  if (opt_.turn_slip_max > 0) {
    // A turn is a run of samples turning the same way; each draws its own slip fraction.
    const int sign = std::fabs(u.theta) > 1e-9 ? (u.theta > 0 ? 1 : -1) : 0;
    if (sign != 0 && sign != turn_sign_) {
      turn_slip_ = opt_.turn_slip_min + (opt_.turn_slip_max - opt_.turn_slip_min) * wheel_rng_.uniform01();
    }
    turn_sign_ = sign;
    if (sign != 0) turn /= 1.0 - turn_slip_;  // the base turned (1 − s) × what the wheels report
  }
  turn *= 1.0 + opt_.scale_turn;
  double x = u.x * (1.0 + opt_.scale_dist), y = u.y * (1.0 + opt_.scale_dist);
  if (opt_.sigma_trans_per_m > 0) x += wheel_rng_.gaussian() * opt_.sigma_trans_per_m * step_m;
  if (opt_.sigma_rot_per_rad > 0 || opt_.sigma_rot_deg_per_m > 0) {
    const double sigma = opt_.sigma_rot_per_rad * step_rad + opt_.sigma_rot_deg_per_m * M_PI / 180.0 * step_m;
    turn += wheel_rng_.gaussian() * sigma;
  }
  if (opt_.sigma_lateral_per_m > 0) y += wheel_rng_.gaussian() * opt_.sigma_lateral_per_m * step_m;
  if (opt_.slip_events_per_100m > 0) {
    // Poisson events along the path: probability rate·d per sample (d ≪ 100 m / rate).
    const double draw = wheel_rng_.uniform01();
    if (draw < opt_.slip_events_per_100m / 100.0 * d) {
      x += opt_.slip_min_m + (opt_.slip_max_m - opt_.slip_min_m) * wheel_rng_.uniform01();
      ++slip_events_;
    }
  }
  if (opt_.turn_spin_events_per_rad > 0 && std::fabs(u.theta) > 1e-9) {
    // Poisson events along the turn: probability rate·|Δθ| per sample, over-reporting the turn.
    if (wheel_rng_.uniform01() < opt_.turn_spin_events_per_rad * std::fabs(u.theta)) {
      const double deg = opt_.turn_spin_min_deg + (opt_.turn_spin_max_deg - opt_.turn_spin_min_deg) * wheel_rng_.uniform01();
      turn += (u.theta > 0 ? 1.0 : -1.0) * deg * M_PI / 180.0;
      ++turn_spin_events_;
    }
  }
  return fw::Se2d(x, y, turn);
}

hal::Odometry OdometrySimulator::next(const fw::Se2d& truth, std::uint64_t t_ns, double fraction_of_scan_step) {
  const fw::Se2d u = last_truth_.between(truth);
  const double k = std::sqrt(std::max(0.0, fraction_of_scan_step));
  const double nx = rng_.gaussian() * opt_.sigma_trans * k;
  const double ny = rng_.gaussian() * opt_.sigma_trans * k;
  const double nt = rng_.gaussian() * opt_.sigma_rot_deg * M_PI / 180.0 * k;
  const fw::Se2d w = opt_.wheel_errors() ? wheel_motion(u, fraction_of_scan_step) : u;
  const fw::Se2d noisy(w.x + nx, w.y + ny, fw::wrap_angle(w.theta + nt));
  odom_ = odom_.compose(noisy);
  const double dt = t_ns > last_t_ns_ ? static_cast<double>(t_ns - last_t_ns_) * 1e-9 : 0.0;
  hal::Odometry o;
  o.timestamp_ns = t_ns;
  o.x = static_cast<float>(odom_.x);
  o.y = static_cast<float>(odom_.y);
  o.theta = static_cast<float>(odom_.theta);
  o.v = dt > 0 ? static_cast<float>(noisy.x / dt) : 0.0f;
  o.omega = dt > 0 ? static_cast<float>(noisy.theta / dt) : 0.0f;
  last_truth_ = truth;
  last_t_ns_ = t_ns;
  return o;
}

}  // namespace sim
