#include "firmware/antslam/closure_pairs.h"

namespace fw::antslam {

double pair_cycle_chi2(const ClosureCandidate& p, const ClosureCandidate& q, const Se2d& cc, const Mat3& cov_cc,
                       const Se2d& aa, const Mat3& cov_aa) {
  // Through the closures: F_a' in F_a = h_a⁻¹ ⊕ T(c → c') ⊕ h_a' (Eq. 3.4 compounding).
  const Mat3 ji = p.h.jacobian_inverse();
  PoseWithCovariance<double> x{p.h.inverse(), ji * p.cov_h * ji.transpose()};
  x = compose_with_covariance(x, PoseWithCovariance<double>{cc, cov_cc});
  x = compose_with_covariance(x, PoseWithCovariance<double>{q.h, q.cov_h});
  // Against the chain a → a' (independent measurements: the covariances add).
  const Vec3 d = se2_difference(x.pose, aa);
  const Mat3 s = x.cov + cov_aa;
  return d.dot(s.inverse() * d);
}

void ClosureCandidateRing::expire(std::uint32_t a, std::uint32_t window) {
  std::uint32_t k = 0;
  for (std::uint32_t i = 0; i < size_; ++i) {
    if (items_[i].a + window >= a) items_[k++] = items_[i];
  }
  size_ = k;
}

void ClosureCandidateRing::push(const ClosureCandidate& c) {
  if (size_ == kCapacity) {
    for (std::uint32_t i = 1; i < kCapacity; ++i) items_[i - 1] = items_[i];
    --size_;
  }
  items_[size_++] = c;
}

}  // namespace fw::antslam
