#include "firmware/runtime/odometry_interpolation.h"

#include <cmath>

namespace fw {

namespace {
// Below this rotation the series expansions are used (sin θ/θ and (1−cos θ)/θ lose precision).
constexpr double kSmallAngle = 1e-6;

// V(θ) maps the translational twist to the chord of the arc:  t = V(θ)·u.
void v_coefficients(double theta, double* a, double* b) {
  if (std::fabs(theta) < kSmallAngle) {
    *a = 1.0 - theta * theta / 6.0;  // sin θ / θ
    *b = theta / 2.0;                // (1 − cos θ) / θ
  } else {
    *a = std::sin(theta) / theta;
    *b = (1.0 - std::cos(theta)) / theta;
  }
}
}  // namespace

Se2d se2_log(const Se2d& delta) {
  const double theta = delta.theta;
  double a, b;
  v_coefficients(theta, &a, &b);
  // V = [a −b; b a]  ⇒  V⁻¹ = [a b; −b a] / (a² + b²)
  const double det = a * a + b * b;
  return Se2d((a * delta.x + b * delta.y) / det, (-b * delta.x + a * delta.y) / det, theta);
}

Se2d se2_exp(const Se2d& twist) {
  double a, b;
  v_coefficients(twist.theta, &a, &b);
  return Se2d(a * twist.x - b * twist.y, b * twist.x + a * twist.y, wrap_angle(twist.theta));
}

Se2d interpolate_se2(const Se2d& a, const Se2d& b, double s) {
  const Se2d twist = se2_log(a.between(b));
  return a.compose(se2_exp(Se2d(twist.x * s, twist.y * s, twist.theta * s)));
}

bool odometry_is_finite(const hal::Odometry& o) {
  return std::isfinite(o.x) && std::isfinite(o.y) && std::isfinite(o.theta) && std::isfinite(o.v) &&
         std::isfinite(o.omega);
}

Status interpolate_odometry(const hal::Odometry& a, const hal::Odometry& b, std::uint64_t t_ns, hal::Odometry* out) {
  if (a.timestamp_ns > b.timestamp_ns || t_ns < a.timestamp_ns || t_ns > b.timestamp_ns) {
    return Status::error(Errc::kOutOfRange, "odometry interpolation: t=%llu ns not within [%llu, %llu] ns",
                         static_cast<unsigned long long>(t_ns), static_cast<unsigned long long>(a.timestamp_ns),
                         static_cast<unsigned long long>(b.timestamp_ns));
  }
  const std::uint64_t span = b.timestamp_ns - a.timestamp_ns;
  if (span == 0) {
    *out = b;
    out->timestamp_ns = t_ns;
    return Status::ok();
  }
  const double s = static_cast<double>(t_ns - a.timestamp_ns) / static_cast<double>(span);
  const Se2d pa(a.x, a.y, a.theta), pb(b.x, b.y, b.theta);
  const Se2d p = interpolate_se2(pa, pb, s);
  out->timestamp_ns = t_ns;
  out->x = static_cast<float>(p.x);
  out->y = static_cast<float>(p.y);
  out->theta = static_cast<float>(p.theta);
  out->v = static_cast<float>(a.v + (b.v - a.v) * s);
  out->omega = static_cast<float>(a.omega + (b.omega - a.omega) * s);
  return Status::ok();
}

}  // namespace fw
