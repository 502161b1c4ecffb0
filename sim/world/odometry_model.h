// Odometry noise model (Sec. 5.7.1: Gaussian noise on the robot motions, σ = 4 cm and 4° per
// step). The true motion between consecutive odometry samples, u = g(τ₋)⁻¹ ⊕ g(τ), is perturbed
// component-wise with zero-mean Gaussian noise and chained in the odometry frame. The standard
// deviations are per *scan step*; when odometry is sampled k times per scan, each sample gets
// σ/√k, so the error accumulated over one scan step has the stated σ whatever the odometry rate.
#pragma once

#include <string>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "hal/msg/odometry.h"

namespace sim {

struct OdometryNoiseOptions {
  double sigma_trans = 0.04;     // m per scan step (each of x, y in the robot frame)
  double sigma_rot_deg = 4.0;    // deg per scan step
  fw::Se2d odom_origin;          // odometry-frame pose where the robot starts (not the map pose)

  std::string validate() const;
};

class OdometrySimulator {
 public:
  OdometrySimulator(const OdometryNoiseOptions& opt, std::uint64_t seed);
  // First sample: the robot is at true pose `truth` at time t_ns.
  hal::Odometry start(const fw::Se2d& truth, std::uint64_t t_ns);
  // Next sample. `fraction_of_scan_step` = (τ − τ₋) / scan period scales the variance.
  hal::Odometry next(const fw::Se2d& truth, std::uint64_t t_ns, double fraction_of_scan_step);
  // The robot is carried to `truth` (kidnapped): the wheels see nothing, odometry does not move.
  void teleport(const fw::Se2d& truth) { last_truth_ = truth; }
  const fw::Se2d& odom_pose() const { return odom_; }

 private:
  OdometryNoiseOptions opt_;
  fw::RandomStream rng_;
  fw::Se2d last_truth_, odom_;
  std::uint64_t last_t_ns_ = 0;
};

}  // namespace sim
