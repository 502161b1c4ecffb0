// Rating of a hypothesis (Eq. 4.7, with the early stop of Eq. 4.8) on the contact field; while the
// unmapped-space hypothesis is active (matcher.h), a point in unmapped space counts as contact.
#include "firmware/pransam/matcher.h"

#include <cmath>

namespace fw::pransam {

namespace {
// Contact value → contribution to Ω: hard (Eq. 4.31) counts only 255, fuzzy (Eq. 4.33) is linear.
struct ContactLut {
  float hard[256];
  float fuzzy[256];
  ContactLut() {
    for (int c = 0; c < 256; ++c) {
      hard[c] = c == 255 ? 1.0f : 0.0f;
      fuzzy[c] = c == 255 ? 1.0f : static_cast<float>(c) / 255.0f;
    }
  }
};
const ContactLut kLut;

}  // namespace

template <int D>
float Matcher<D>::rate(const Hypothesis<D>& h, float bound, std::uint32_t start, bool* complete,
                       std::uint64_t* checks) const {
  const float* lut = params_.fuzzy ? kLut.fuzzy : kLut.hard;
  const std::uint32_t n = scene_n_;
  const std::uint32_t kmin = params_.min_extrapolation_points;
  const bool extrapolate = params_.extrapolate && bound > 0.0f;
  float sum = 0.0f;
  std::uint32_t k = 0;
  std::uint32_t idx = start;
  for (; k < n;) {
    const Point<D> p = h.rotation * scene_[scene_order_[idx]] + h.translation;
    std::uint8_t c = field_.contact(p);
    if (unmapped_active_ && c != 255 && unmapped_fn_(unmapped_ctx_, p)) c = 255;
    sum += lut[c];
    ++k;
    if (++idx == n) idx = 0;
    // Eq. 4.8: Ω⁺(k) = mean + 1.96 / (2√k); give up once it cannot beat the bound.
    if (extrapolate && (k & 7u) == 0 && k >= kmin && k < n) {
      const float kf = static_cast<float>(k);
      if (sum / kf + 0.98f / std::sqrt(kf) < bound) {
        *checks += k;
        *complete = false;
        return sum / kf;
      }
    }
  }
  *checks += n;
  *complete = true;
  return sum / static_cast<float>(n);
}

template float Matcher<2>::rate(const Hypothesis<2>& h, float bound, std::uint32_t start, bool* complete, std::uint64_t* checks) const;
template float Matcher<3>::rate(const Hypothesis<3>& h, float bound, std::uint32_t start, bool* complete, std::uint64_t* checks) const;

}  // namespace fw::pransam
