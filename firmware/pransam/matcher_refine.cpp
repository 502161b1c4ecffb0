// Gauss–Newton refinement of a hypothesis on the distance field (2-D and 3-D frames).
#include "firmware/pransam/matcher.h"

#include <Eigen/Cholesky>
#include <Eigen/Geometry>
#include <cmath>

namespace fw::pransam {

template <int D>
void Matcher<D>::refine(Hypothesis<D>* h) const {
  // Gauss–Newton on Σ d(R·a_i + t)² over points within the cutoff (a truncated least squares).
  constexpr int kP = D == 2 ? 3 : 6;
  using MatP = Eigen::Matrix<float, kP, kP>;
  using VecP = Eigen::Matrix<float, kP, 1>;
  const float cutoff = params_.refine_cutoff;
  const std::uint32_t cap = params_.refine_max_points;
  const std::uint32_t stride = cap > 0 && scene_n_ > cap ? (scene_n_ + cap - 1) / cap : 1;
  for (std::uint32_t it = 0; it < params_.refine_iterations; ++it) {
    MatP hess = MatP::Zero();
    VecP grad = VecP::Zero();
    int used = 0;
    for (std::uint32_t i = 0; i < scene_n_; i += stride) {
      const Point<D> q = h->rotation * scene_[i];
      const Point<D> p = q + h->translation;
      float d;
      Point<D> g;
      const bool known = refine_fn_ != nullptr ? refine_fn_(refine_ctx_, p, &d, &g) : field_.distance_gradient(p, &d, &g);
      if (!known || d > cutoff) continue;
      VecP j;
      if constexpr (D == 2) {
        // Update R ← r(δθ)·R, t ← t + δt, so ∂p/∂δθ = perp(R·a).
        j << g(0), g(1), g(0) * -q(1) + g(1) * q(0);
      } else {
        // Left-multiplied small rotation ω: ∂p/∂ω = −[q]×.
        const Point<D> c = q.cross(g);  // gᵀ(ω × q) = ω · (q × g)
        j << g(0), g(1), g(2), c(0), c(1), c(2);
      }
      hess.noalias() += j * j.transpose();
      grad.noalias() += j * d;
      ++used;
    }
    if (used < kP + 3) return;
    for (int k = 0; k < kP; ++k) hess(k, k) += 1e-3f + 1e-3f * hess(k, k);  // Levenberg damping
    const VecP step = -hess.ldlt().solve(grad);
    if (!step.allFinite()) return;
    if constexpr (D == 2) {
      const float c = std::cos(step(2)), s = std::sin(step(2));
      Eigen::Matrix<float, 2, 2> r;
      r << c, -s, s, c;
      h->rotation = r * h->rotation;
      h->translation += Point<D>(step(0), step(1));
    } else {
      const Point<D> w(step(3), step(4), step(5));
      const float angle = w.norm();
      Eigen::Matrix<float, 3, 3> r = Eigen::Matrix<float, 3, 3>::Identity();
      if (angle > 1e-9f) r = Eigen::AngleAxisf(angle, w / angle).toRotationMatrix();
      h->rotation = r * h->rotation;
      h->translation += Point<D>(step(0), step(1), step(2));
    }
    if (step.squaredNorm() < 1e-10f) return;
  }
}

template void Matcher<2>::refine(Hypothesis<2>* h) const;
template void Matcher<3>::refine(Hypothesis<3>* h) const;

}  // namespace fw::pransam
