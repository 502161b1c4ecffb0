#include "firmware/mml/local_map_correction.h"

#include <cmath>

#include "firmware/map/distance_sample.h"

namespace fw {
namespace mml {

double correction_error(const GlobalMap& map, const Se2f& a, const Point2f* pts, std::size_t n, float clip_m,
                        const double delta[3], double grad[3], std::uint32_t* inliers) {
  // p(δ) = R(β)·(R(δφ)·x + (δx, δy)) + t, β = angle of H_best ⊕ F_N (App. D, Eq. D.1).
  const double cb = std::cos(static_cast<double>(a.theta)), sb = std::sin(static_cast<double>(a.theta));
  const double cd = std::cos(delta[2]), sd = std::sin(delta[2]);
  const double clip = clip_m, clip2 = clip * clip;
  double e = 0.0, g0 = 0.0, g1 = 0.0, g2 = 0.0;
  std::uint32_t inl = 0;
  for (std::size_t j = 0; j < n; ++j) {
    const double xl = pts[j].x(), yl = pts[j].y();
    const double ux = cd * xl - sd * yl + delta[0], uy = sd * xl + cd * yl + delta[1];
    const double px = a.x + cb * ux - sb * uy, py = a.y + sb * ux + cb * uy;
    double d = 0.0, gx = 0.0, gy = 0.0;
    if (!sample_distance<double>(map, px, py, &d, &gx, &gy) || d >= clip) {
      e += clip2;  // truncated: constant, no pull
      continue;
    }
    ++inl;
    e += d * d;
    // ∂p/∂δ (Eq. D.3): ∂p/∂δx = (cβ, sβ), ∂p/∂δy = (−sβ, cβ),
    // ∂p/∂δφ = (y(sβ sδφ − cβ cδφ) − x(cβ sδφ + sβ cδφ), x(cβ cδφ − sβ sδφ) − y(sβ cδφ + cβ sδφ)).
    const double dpx_dphi = yl * (sb * sd - cb * cd) - xl * (cb * sd + sb * cd);
    const double dpy_dphi = xl * (cb * cd - sb * sd) - yl * (sb * cd + cb * sd);
    // ∇ of d² = 2·d·∇d (Eq. D.2 with (p − c) replaced by d·∇d from the distance field).
    const double w = 2.0 * d;
    g0 += w * (gx * cb + gy * sb);
    g1 += w * (-gx * sb + gy * cb);
    g2 += w * (gx * dpx_dphi + gy * dpy_dphi);
  }
  if (inliers != nullptr) *inliers = inl;
  const double inv = n > 0 ? 1.0 / static_cast<double>(n) : 0.0;
  if (grad != nullptr) {
    grad[0] = g0 * inv;
    grad[1] = g1 * inv;
    grad[2] = g2 * inv;
  }
  return e * inv;
}

CorrectionResult correct_fragment(const GlobalMap& map, const Se2f& a, const Point2f* pts, std::size_t n,
                                  const CorrectionParams& p) {
  CorrectionResult r;
  if (!map.valid() || pts == nullptr || n == 0) return r;
  // Mean squared lever arm about the fragment origin (T(δ) rotates about it): scales the rotational
  // gradient so that one α moves all three parameters by comparable arc lengths.
  double lever2 = 0.0;
  for (std::size_t j = 0; j < n; ++j) lever2 += static_cast<double>(pts[j].squaredNorm());
  lever2 = lever2 / static_cast<double>(n) + 1e-2;
  double delta[3] = {0.0, 0.0, 0.0}, grad[3];
  double e = correction_error(map, a, pts, n, p.clip_m, delta, grad, &r.inliers);
  r.e_before = e;
  r.iterations = 1;
  double alpha = p.step;
  const double alpha_max = p.step > 0.5f ? p.step : 0.5;
  for (std::uint32_t it = 0; it < p.iterations; ++it) {
    // Eq. 5.27 with the diagonal scaling above.
    const double trial[3] = {delta[0] - alpha * grad[0], delta[1] - alpha * grad[1], delta[2] - alpha * grad[2] / lever2};
    double tgrad[3];
    std::uint32_t tin = 0;
    const double te = correction_error(map, a, pts, n, p.clip_m, trial, tgrad, &tin);
    ++r.iterations;
    if (te < e) {
      for (int k = 0; k < 3; ++k) {
        delta[k] = trial[k];
        grad[k] = tgrad[k];
      }
      e = te;
      r.inliers = tin;
      alpha = alpha * 2.0 < alpha_max ? alpha * 2.0 : alpha_max;
    } else {
      alpha *= 0.5;
      if (alpha < 1e-4 * p.step) break;  // converged (or a kink of the truncated cost)
    }
  }
  r.e_after = e;
  const bool bounded = std::hypot(delta[0], delta[1]) <= p.max_shift_m && std::fabs(delta[2]) <= p.max_rotation_rad;
  if (bounded && e < r.e_before) {
    r.delta = Se2f(static_cast<float>(delta[0]), static_cast<float>(delta[1]), static_cast<float>(delta[2]));
    r.applied = true;
  } else {
    r.e_after = r.e_before;
  }
  return r;
}

}  // namespace mml
}  // namespace fw
