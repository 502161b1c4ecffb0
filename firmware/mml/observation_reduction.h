// Local map reduction rule (dissertation Sec. 5.5.1, Eq. 5.28–5.30). f(t) = number of clusters at
// step t; with the discrete derivatives
//   f'(t) = f(t) − f(t−1),   f''(t) = f(t) − 2 f(t−1) + f(t−2)                       (Eq. 5.28)
// an observation is accepted when f'' crosses zero from − to + with a jump larger than Δ(|C(t)|):
//   f''(t−1) < 0  ∧  f''(t) > 0  ∧  f''(t) − f''(t−1) > Δ(|C(t)|)                     (Eq. 5.29)
//   Δ(c) = Δ_max if c ≥ |C|_max, else ⌊Δ_0 + (Δ_max − Δ_0)·c/|C|_max⌋ with Δ_0 = 2     (Eq. 5.30)
// (the text prints the jump with the sign lost; − and + of a crossing make it |f''(t)| + |f''(t−1)|).
// Which observation: the crossing between t−1 and t marks the collapse of f at t−1 (Fig. 5.5: the
// crossing between t = 5 and t = 6 keeps the observation of t = 5), so push(f(t)) accepts the
// observation of step t−1. The caller keeps the first observations (t = 0) unconditionally.
// Extension: the accepted observation must have left at least one cluster (f(t−1) ≥ 1). On real
// logs f(t) flickers between 0 and 2 once the pose is unique (a step without any hypothesis above
// the threshold), and 1, 1, 0, 1 would pass Eq. 5.29 (jump 3 > Δ(1) = 2): a match that produced
// nothing is a failed match, not an information-rich observation.
#pragma once

#include <cstdint>

#include "firmware/mml/mml_options.h"

namespace fw {
namespace mml {

class ReductionRule {
 public:
  explicit ReductionRule(const MmlOptions& o)
      : delta0_(o.reduction_min_jump), delta_max_(o.reduction_delta_max), clusters_max_(o.reduction_clusters_max) {}
  ReductionRule(float delta0, float delta_max, std::uint32_t clusters_max)
      : delta0_(delta0), delta_max_(delta_max), clusters_max_(clusters_max) {}

  void reset() { n_ = 0; }
  // Eq. 5.30.
  float delta(std::uint32_t clusters) const;
  // Feeds f(t) = `clusters`; true when the observation of step t−1 is accepted (Eq. 5.29).
  bool push(std::uint32_t clusters);
  // f''(t) of the last push (0 before three values).
  float second_difference() const { return d2_; }

 private:
  float delta0_, delta_max_;
  std::uint32_t clusters_max_;
  std::int64_t f_[3] = {0, 0, 0};  // f(t), f(t−1), f(t−2)
  std::uint32_t n_ = 0;            // values seen (saturates at 4)
  float d2_ = 0.0f, d2_prev_ = 0.0f;
};

}  // namespace mml
}  // namespace fw
