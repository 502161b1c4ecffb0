// Point-to-line Gauss–Newton normal equations for a 2-D rigid alignment: the one solver shared by
// RBSM's final refinement (scan → local end-point map, issue 15), the PL-ICP baseline (scan → last
// key scan, Censi 2008), the tracker's distance-field alignment (scan → global map,
// firmware/track/scan_alignment.cpp) and MML's published-pose refinement (firmware/mml/pose_refiner.cpp).
// Not here, on purpose: pRANSAM's refinement (D-dimensional, 2-D and 3-D frames) and the local-map
// correction (gradient descent of Eq. 5.27 on the truncated cost, as the dissertation). All three minimise Σ w_i r_i² with a residual that is, to
// first order, the distance of the transformed sensor point q_i = R(θ) p_i + t from a line through
// c_i with unit normal n_i:  r_i = n_iᵀ(q_i − c_i)  (on a distance field: r = d(q), n = ∇d).
// Its Jacobian with respect to (x, y, θ) is J_i = (n_x, n_y, n_ᵀ ∂q/∂θ), ∂q/∂θ = (−s p_x − c p_y,
// c p_x − s p_y) — the point Jacobian J_x of Eq. 2.14 projected on the normal.
// Accumulated in double (a few hundred terms of mixed magnitude), solved by LDLT with an optional
// Levenberg pull towards a prior pose for the directions a scan does not constrain (a corridor's
// axis). Header-only, no allocation; the callers own correspondence search, gating and weights.
#pragma once

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdint>

namespace fw {

struct PointToLineSystem {
  // Σ w J Jᵀ (row-major), Σ w r J and Σ w r² as plain doubles: in the callers' per-point loops the
  // compiler keeps them in registers (Eigen members were re-loaded and stored at every term, the
  // largest single cost of the tracker's alias check). Each term is summed exactly as
  // `h += w * (j * jᵀ)` summed it: (w·j_a)·j_e. Only the lower triangle (e ≤ a) is summed —
  // the only part LDLT and the self-adjoint eigensolver read — and information() mirrors it.
  double h[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  double b[3] = {0, 0, 0};
  double cost = 0.0;
  std::uint32_t used = 0;

  void clear() { *this = PointToLineSystem(); }

  // One term: sensor point (px, py), current rotation (c, s) = (cos θ, sin θ), normal (nx, ny)
  // (unit, or the distance-field gradient), residual r, weight w (IRLS weight of a robust loss).
  void add(float px, float py, float c, float s, float nx, float ny, float r, double w) {
    add_jacobian(nx, ny, nx * (-s * px - c * py) + ny * (c * px - s * py), r, w);
  }
  // The same term with the heading column jt = nᵀ ∂q/∂θ already computed (DistanceBatch::jt).
  void add_jacobian(float nx, float ny, float jt, float r, double w) {
    const double j[3] = {nx, ny, static_cast<double>(jt)};
    const double wj[3] = {w * j[0], w * j[1], w * j[2]};
    for (int a = 0; a < 3; ++a)
      for (int e = 0; e <= a; ++e) h[3 * a + e] += wj[a] * j[e];
    const double wr = w * static_cast<double>(r);
    for (int a = 0; a < 3; ++a) b[a] += wr * j[a];
    cost += wr * r;
    ++used;
  }

  Eigen::Matrix3d information() const {
    Eigen::Matrix3d m;
    m << h[0], h[3], h[6], h[3], h[4], h[7], h[6], h[7], h[8];
    return m;
  }
  Eigen::Vector3d gradient() const { return Eigen::Vector3d(b[0], b[1], b[2]); }

  // Gauss–Newton step dx = −(H + D + λI)⁻¹ (b + D·offset), D = diag(reg_xy, reg_xy, reg_th) and
  // `offset` = current pose − prior (θ wrapped by the caller), λ = damping·(1 + trace(H + D)) (a
  // Levenberg damping relative to the system's scale): with D = 0 and damping 0 a plain GN step.
  // False when the step is not finite (a degenerate system).
  bool solve(Eigen::Vector3d* dx, double reg_xy = 0.0, double reg_th = 0.0,
             const Eigen::Vector3d& offset = Eigen::Vector3d::Zero(), double damping = 0.0) const {
    Eigen::Matrix3d a = information();
    Eigen::Vector3d g = gradient();
    a(0, 0) += reg_xy;
    a(1, 1) += reg_xy;
    a(2, 2) += reg_th;
    g(0) += reg_xy * offset(0);
    g(1) += reg_xy * offset(1);
    g(2) += reg_th * offset(2);
    if (damping > 0.0) a.diagonal() += Eigen::Vector3d(damping, damping, damping) * (1.0 + a.trace());
    *dx = -a.ldlt().solve(g);
    return dx->allFinite();
  }

  // Gauss–Newton step restricted to the directions the terms constrain (degeneracy-aware, after
  // Zhang, Kaess & Singh, ICRA 2016): with θ scaled by `length_m` (a typical lever, so 1 rad and
  // length_m metres weigh alike), directions whose eigenvalue is below min_ratio × the largest are
  // left where they are — along a corridor's axis the walls say nothing, and a free GN step there
  // follows noise. False when degenerate in every direction or not finite.
  bool solve_constrained(Eigen::Vector3d* dx, double length_m, double min_ratio) const {
    const Eigen::Vector3d scale(1.0, 1.0, 1.0 / length_m);
    const Eigen::Matrix3d hs = scale.asDiagonal() * information() * scale.asDiagonal();
    const Eigen::Vector3d bs = scale.asDiagonal() * gradient();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(hs);
    if (es.info() != Eigen::Success) return false;
    const Eigen::Vector3d lambda = es.eigenvalues();  // ascending
    const double floor = min_ratio * lambda(2);
    if (!(lambda(2) > 0.0)) return false;
    Eigen::Vector3d step = Eigen::Vector3d::Zero();
    for (int k = 0; k < 3; ++k) {
      if (!(lambda(k) > floor)) continue;
      const Eigen::Vector3d v = es.eigenvectors().col(k);
      step -= v * (v.dot(bs) / lambda(k));
    }
    *dx = scale.asDiagonal() * step;
    return dx->allFinite();
  }
};

// Unit normal of the best-fitting line through a point scatter (second moments about the centroid
// sxx, sxy, syy): the eigenvector of the smaller eigenvalue of [[sxx, sxy], [sxy, syy]]. `*ratio`
// receives λmin/λmax (0 = a perfect line, 1 = an isotropic blob).
inline void line_normal_from_scatter(float sxx, float sxy, float syy, float* nx, float* ny, float* ratio) {
  const float tr = 0.5f * (sxx + syy);
  const float d = 0.5f * (sxx - syy);
  const float root = std::sqrt(d * d + sxy * sxy);
  const float lmax = tr + root, lmin = tr - root;
  // Principal (line) direction angle φ = ½ atan2(2 sxy, sxx − syy); the normal is φ + 90°.
  const float phi = 0.5f * std::atan2(2.0f * sxy, sxx - syy);
  *nx = -std::sin(phi);
  *ny = std::cos(phi);
  *ratio = lmax > 0.0f ? lmin / lmax : 1.0f;
}

}  // namespace fw
