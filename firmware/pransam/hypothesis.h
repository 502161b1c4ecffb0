// Triangle frames and pose hypotheses (Sec. 4.3, Fig. 4.2, Eq. 4.5/4.9), shared by 2-D and 3-D.
// Frame of a canonically ordered triangle (p0 opposite the shortest side): origin = centroid,
// x toward the midpoint of the shortest side, z = plane normal, y = z × x.
// Hypothesis H = T_B · T_A⁻¹ maps A's points into B.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>
#include <cstdint>

#include "firmware/base/se2.h"
#include "firmware/pransam/relation_table.h"

namespace fw::pransam {

template <int D>
struct TriangleFrame {
  Eigen::Matrix<float, D, D> rotation;
  Point<D> origin;
  int orientation = 1;  // 2-D: sign of the normal (+1 = z up); 3-D: always +1
};

// False when the frame is undefined (degenerate triangle, NaN).
template <int D>
bool triangle_frame(const Point<D>& p0, const Point<D>& p1, const Point<D>& p2, TriangleFrame<D>* f) {
  const Point<D> c = (p0 + p1 + p2) * (1.0f / 3.0f);
  const Point<D> m = (p1 + p2) * 0.5f;  // midpoint of the shortest side (canonical order)
  Point<D> x = m - c;
  const float xn = x.norm();
  if (!(xn > 1e-9f)) return false;
  x /= xn;
  if constexpr (D == 2) {
    const Point<D> e1 = p1 - p0, e2 = p2 - p0;
    const float cross = e1(0) * e2(1) - e1(1) * e2(0);
    if (!(cross != 0.0f)) return false;
    f->orientation = cross > 0.0f ? 1 : -1;
    // y = z × x with z = ±e_z.
    const Point<D> y(-x(1) * static_cast<float>(f->orientation), x(0) * static_cast<float>(f->orientation));
    f->rotation.col(0) = x;
    f->rotation.col(1) = y;
  } else {
    Point<D> z = (p1 - p0).cross(p2 - p0);
    const float zn = z.norm();
    if (!(zn > 1e-12f)) return false;
    z /= zn;
    const Point<D> y = z.cross(x);
    f->rotation.col(0) = x;
    f->rotation.col(1) = y;
    f->rotation.col(2) = z;
    f->orientation = 1;
  }
  f->origin = c;
  return true;
}

template <int D>
struct Hypothesis {
  Eigen::Matrix<float, D, D> rotation = Eigen::Matrix<float, D, D>::Identity();
  Point<D> translation = Point<D>::Zero();
  float quality = 0.0f;          // Ω (Eq. 4.7), exact (all points of A evaluated)
  std::uint32_t iteration = 0;   // global iteration index at which the collision happened
  std::uint16_t worker = 0;      // logical worker that found it

  Point<D> apply(const Point<D>& p) const { return rotation * p + translation; }
};

// H = T_B · T_A⁻¹ (Eq. 4.9). In 2-D a frame pair with opposite orientations is a reflection, which
// a rigid 2-D motion cannot produce (the robot "below the map", Eq. 5.3): rejected (false).
template <int D>
bool make_hypothesis(const TriangleFrame<D>& a, const TriangleFrame<D>& b, Hypothesis<D>* h) {
  if (a.orientation != b.orientation) return false;
  h->rotation = b.rotation * a.rotation.transpose();
  h->translation = b.origin - h->rotation * a.origin;
  return true;
}

// 2-D hypothesis as (x, y, θ).
inline Se2f to_se2(const Hypothesis<2>& h) {
  return Se2f(h.translation(0), h.translation(1), std::atan2(h.rotation(1, 0), h.rotation(0, 0)));
}

// Roll-pitch-yaw of a rotation R = Rz(yaw)·Ry(pitch)·Rx(roll) (App. B), radians.
inline Eigen::Matrix<float, 3, 1> rpy(const Eigen::Matrix<float, 3, 3>& r) {
  const float pitch = std::atan2(-r(2, 0), std::sqrt(r(0, 0) * r(0, 0) + r(1, 0) * r(1, 0)));
  const float roll = std::atan2(r(2, 1), r(2, 2));
  const float yaw = std::atan2(r(1, 0), r(0, 0));
  return Eigen::Matrix<float, 3, 1>(roll, pitch, yaw);
}

}  // namespace fw::pransam
