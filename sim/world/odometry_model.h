// Odometry noise model (Sec. 5.7.1: Gaussian noise on the robot motions, σ = 4 cm and 4° per
// step). The true motion between consecutive odometry samples, u = g(τ₋)⁻¹ ⊕ g(τ), is perturbed
// component-wise with zero-mean Gaussian noise and chained in the odometry frame. The standard
// deviations are per *scan step*; when odometry is sampled k times per scan, each sample gets
// σ/√k, so the error accumulated over one scan step has the stated σ whatever the odometry rate.
//
// Wheel errors of real bases (issue 55, odometry_profiles.h), all off by default; the white model
// above is applied last, on top of them. With every one of them off a run is bit for bit what it
// was (they draw from a stream of their own, and only when on):
//   - proportional noise, per scan step like the tracker's α model (σ_trans = a·|Δs|, σ_rot =
//     b·|Δθ| + c·|Δs| over a scan interval, split over the samples as σ/√k above);
//   - systematic errors: the reported distance is (1 + scale_dist) × the driven one (a wheel radius
//     off), the reported turn (1 + scale_turn) × the turned one (a track width off);
//   - skid-steer: the base turns less than its wheels report, by a fraction s drawn per turn in
//     [turn_slip_min, turn_slip_max] (reported = turned / (1 − s)), and slides sideways (σ per metre);
//   - wheel-slip events: at a rate per 100 m driven, the wheels report slip_min_m–slip_max_m of
//     forward motion that did not happen, at once (one sample);
//   - turn-spin events: at a rate per radian turned, the wheels report turn_spin_min_deg–
//     turn_spin_max_deg more of the turn than the base made, at once (a wheel spinning or a caster
//     dragging through a turn; mit-killian's raw odometry reports 23° where the robot turned 5°).
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

  // ---- issue 55 (all off by default) ----
  double sigma_trans_per_m = 0.0;    // m per m driven (along the motion), per scan step
  double sigma_rot_per_rad = 0.0;    // rad per rad turned, per scan step
  double sigma_rot_deg_per_m = 0.0;  // deg per m driven, per scan step
  double scale_dist = 0.0;           // reported distance = (1 + scale_dist) × driven
  double scale_turn = 0.0;           // reported turn = (1 + scale_turn) × turned
  double turn_slip_min = 0.0;        // skid-steer heading slip, fraction of every turn, drawn per turn
  double turn_slip_max = 0.0;
  double sigma_lateral_per_m = 0.0;  // skid-steer sideways slide, m per m driven, per scan step
  double slip_events_per_100m = 0.0; // wheel-slip events per 100 m driven
  double slip_min_m = 0.3;           // forward motion the wheels report falsely in one event
  double slip_max_m = 1.0;
  double turn_spin_events_per_rad = 0.0;  // turn-spin events per radian turned
  double turn_spin_min_deg = 8.0;         // turn the wheels over-report in one event
  double turn_spin_max_deg = 20.0;

  // True when any issue-55 term is on.
  bool wheel_errors() const {
    return sigma_trans_per_m > 0 || sigma_rot_per_rad > 0 || sigma_rot_deg_per_m > 0 || scale_dist != 0 ||
           scale_turn != 0 || turn_slip_max > 0 || sigma_lateral_per_m > 0 || slip_events_per_100m > 0 ||
           turn_spin_events_per_rad > 0;
  }

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
  // Wheel-slip events so far (issue 55; for tests and reports).
  int slip_events() const { return slip_events_; }
  // Turn-spin events so far (issue 56's turn-scale wheel error).
  int turn_spin_events() const { return turn_spin_events_; }

 private:
  // The motion the wheels report for the true motion u (the issue-55 terms; u when all are off).
  fw::Se2d wheel_motion(const fw::Se2d& u, double fraction_of_scan_step);

  OdometryNoiseOptions opt_;
  fw::RandomStream rng_;
  fw::RandomStream wheel_rng_;  // the issue-55 terms' draws
  fw::Se2d last_truth_, odom_;
  std::uint64_t last_t_ns_ = 0;
  int turn_sign_ = 0;           // sign of the turn in progress (0: not turning)
  double turn_slip_ = 0.0;      // its slip fraction
  int slip_events_ = 0;
  int turn_spin_events_ = 0;
};

}  // namespace sim
