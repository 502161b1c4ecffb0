#include "firmware/antslam/sampled_edge.h"

#include <Eigen/LU>  // Matrix::inverse (closed form for 3x3)
#include <cmath>

namespace fw::antslam {
namespace {

// Cholesky factor of a 3x3 covariance, written out: Eigen::LLT's unblocked path goes through its
// dynamic-size block products, which reference malloc in unoptimised/sanitizer builds (symbol_check).
bool cholesky3(const Mat3& a, Mat3* l) {
  l->setZero();
  for (int j = 0; j < 3; ++j) {
    double d = a(j, j);
    for (int k = 0; k < j; ++k) d -= (*l)(j, k) * (*l)(j, k);
    if (!(d > 0.0)) return false;
    (*l)(j, j) = std::sqrt(d);
    for (int i = j + 1; i < 3; ++i) {
      double s = a(i, j);
      for (int k = 0; k < j; ++k) s -= (*l)(i, k) * (*l)(j, k);
      (*l)(i, j) = s / (*l)(j, j);
    }
  }
  return true;
}

}  // namespace

Status init_sampled_edge(std::uint32_t from, std::uint32_t to, const Se2d& mean, const Mat3& cov, Se2d* options,
                         double* option_cost, std::uint32_t count, RandomStream& rng, SampledEdge* edge) {
  if (count == 0 || options == nullptr || option_cost == nullptr) {
    return Status::error(Errc::kInvalidArgument, "edge %u->%u: no storage for its options", from, to);
  }
  if (!std::isfinite(mean.x) || !std::isfinite(mean.y) || !std::isfinite(mean.theta)) {
    return Status::error(Errc::kInvalidArgument, "edge %u->%u: non-finite mean", from, to);
  }
  if (!cov.allFinite() || (cov - cov.transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + cov.cwiseAbs().maxCoeff())) {
    return Status::error(Errc::kNumerical, "edge %u->%u: covariance not finite and symmetric", from, to);
  }
  Mat3 l;
  if (!cholesky3(cov, &l)) {
    return Status::error(Errc::kNumerical, "edge %u->%u: covariance not positive definite", from, to);
  }
  edge->from = from;
  edge->to = to;
  edge->mean = mean;
  edge->cov = cov;
  edge->predict_cov = cov;
  edge->info = cov.inverse();  // closed form for 3x3; positive definite checked above
  edge->value = mean;
  edge->frozen = false;
  edge->closure = false;
  edge->options = options;
  edge->option_cost = option_cost;
  edge->num_options = count;
  for (std::uint32_t k = 0; k < count; ++k) {
    Vec3 t(mean.x, mean.y, mean.theta);
    if (k > 0) {  // Eq. 3.10: a draw from N(μ_ij, Σ_ij)
      // One draw per statement: the order of a constructor's arguments is unspecified, and the
      // x86-64 GCC build drew z first while aarch64 and clang drew x first (different edges for one
      // seed). Kept z, y, x — the order every recorded figure was measured with.
      const double gz = rng.gaussian();
      const double gy = rng.gaussian();
      const double gx = rng.gaussian();
      const Vec3 z(gx, gy, gz);
      t += l * z;
    }
    options[k] = Se2d(t(0), t(1), wrap_angle(t(2)));
    option_cost[k] = mahalanobis2(options[k], mean, edge->info);
  }
  return Status::ok();
}

}  // namespace fw::antslam
