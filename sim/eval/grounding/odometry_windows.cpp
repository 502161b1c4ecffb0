#include "sim/eval/grounding/odometry_windows.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sim::ground {

namespace {

constexpr double kDeg = 180.0 / M_PI;

// The window [s, e] of the pose pairs, measured.
OdometryWindow measure(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref, std::size_t s,
                       std::size_t e, double driven, const WindowOptions& opt) {
  OdometryWindow w;
  w.driven_m = driven;
  for (std::size_t i = s; i < e; ++i) {
    w.turn_ref += fw::wrap_angle(ref[i + 1].theta - ref[i].theta);
    w.turn_odom += fw::wrap_angle(odom[i + 1].theta - odom[i].theta);
  }
  const fw::Se2d d_o = odom[s].between(odom[e]);
  const fw::Se2d d_r = ref[s].between(ref[e]);
  w.chord_m = std::hypot(d_r.x, d_r.y);
  w.trans_err_per_m = std::hypot(d_o.x - d_r.x, d_o.y - d_r.y) / driven;
  const double dh = w.turn_odom - w.turn_ref;
  w.head_err_per_m = std::fabs(dh) / driven;
  w.straight = w.chord_m >= opt.straight_fraction * driven && w.chord_m > 0;
  if (w.straight) w.dist_scale = (std::hypot(d_o.x, d_o.y) - w.chord_m) / w.chord_m;
  w.turning = std::fabs(w.turn_ref) > opt.min_turn_rad;
  if (w.turning) {
    w.head_err_per_rad = std::fabs(dh) / std::fabs(w.turn_ref);
  }
  return w;
}

}  // namespace

std::vector<OdometryWindow> odometry_windows(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref,
                                             const WindowOptions& opt) {
  std::vector<OdometryWindow> out;
  const std::size_t n = std::min(odom.size(), ref.size());
  if (n < 2 || !(opt.window_m > 0)) return out;
  const double stride = opt.stride_m > 0 ? opt.stride_m : opt.window_m;
  // Cumulative reference path length at each instant.
  std::vector<double> cum(n, 0.0);
  for (std::size_t i = 1; i < n; ++i) cum[i] = cum[i - 1] + std::hypot(ref[i].x - ref[i - 1].x, ref[i].y - ref[i - 1].y);
  std::size_t s = 0;
  while (s + 1 < n) {
    std::size_t e = s + 1;
    while (e < n && cum[e] - cum[s] < opt.window_m) ++e;
    if (e >= n) break;
    const double driven = cum[e] - cum[s];
    if (driven <= opt.max_overshoot * opt.window_m) out.push_back(measure(odom, ref, s, e, driven, opt));
    // The next start: the first instant at least `stride` further on.
    std::size_t next = s + 1;
    while (next < n && cum[next] - cum[s] < stride) ++next;
    s = next;
  }
  return out;
}

double quantile(std::vector<double> v, double q) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double pos = std::clamp(q, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, v.size() - 1);
  const double f = pos - static_cast<double>(lo);
  if (!std::isfinite(v[hi]) || f == 0) return v[lo];
  return v[lo] + f * (v[hi] - v[lo]);
}

OdometryErrorSummary summarize(const std::vector<OdometryWindow>& w) {
  OdometryErrorSummary s;
  std::vector<double> trans, head, per_rad, dscale, tscale;
  for (const OdometryWindow& x : w) {
    ++s.windows;
    s.driven_m += x.driven_m;
    trans.push_back(x.trans_err_per_m);
    head.push_back(x.head_err_per_m * kDeg);
    if (x.straight) {
      ++s.straight_windows;
      dscale.push_back(x.dist_scale);
    }
    if (x.turning) {
      ++s.turning_windows;
      per_rad.push_back(x.head_err_per_rad);
      tscale.push_back((x.turn_odom - x.turn_ref) / x.turn_ref);
    }
  }
  s.trans_p50 = quantile(trans, 0.5);
  s.trans_p95 = quantile(trans, 0.95);
  s.trans_p10 = quantile(trans, 0.10);
  s.trans_p90 = quantile(trans, 0.90);
  s.head_deg_per_m_p50 = quantile(head, 0.5);
  s.head_deg_per_m_p95 = quantile(head, 0.95);
  s.head_deg_per_m_p10 = quantile(head, 0.10);
  s.head_deg_per_m_p90 = quantile(head, 0.90);
  s.head_per_rad_p50 = quantile(per_rad, 0.5);
  s.head_per_rad_p95 = quantile(per_rad, 0.95);
  s.dist_scale_median = quantile(dscale, 0.5);
  s.turn_scale_median = quantile(tscale, 0.5);
  return s;
}

}  // namespace sim::ground
