#include "firmware/antslam/closure_isolation.h"

#include <algorithm>
#include <cmath>

namespace fw::antslam {

namespace {

// Se2::transform_point with the rotation computed once per pose, not once per point: the scene is
// placed at two poses for every rival.
struct Placement {
  explicit Placement(const Se2d& pose) : x(pose.x), y(pose.y), c(std::cos(pose.theta)), s(std::sin(pose.theta)) {}
  Point2f operator()(const Point2f& p) const {
    return Point2f(static_cast<float>(x + c * p(0) - s * p(1)), static_cast<float>(y + s * p(0) + c * p(1)));
  }
  double x, y, c, s;
};

// z of mean(contact at a − contact at b) over the correlation cells of the points at a (the points of
// one cell are averaged first: neighbouring end-points are not independent).
float paired_z(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n, const Se2d& a, const Se2d& b,
               float cell_m, CellSample* cells) {
  const Placement at_a(a), at_b(b);
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f q = at_a(scene[i]);
    const auto cx = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(q(0) / cell_m)) & 0xffff);
    const auto cy = static_cast<std::uint32_t>(static_cast<std::int32_t>(std::floor(q(1) / cell_m)) & 0xffff);
    cells[i].key = (cx << 16) | cy;
    cells[i].d = (static_cast<float>(field.contact(q)) - static_cast<float>(field.contact(at_b(scene[i])))) / 255.0f;
  }
  std::sort(cells, cells + n, [](const CellSample& l, const CellSample& r) { return l.key < r.key; });
  double s1 = 0.0, s2 = 0.0;
  std::size_t used = 0;
  for (std::size_t i = 0; i < n;) {
    std::size_t j = i;
    double cs = 0.0;
    while (j < n && cells[j].key == cells[i].key) cs += cells[j++].d;
    const double d = cs / static_cast<double>(j - i);
    s1 += d;
    s2 += d * d;
    ++used;
    i = j;
  }
  if (used < 2) return 0.0f;
  const double mean = s1 / static_cast<double>(used);
  const double var = std::max(0.0, (s2 - s1 * mean) / static_cast<double>(used - 1));
  const double se = std::sqrt(var / static_cast<double>(used));
  if (!(se > 0.0)) return mean > 0.0 ? 1e6f : 0.0f;
  return static_cast<float>(mean / se);
}

}  // namespace

Status IsolationOptions::validate() const {
  if (!(max_shift_m >= 0.0f && shift_step_m > 0.0f && min_separation_m > 0.0f && min_separation_rad > 0.0f &&
        cell_m > 0.0f && z > 0.0f && cutoff_start_m > 0.0f && cutoff_end_m > 0.0f)) {
    return Status::error(Errc::kInvalidArgument, "antslam isolation: shifts, separations, cell, z and cutoffs must be > 0");
  }
  return Status::ok();
}

IsolationResult check_closure_isolation(const pransam::ContactField<2>& field, const Point2f* scene, std::size_t n,
                                        const Se2d& h, const IsolationOptions& o, CellSample* cells,
                                        const IsolationPrior* prior) {
  IsolationResult r;
  const FieldFit fh = fit_on_field(field, scene, n, h, o.refine_iterations, o.cutoff_start_m, o.cutoff_end_m);
  r.pose = fh.pose;
  r.quality = fh.quality;
  r.rival_z = 1e6f;
  if (n < 3) return r;
  // Principal axes of the scene's extent at the closure.
  const Placement at_h(fh.pose);
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f q = at_h(scene[i]);
    mx += q(0);
    my += q(1);
  }
  mx /= static_cast<double>(n);
  my /= static_cast<double>(n);
  double sxx = 0, sxy = 0, syy = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const Point2f q = at_h(scene[i]);
    sxx += (q(0) - mx) * (q(0) - mx);
    sxy += (q(0) - mx) * (q(1) - my);
    syy += (q(1) - my) * (q(1) - my);
  }
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  const double axes[2][2] = {{std::cos(angle), std::sin(angle)}, {-std::sin(angle), std::cos(angle)}};
  const int steps = static_cast<int>(std::floor(o.max_shift_m / o.shift_step_m));
  // The scene turned by π about its own centroid (in the field's frame): a corridor walked the other way.
  for (int turn = 0; turn < (o.turned_rivals ? 2 : 1); ++turn) {
    Se2d base = fh.pose;
    if (turn == 1) {
      const Se2d about(mx, my, 0.0);
      base = about.compose(Se2d(0, 0, 3.14159265358979323846)).compose(about.inverse()).compose(fh.pose);
    }
    for (int axis = 0; axis < 2; ++axis) {
      for (int k = -steps; k <= steps; ++k) {
        if (k == 0 && (axis == 1 || turn == 0)) continue;  // the closure itself; the turned one once
        const double d = k * static_cast<double>(o.shift_step_m);
        const Se2d seed(base.x + d * axes[axis][0], base.y + d * axes[axis][1], base.theta);
        const FieldFit fr = fit_on_field(field, scene, n, seed, o.refine_iterations, o.cutoff_start_m, o.cutoff_end_m);
        ++r.rivals_tried;
        const double sep = std::hypot(fr.pose.x - fh.pose.x, fr.pose.y - fh.pose.y);
        const double sep_th = std::fabs(wrap_angle(fr.pose.theta - fh.pose.theta));
        if (sep < o.min_separation_m && sep_th < o.min_separation_rad) continue;  // the closure's own mode
        if (prior != nullptr && !(mahalanobis2(fr.pose, prior->mean, prior->info) <= prior->gate)) continue;
        const float z = paired_z(field, scene, n, fh.pose, fr.pose, o.cell_m, cells);
        if (z < r.rival_z) {
          r.rival_z = z;
          r.rival_quality = fr.quality;
          r.rival = fr.pose;
        }
      }
    }
  }
  r.isolated = r.rival_z > o.z;
  return r;
}

}  // namespace fw::antslam
