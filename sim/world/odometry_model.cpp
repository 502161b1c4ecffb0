#include "sim/world/odometry_model.h"

#include <cmath>

namespace sim {

std::string OdometryNoiseOptions::validate() const {
  if (!(sigma_trans >= 0 && std::isfinite(sigma_trans))) return "odometry sigma_trans must be a number ≥ 0";
  if (!(sigma_rot_deg >= 0 && std::isfinite(sigma_rot_deg))) return "odometry sigma_rot_deg must be a number ≥ 0";
  return {};
}

// Stream index 2 of the run's seed: odometry noise has its own generator.
OdometrySimulator::OdometrySimulator(const OdometryNoiseOptions& opt, std::uint64_t seed) : opt_(opt), rng_(seed, 2) {}

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

hal::Odometry OdometrySimulator::next(const fw::Se2d& truth, std::uint64_t t_ns, double fraction_of_scan_step) {
  const fw::Se2d u = last_truth_.between(truth);
  const double k = std::sqrt(std::max(0.0, fraction_of_scan_step));
  const double nx = rng_.gaussian() * opt_.sigma_trans * k;
  const double ny = rng_.gaussian() * opt_.sigma_trans * k;
  const double nt = rng_.gaussian() * opt_.sigma_rot_deg * M_PI / 180.0 * k;
  const fw::Se2d noisy(u.x + nx, u.y + ny, fw::wrap_angle(u.theta + nt));
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
