// Local map correction (dissertation Sec. 5.4, Eq. 5.23–5.27, App. D): a fragment N of the local map
// is moved by a small rigid T(δx, δy, δφ) in its own frame so that its points, mapped into the
// global map by H_best ⊕ F_N ⊕ T(δ), lie on the map: minimise
//   e(δ) = 1/n Σ_j ρ(d(H_best · F_N · T(δ) · x_j))          (Eq. 5.26, mean instead of sum)
// by gradient descent δ ← δ − α ∇e (Eq. 5.27). Instead of the closest map point c_j from a kd-tree,
// ‖x^GM − c_j‖ is the global map's exact distance field d (bilinear), so ∇ of d² is 2·d·∇d with ∇d
// the interpolated field's gradient, chained with ∂p/∂δ of App. D (Eq. D.3). ρ truncates at
// clip: points farther from the map (unmapped objects, the unknown part of a fragment) do not pull.
// Step size: the thesis leaves α(j) open; here the rotational gradient is divided by the mean
// squared lever arm of the points (so α has the same meaning in metres for all three parameters)
// and α adapts (×2 after a step that lowered e, up to 0.5; halved and the step undone otherwise),
// so e never increases. Pure computation on the caller's points; never allocates.
#pragma once

#include <cstddef>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"

namespace fw {
namespace mml {

struct CorrectionParams {
  std::uint32_t iterations = 20;
  float step = 0.05f;             // α(0)
  float clip_m = 0.30f;
  float max_shift_m = 0.30f;      // result rejected beyond these
  float max_rotation_rad = 0.10f;
};

struct CorrectionResult {
  Se2f delta;                     // T(δ) to compose onto the fragment's frame (identity if rejected)
  double e_before = 0.0, e_after = 0.0;  // Eq. 5.26 (mean, m²) at δ = 0 and at the result
  std::uint32_t iterations = 0;   // gradient evaluations
  std::uint32_t inliers = 0;      // points within clip at the result
  bool applied = false;
};

// e(δ) of Eq. 5.26 and (optional) its gradient (App. D) for points `pts` (fragment frame) mapped by
// `map_from_fragment` = H_best ⊕ F_N. delta = (δx, δy, δφ). Returns e; grad may be null.
double correction_error(const GlobalMap& map, const Se2f& map_from_fragment, const Point2f* pts, std::size_t n,
                        float clip_m, const double delta[3], double grad[3], std::uint32_t* inliers);

// Gradient descent of Eq. 5.27 from δ = 0.
CorrectionResult correct_fragment(const GlobalMap& map, const Se2f& map_from_fragment, const Point2f* pts,
                                  std::size_t n, const CorrectionParams& params);

}  // namespace mml
}  // namespace fw
