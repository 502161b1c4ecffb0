#include "firmware/rbsm/increment_smoother.h"

#include <Eigen/LU>
#include <cmath>

namespace fw {

Status smooth_fusion_steps(FusionStep* steps, std::size_t n) {
  using M3 = Eigen::Matrix<double, 3, 3>;
  using V3 = Eigen::Matrix<double, 3, 1>;
  for (std::size_t k = n; k-- > 1;) {
    const FusionStep& next = steps[k];
    FusionStep& s = steps[k - 1];
    // P̂ is symmetric positive definite when it came from the filter (Q has a floor): Sylvester's
    // criterion on its leading minors, then the closed-form 3×3 inverse (no allocation, unlike a
    // Cholesky factorisation's blocked path in unoptimised builds).
    const M3& p = next.predicted_cov;
    const double m1 = p(0, 0), m2 = p(0, 0) * p(1, 1) - p(0, 1) * p(1, 0), m3 = p.determinant();
    if (!(m1 > 0.0 && m2 > 0.0 && m3 > 0.0)) {
      return Status::error(Errc::kInvalidArgument,
                           "increment smoother: the predicted covariance of step %zu is not positive definite", k);
    }
    const M3 gain = s.cov * next.transition.transpose() * p.inverse();
    if (!gain.allFinite()) {
      return Status::error(Errc::kInvalidArgument, "increment smoother: non-finite gain at step %zu", k);
    }
    const V3 d(next.pose.x - next.predicted.x, next.pose.y - next.predicted.y,
               wrap_angle(next.pose.theta - next.predicted.theta));
    const V3 dx = gain * d;
    s.pose = Se2d(s.pose.x + dx(0), s.pose.y + dx(1), wrap_angle(s.pose.theta + dx(2)));
    const M3 cov = s.cov + gain * (next.cov - next.predicted_cov) * gain.transpose();
    s.cov = 0.5 * (cov + cov.transpose());
  }
  return Status::ok();
}

}  // namespace fw
