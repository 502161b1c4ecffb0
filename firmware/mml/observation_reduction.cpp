#include "firmware/mml/observation_reduction.h"

#include <cmath>

namespace fw {
namespace mml {

float ReductionRule::delta(std::uint32_t clusters) const {
  if (clusters >= clusters_max_) return delta_max_;
  const float r = static_cast<float>(clusters) / static_cast<float>(clusters_max_);
  return std::floor(delta0_ + (delta_max_ - delta0_) * r);
}

bool ReductionRule::push(std::uint32_t clusters) {
  f_[2] = f_[1];
  f_[1] = f_[0];
  f_[0] = clusters;
  if (n_ < 4) ++n_;
  d2_prev_ = d2_;
  d2_ = n_ >= 3 ? static_cast<float>(f_[0] - 2 * f_[1] + f_[2]) : 0.0f;
  if (n_ < 4) return false;  // f''(t−1) needs f(t−3)
  return f_[1] >= 1 && d2_prev_ < 0.0f && d2_ > 0.0f && d2_ - d2_prev_ > delta(clusters);
}

}  // namespace mml
}  // namespace fw
