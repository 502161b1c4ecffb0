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
  // Eq. 4.8's test runs after every kBlock-th point, so the points between two tests are looked up
  // first and summed after, in the same order (the same sum, bit for bit): the look-ups of a block
  // wait neither on each other nor on a branch on a byte read, so their cache misses overlap. On a
  // map larger than the cache (aces: 1.4 MB of contact bytes) the byte's load was half of rate's time.
  constexpr std::uint32_t kBlock = 8;
  static_assert(kBlock == 8, "a block ends where Eq. 4.8 is tested (k & 7 == 0)");
  while (k < n) {
    const std::uint32_t len = n - k < kBlock ? n - k : kBlock;
    Point<D> p[kBlock];
    std::uint8_t c[kBlock];
    for (std::uint32_t j = 0; j < len; ++j) {
      p[j] = h.rotation * scene_[scene_order_[idx]] + h.translation;
      c[j] = field_.contact(p[j]);
      if (++idx == n) idx = 0;
    }
    for (std::uint32_t j = 0; j < len; ++j) {
      std::uint8_t cj = c[j];
      if (unmapped_active_ && cj != 255 && unmapped_fn_(unmapped_ctx_, p[j])) cj = 255;
      sum += lut[cj];
    }
    k += len;
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
