// RandomStream: one seeded generator object per consumer (no global RNG). Streams are derived
// from (seed, stream index) with SplitMix64, the generator is PCG32 (O'Neill 2014), and all draws
// use only IEEE-exact operations (+ − × ÷ √ and our own polynomial log), so the same seed gives
// bit-identical draws on x86-64 and aarch64 (libm's log/sin/cos may differ across platforms, and
// GCC contracts a*b+c into FMA on aarch64 unless -ffp-contract=off, which toolchain/ sets) — as
// long as a caller never takes two draws in one expression, whose order C++ leaves to the compiler
// (`Vec3(r.gaussian(), r.gaussian(), r.gaussian())` fills x from the third draw with x86-64 GCC and
// from the first with aarch64 GCC; scripts/check_draw_order.py reports such expressions).
// Hand-written instead of <random>: std::normal_distribution's algorithm is unspecified and
// differs between standard libraries.
#pragma once

#include <cstdint>

namespace fw {

// log(x) for x > 0 from frexp and an atanh series: deterministic across platforms (|err| < 2e-16 rel).
double deterministic_log(double x);

class RandomStream {
 public:
  RandomStream() : RandomStream(0, 0) {}
  RandomStream(std::uint64_t seed, std::uint64_t stream_index) { reseed(seed, stream_index); }
  void reseed(std::uint64_t seed, std::uint64_t stream_index);

  // Inline, as the draws below: pRANSAM takes three uniform_index draws per triple, ~50 million at
  // the start-up fill of a corpus map's relation table, where the calls cost ~13 % of the draws.
  std::uint32_t next_u32() {
    const std::uint64_t old = state_;
    state_ = old * 6364136223846793005ull + inc_;
    const std::uint32_t xorshifted = static_cast<std::uint32_t>(((old >> 18u) ^ old) >> 27u);
    const std::uint32_t rot = static_cast<std::uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((32u - rot) & 31u));
  }
  // Uniform integer in [0, n) without modulo bias (Lemire); n > 0.
  std::uint32_t uniform_index(std::uint32_t n) {
    std::uint64_t m = static_cast<std::uint64_t>(next_u32()) * n;
    std::uint32_t l = static_cast<std::uint32_t>(m);
    if (l < n) {
      const std::uint32_t t = (0u - n) % n;
      while (l < t) {
        m = static_cast<std::uint64_t>(next_u32()) * n;
        l = static_cast<std::uint32_t>(m);
      }
    }
    return static_cast<std::uint32_t>(m >> 32);
  }
  // Uniform in [0, 1).
  float uniform01f() { return static_cast<float>(next_u32() >> 8) * (1.0f / 16777216.0f); }
  double uniform01() {
    const std::uint64_t hi = next_u32() >> 5, lo = next_u32() >> 6;  // 53 bits
    return (static_cast<double>(hi) * 67108864.0 + static_cast<double>(lo)) * (1.0 / 9007199254740992.0);
  }
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform01f(); }
  // Standard normal (Marsaglia polar method; the spare value is cached).
  double gaussian();
  float gaussianf(float mean, float sigma) { return mean + sigma * static_cast<float>(gaussian()); }

 private:
  std::uint64_t state_ = 0;
  std::uint64_t inc_ = 1;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace fw
