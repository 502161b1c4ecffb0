// IncrementFusion (extension of Alg. 1, issue 15): RBSM's map-anchored pose fused with the increments
// of a precise laser-to-laser matcher (PL-ICP, firmware/baselines/icp/pl_icp.h) by a Kalman filter
// on SE(2).
//
// Why: RBSM's 51 m end-point map keeps the chain consistent over a whole building (the long
// relations), but each estimate scatters by a few centimetres around the truth (the particles stop
// at the M_eff rule on a 5 cm binary grid; firmware/rbsm/README.md). PL-ICP against the previous key
// scan is precise from one scan to the next (short relations ≈ CSM's) but drifts metres over a log.
// The two errors live at different frequencies, so the textbook answer is a complementary filter:
// predict with the precise increment, correct with the drift-free pose. Written as a Kalman filter so
// the gain follows from two noise models a user can read off their own matchers, not a tuned factor:
//   predict  x ← x ⊕ u,  P ← J_x P J_xᵀ + J_u Q(u) J_uᵀ          (Eq. 3.4's propagation)
//   update   y = z ⊖ x (components), S = P + R, K = P S⁻¹, x ← x + K y, P ← (I − K) P
// with Q(u) = diag(σ_u², σ_u², σ_uθ²), σ_u = relative_sigma_m + relative_sigma_per_m·|u|,
// σ_uθ = relative_sigma_rad + relative_sigma_per_rad·|u_θ|, and R = diag(σ_a², σ_a², σ_aθ²) RBSM's
// per-scan scatter. A standing robot gets Q at its floor, so RBSM's jitter is averaged out; a long
// straight run grows P and hands the pose back to RBSM. Beyond the χ² gate (yᵀ S⁻¹ y > gate_chi2:
// RBSM's particle set diffused along a corridor, or the laser-to-laser matcher slid or lost its key
// scan) neither source is taken at face value: R is inflated until the innovation sits on the gate,
// so one scan moves the pose by a bounded amount and a lasting disagreement is still resolved
// towards the drift-free pose over the next scans (a Huber-type robust Kalman update).
// A scan without an increment (the relative matcher refused it) is predicted with RBSM's own
// increment and a wide Q (unknown_increment_scale × Q).
//
// Embedded rules: fixed-size Eigen, no heap, errors as Status.
#pragma once

#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/base/status.h"

namespace fw {

// One scan of the filter as a Rauch–Tung–Striebel smoother needs it (increment_smoother.h): the
// filtered pose and covariance, the prediction into this scan (before RBSM's pose was fused) and
// that prediction's state transition J_x = ∂(x ⊕ u)/∂x.
struct FusionStep {
  Se2d pose;
  Eigen::Matrix<double, 3, 3> cov = Eigen::Matrix<double, 3, 3>::Zero();
  Se2d predicted;
  Eigen::Matrix<double, 3, 3> predicted_cov = Eigen::Matrix<double, 3, 3>::Zero();
  Eigen::Matrix<double, 3, 3> transition = Eigen::Matrix<double, 3, 3>::Identity();
};

struct IncrementFusionOptions {
  // Relative matcher's error per increment (PL-ICP laser-to-laser): a floor and a share of the motion.
  double relative_sigma_m = 0.002;
  double relative_sigma_per_m = 0.01;
  double relative_sigma_rad = 0.0009;  // 0.05°
  double relative_sigma_per_rad = 0.01;
  // RBSM's per-scan scatter about the truth (its short relations' median is ~2 cm, README).
  double absolute_sigma_m = 0.03;
  double absolute_sigma_rad = 0.0087;  // 0.5°
  double gate_chi2 = 16.27;            // 3 dof, 99.9 %
  double unknown_increment_scale = 100.0;  // Q × this when the relative matcher gave no increment
  Status validate() const;
};

class IncrementFusion {
 public:
  Status init(const IncrementFusionOptions& options);
  void reset() { started_ = false; gated_ = 0; }

  // One scan: RBSM's pose `absolute` (world) and, when `has_increment`, the relative matcher's motion
  // since the previous scan (in the previous pose's frame). The first call starts at `absolute`.
  // Errors for non-finite input (the state is left unchanged).
  Status update(const Se2d& absolute, bool has_increment, const Se2d& increment);

  const Se2d& pose() const { return step_.pose; }
  const Eigen::Matrix<double, 3, 3>& covariance() const { return step_.cov; }
  const FusionStep& step() const { return step_; }  // the last update, for the smoother
  std::uint32_t gated_updates() const { return gated_; }  // updates down-weighted at the gate

 private:
  Eigen::Matrix<double, 3, 3> increment_cov(const Se2d& u, double scale) const;

  IncrementFusionOptions options_;
  Eigen::Matrix<double, 3, 3> r_ = Eigen::Matrix<double, 3, 3>::Zero();
  bool initialized_ = false;
  bool started_ = false;
  Se2d last_absolute_;
  FusionStep step_;
  std::uint32_t gated_ = 0;
};

}  // namespace fw
