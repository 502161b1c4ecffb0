// Test helpers shared by the increment fusion and smoother tests: a synthetic tour with RBSM-like
// absolute poses and PL-ICP-like increments, and the two error figures the README reports.
#pragma once

#include <cmath>
#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

#include "firmware/base/rng.h"
#include "firmware/rbsm/increment_fusion.h"

namespace fw {
namespace testing {

// A tour: drive 0.1 m per scan, turn in place, stand still, drive again (600 scans).
inline std::vector<Se2d> truth_tour() {
  std::vector<Se2d> t{Se2d(0, 0, 0)};
  for (int i = 1; i < 600; ++i) {
    Se2d u(0.1, 0.0, 0.0);
    if (i % 150 >= 100 && i % 150 < 120) u = Se2d(0.0, 0.0, 0.08);  // in-place turn
    if (i % 150 >= 120 && i % 150 < 135) u = Se2d(0.0, 0.0, 0.0);   // standing
    t.push_back(t.back().compose(u));
  }
  return t;
}

inline double dist(const Se2d& a, const Se2d& b) { return std::hypot(a.x - b.x, a.y - b.y); }

struct Tour {
  std::vector<Se2d> truth, absolute, relative;  // relative: the precise matcher's chained poses
};

// RBSM-like absolute poses: truth + N(0, 3 cm, 0.5°) per scan; PL-ICP-like increments: truth's +
// N(0, 2 mm + 1 % of the motion, 0.05° + 1 %) each, chained (so they drift).
inline Tour make_tour(std::uint64_t seed) {
  RandomStream rng;
  rng.reseed(seed, 7);
  Tour t;
  t.truth = truth_tour();
  t.relative.push_back(t.truth[0]);
  for (std::size_t i = 0; i < t.truth.size(); ++i) {
    // One draw per statement (argument order is unspecified): θ, y, x as x86-64 GCC drew them.
    const double at = 0.0087 * rng.gaussian(), ay = 0.03 * rng.gaussian(), ax = 0.03 * rng.gaussian();
    t.absolute.push_back(Se2d(t.truth[i].x + ax, t.truth[i].y + ay, wrap_angle(t.truth[i].theta + at)));
    if (i == 0) continue;
    const Se2d u = t.truth[i - 1].between(t.truth[i]);
    const double st = 0.002 + 0.01 * std::hypot(u.x, u.y), sr = 0.0009 + 0.01 * std::fabs(u.theta);
    const double rt = sr * rng.gaussian(), ry = st * rng.gaussian(), rx = st * rng.gaussian();
    t.relative.push_back(t.relative.back().compose(Se2d(u.x + rx, u.y + ry, u.theta + rt)));
  }
  return t;
}

inline std::vector<Se2d> fuse(const Tour& t, IncrementFusion* f) {
  std::vector<Se2d> out;
  for (std::size_t i = 0; i < t.truth.size(); ++i) {
    const Se2d u = i == 0 ? Se2d() : t.relative[i - 1].between(t.relative[i]);
    EXPECT_TRUE(f->update(t.absolute[i], i > 0, u).is_ok());
    out.push_back(f->pose());
  }
  return out;
}

// RMS of the error of the relative motion over `k` scans (the "short relations").
inline double short_error(const std::vector<Se2d>& est, const std::vector<Se2d>& truth, std::size_t k) {
  double s = 0;
  std::size_t n = 0;
  for (std::size_t i = 0; i + k < est.size(); ++i, ++n) {
    const Se2d e = est[i].between(est[i + k]), g = truth[i].between(truth[i + k]);
    s += (e.x - g.x) * (e.x - g.x) + (e.y - g.y) * (e.y - g.y);
  }
  return std::sqrt(s / static_cast<double>(n));
}

inline double rms_error(const std::vector<Se2d>& est, const std::vector<Se2d>& truth) {
  double s = 0;
  for (std::size_t i = 0; i < est.size(); ++i) s += dist(est[i], truth[i]) * dist(est[i], truth[i]);
  return std::sqrt(s / static_cast<double>(est.size()));
}

}  // namespace testing
}  // namespace fw
