#include "firmware/antslam/closure_pairs.h"

namespace fw::antslam {

double pair_cycle_chi2(const ClosureCandidate& p, const ClosureCandidate& q, const Se2d& cc, const Mat3& cov_cc,
                       const Se2d& aa, const Mat3& cov_aa) {
  // Through the closures: F_a' in F_a = h_a⁻¹ ⊕ T(c → c') ⊕ h_a'.
  const Mat3 ji = p.h.jacobian_inverse();
  Se2d x = p.h.inverse();
  Mat3 cov = ji * p.cov_h * ji.transpose();
  Mat3 j1 = x.jacobian_compose_first(cc), j2 = x.jacobian_compose_second();
  cov = j1 * cov * j1.transpose() + j2 * cov_cc * j2.transpose();
  x = x.compose(cc);
  j1 = x.jacobian_compose_first(q.h);
  j2 = x.jacobian_compose_second();
  cov = j1 * cov * j1.transpose() + j2 * q.cov_h * j2.transpose();
  x = x.compose(q.h);
  // Against the chain a → a' (independent measurements: the covariances add).
  const Vec3 d = se2_difference(x, aa);
  const Mat3 s = cov + cov_aa;
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
