#include "firmware/antslam/fragment_borders.h"

#include <algorithm>
#include <cmath>

namespace fw::antslam {
namespace {

constexpr double kPi = 3.14159265358979323846;

double wrap(double a) {
  while (a > kPi) a -= 2.0 * kPi;
  while (a < -kPi) a += 2.0 * kPi;
  return a;
}

}  // namespace

Border Border::transformed(const Se2d& to_other) const {
  const Eigen::Vector2d a = to_other.transform_point(Eigen::Vector2d(x1, y1));
  const Eigen::Vector2d b = to_other.transform_point(Eigen::Vector2d(x2, y2));
  return Border{a.x(), a.y(), b.x(), b.y()};
}

double Border::length() const { return std::hypot(x2 - x1, y2 - y1); }

bool select_border(const Point2f* points, std::size_t n, const Se2d& robot, const BorderOptions& options,
                   Border* out) {
  // η1: 1 / the largest distance of a point to the robot; η2 = 1/π (Eq. 3.6).
  double dmax = 0.0;
  for (std::size_t j = 0; j < n; ++j) {
    const double d = std::hypot(points[j](0) - robot.x, points[j](1) - robot.y);
    if (std::isfinite(d)) dmax = std::max(dmax, d);
  }
  if (!(dmax > 0.0)) return false;
  const double eta1 = 1.0 / dmax, eta2 = 1.0 / kPi;
  const double alpha = options.alpha;
  double best[2] = {INFINITY, INFINITY};
  std::size_t arg[2] = {n, n};
  for (std::size_t j = 0; j < n; ++j) {
    const double dx = points[j](0) - robot.x, dy = points[j](1) - robot.y;
    const double d = std::hypot(dx, dy);
    if (!std::isfinite(d) || d <= 0.0) continue;
    const double bearing = std::atan2(dy, dx);
    for (int k = 0; k < 2; ++k) {
      // b1 to the left (Θ_r + π/2), b2 to the right (Θ_r − π/2).
      const double off = std::fabs(wrap(bearing - robot.theta - (k == 0 ? 0.5 * kPi : -0.5 * kPi)));
      if (off > options.max_angle_off_rad) continue;
      const double w = alpha * eta1 * d + (1.0 - alpha) * eta2 * off;  // Eq. 3.6
      if (w < best[k]) {  // Eq. 3.7: argmin
        best[k] = w;
        arg[k] = j;
      }
    }
  }
  if (arg[0] == n || arg[1] == n) return false;
  *out = Border{points[arg[0]](0), points[arg[0]](1), points[arg[1]](0), points[arg[1]](1)};
  return true;
}

// Graham scan: the lowest point (then leftmost) as pivot, the others sorted by polar angle about it
// (nearer first on ties), then one pass keeping left turns only.
std::size_t convex_hull(const Point2f* points, std::size_t n, Point2f* scratch, Point2f* hull,
                        std::size_t capacity) {
  std::size_t m = 0;
  for (std::size_t j = 0; j < n; ++j) {
    if (std::isfinite(points[j](0)) && std::isfinite(points[j](1))) scratch[m++] = points[j];
  }
  if (m < 3) return 0;
  std::size_t pivot = 0;
  for (std::size_t j = 1; j < m; ++j) {
    if (scratch[j](1) < scratch[pivot](1) || (scratch[j](1) == scratch[pivot](1) && scratch[j](0) < scratch[pivot](0))) {
      pivot = j;
    }
  }
  std::swap(scratch[0], scratch[pivot]);
  const Point2f p0 = scratch[0];
  std::sort(scratch + 1, scratch + m, [&p0](const Point2f& a, const Point2f& b) {
    const double h = signed_area(p0(0), p0(1), a(0), a(1), b(0), b(1));
    if (h != 0.0) return h > 0.0;  // a before b when b is left of p0 → a (smaller polar angle)
    return (a - p0).squaredNorm() < (b - p0).squaredNorm();
  });
  std::size_t top = 0;
  for (std::size_t j = 0; j < m; ++j) {
    while (top >= 2 && signed_area(hull[top - 2](0), hull[top - 2](1), hull[top - 1](0), hull[top - 1](1),
                                   scratch[j](0), scratch[j](1)) <= 0.0) {
      --top;
    }
    if (top >= capacity) return 0;
    hull[top++] = scratch[j];
  }
  return top >= 3 ? top : 0;
}

bool inside_convex_hull(const Point2f* hull, std::size_t m, double x, double y) {
  if (m < 3) return false;
  for (std::size_t i = 0; i < m; ++i) {
    const Point2f& a = hull[i];
    const Point2f& b = hull[(i + 1) % m];
    if (signed_area(a(0), a(1), b(0), b(1), x, y) < 0.0) return false;  // right of a CCW edge: outside
  }
  return true;
}

bool right_of_borders(const Border* borders, std::size_t count, double x, double y) {
  for (std::size_t i = 0; i < count; ++i) {
    const Border& b = borders[i];
    if (signed_area(b.x1, b.y1, b.x2, b.y2, x, y) > 0.0) return false;  // Eq. 3.8: left of b1 → b2
  }
  return true;
}

}  // namespace fw::antslam
