// SE(2) poses (x, y, θ) on Eigen fixed-size types, with the compounding operators of Smith, Self
// and Cheeseman used throughout the dissertation: ⊕ (compose), ⊖ (inverse) and their Jacobians.
// These propagate covariances in AntSLAM's pose tracking (Eq. 3.4) and in MML's localization
// constraint (Eq. 5.8–5.13). Templated on the scalar so tests can check Jacobians in double.
#pragma once

#include <Eigen/Core>
#include <cmath>

namespace fw {

template <typename S>
S wrap_angle(S a) {
  constexpr S kPi = static_cast<S>(3.14159265358979323846);
  // Deterministic: remainder-based wrap into (-π, π].
  a = std::fmod(a + kPi, static_cast<S>(2) * kPi);
  if (a <= S(0)) a += static_cast<S>(2) * kPi;
  return a - kPi;
}

template <typename S>
struct Se2 {
  using Vec3 = Eigen::Matrix<S, 3, 1>;
  using Mat3 = Eigen::Matrix<S, 3, 3>;

  S x = 0, y = 0, theta = 0;

  Se2() = default;
  Se2(S x_, S y_, S theta_) : x(x_), y(y_), theta(theta_) {}
  static Se2 from_vector(const Vec3& v) { return Se2(v(0), v(1), v(2)); }
  Vec3 vector() const { return Vec3(x, y, theta); }

  // a ⊕ b: b expressed in a's frame, composed.
  Se2 compose(const Se2& b) const {
    const S c = std::cos(theta), s = std::sin(theta);
    return Se2(x + c * b.x - s * b.y, y + s * b.x + c * b.y, wrap_angle(theta + b.theta));
  }
  // ⊖a: the inverse transform.
  Se2 inverse() const {
    const S c = std::cos(theta), s = std::sin(theta);
    return Se2(-c * x - s * y, s * x - c * y, wrap_angle(-theta));
  }
  // (⊖a) ⊕ b: b relative to a (Eq. 5.11 uses it with a = x_e, b = x_h).
  Se2 between(const Se2& b) const { return inverse().compose(b); }

  Eigen::Matrix<S, 2, 1> transform_point(const Eigen::Matrix<S, 2, 1>& p) const {
    const S c = std::cos(theta), s = std::sin(theta);
    return Eigen::Matrix<S, 2, 1>(x + c * p(0) - s * p(1), y + s * p(0) + c * p(1));
  }

  // ∂(a⊕b)/∂a  (J_{⊕1}; J_x in Eq. 3.4 and J_xprev in Eq. 5.10)
  Mat3 jacobian_compose_first(const Se2& b) const {
    const S c = std::cos(theta), s = std::sin(theta);
    Mat3 j;
    j << S(1), S(0), -s * b.x - c * b.y,
         S(0), S(1),  c * b.x - s * b.y,
         S(0), S(0), S(1);
    return j;
  }
  // ∂(a⊕b)/∂b  (J_{⊕2}; J_u in Eq. 3.4, J_xr in Eq. 5.10, J_⊕ in Eq. 5.13)
  Mat3 jacobian_compose_second() const {
    const S c = std::cos(theta), s = std::sin(theta);
    Mat3 j;
    j << c, -s, S(0),
         s,  c, S(0),
         S(0), S(0), S(1);
    return j;
  }
  // ∂(⊖a)/∂a
  Mat3 jacobian_inverse() const {
    const S c = std::cos(theta), s = std::sin(theta);
    Mat3 j;
    j << -c, -s,  s * x - c * y,
          s, -c,  c * x + s * y,
         S(0), S(0), S(-1);
    return j;
  }
  // ∂((⊖a)⊕b)/∂a — J_⊖ of Eq. 5.13 (chain rule through ⊖ then ⊕).
  Mat3 jacobian_between_first(const Se2& b) const {
    const Se2 ia = inverse();
    return ia.jacobian_compose_first(b) * jacobian_inverse();
  }
  // ∂((⊖a)⊕b)/∂b — J_⊕ of Eq. 5.13.
  Mat3 jacobian_between_second() const { return inverse().jacobian_compose_second(); }

  template <typename T>
  Se2<T> cast() const { return Se2<T>(static_cast<T>(x), static_cast<T>(y), static_cast<T>(theta)); }
};

using Se2f = Se2<float>;
using Se2d = Se2<double>;

// A pose with its 3×3 covariance.
template <typename S>
struct PoseWithCovariance {
  Se2<S> pose;
  Eigen::Matrix<S, 3, 3> cov = Eigen::Matrix<S, 3, 3>::Zero();
};

// First-order propagation of two independent pose covariances through a pose function f(a, b):
// Σ = J_a Σ_a J_aᵀ + J_b Σ_b J_bᵀ (the shape of Eq. 3.4 and Eq. 5.13).
template <typename S, typename JA, typename JB, typename C>
PoseWithCovariance<S> propagate(const Se2<S>& pose, const JA& ja, const C& cov_a, const JB& jb, const C& cov_b) {
  PoseWithCovariance<S> out;
  out.pose = pose;
  out.cov = ja * cov_a * ja.transpose() + jb * cov_b * jb.transpose();
  return out;
}

// x_t = x_{t-1} ⊕ u_t with Σ_t = J_x Σ_{t-1} J_xᵀ + J_u G J_uᵀ  (Eq. 3.4; also Eq. 5.8–5.9).
template <typename S>
PoseWithCovariance<S> compose_with_covariance(const PoseWithCovariance<S>& a, const PoseWithCovariance<S>& u) {
  return propagate(a.pose.compose(u.pose), a.pose.jacobian_compose_first(u.pose), a.cov,
                   a.pose.jacobian_compose_second(), u.cov);
}

// r_h = (⊖x_e) ⊕ x_h with R_h = J_⊖ P_e J_⊖ᵀ + J_⊕ P_h J_⊕ᵀ  (Eq. 5.11–5.13).
template <typename S>
PoseWithCovariance<S> between_with_covariance(const PoseWithCovariance<S>& e, const PoseWithCovariance<S>& h) {
  return propagate(e.pose.between(h.pose), e.pose.jacobian_between_first(h.pose), e.cov,
                   e.pose.jacobian_between_second(), h.cov);
}

}  // namespace fw
