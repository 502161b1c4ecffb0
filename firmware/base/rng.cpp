#include "firmware/base/rng.h"

#include <cmath>

namespace fw {
namespace {
std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}
}  // namespace

double deterministic_log(double x) {
  // x = m · 2^e with m in [√½, √2); log m = 2·atanh(s), s = (m−1)/(m+1), |s| < 0.1716.
  int e = 0;
  double m = std::frexp(x, &e);  // m in [0.5, 1)
  if (m < 0.70710678118654752440) {
    m *= 2.0;
    --e;
  }
  const double s = (m - 1.0) / (m + 1.0);
  const double s2 = s * s;
  // Σ s^(2k+1)/(2k+1) for k ≤ 11: truncation < s^25/25 ≈ 3e-21.
  double term = s, sum = 0.0;
  for (int k = 0; k < 12; ++k) {
    sum += term / static_cast<double>(2 * k + 1);
    term *= s2;
  }
  return 2.0 * sum + static_cast<double>(e) * 0.69314718055994530942;
}

void RandomStream::reseed(std::uint64_t seed, std::uint64_t stream_index) {
  std::uint64_t sm = seed ^ (0xD1B54A32D192ED03ull * (stream_index + 1));
  const std::uint64_t init_state = splitmix64(sm);
  inc_ = (splitmix64(sm) << 1) | 1u;
  state_ = 0;
  next_u32();
  state_ += init_state;
  next_u32();
  has_spare_ = false;
}

double RandomStream::gaussian() {
  if (has_spare_) {
    has_spare_ = false;
    return spare_;
  }
  double u, v, s;
  do {
    u = 2.0 * uniform01() - 1.0;
    v = 2.0 * uniform01() - 1.0;
    s = u * u + v * v;
  } while (s >= 1.0 || s == 0.0);
  const double f = std::sqrt(-2.0 * deterministic_log(s) / s);
  spare_ = v * f;
  has_spare_ = true;
  return u * f;
}

}  // namespace fw
