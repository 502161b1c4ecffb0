#include "firmware/baselines/icp/trimmed_icp.h"

#include <algorithm>
#include <cmath>

#include "firmware/baselines/icp/valid_points.h"

namespace fw {

Status TrimmedIcpOptions::validate() const {
  if (!(trim_fraction > 0.0f && trim_fraction <= 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "icp: trim_fraction %g outside (0, 1]", static_cast<double>(trim_fraction));
  }
  if (!(min_error_change > 0.0f)) return Status::error(Errc::kInvalidArgument, "icp: min_error_change must be > 0");
  if (max_iterations < 1 || max_iterations > 1000) {
    return Status::error(Errc::kInvalidArgument, "icp: max_iterations %u outside [1, 1000]", max_iterations);
  }
  if (!(max_correspondence_m > 0.0f) || !std::isfinite(max_correspondence_m)) {
    return Status::error(Errc::kInvalidArgument, "icp: max_correspondence_m %g must be positive",
                         static_cast<double>(max_correspondence_m));
  }
  if (min_points < 3) return Status::error(Errc::kInvalidArgument, "icp: min_points %u must be at least 3", min_points);
  if (!(max_range >= 0.0f)) return Status::error(Errc::kInvalidArgument, "icp: max_range must be >= 0");
  return grid.validate();
}

Status TrimmedIcp::init(const TrimmedIcpOptions& options, StartupArena& arena) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  FW_RETURN_IF_ERROR(grid_.init(options.grid, arena));
  initialized_ = true;
  return Status::ok();
}

Status TrimmedIcp::match(const Point2f* points, std::size_t count, const Se2f& guess, ScanMatchResult* out) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "icp: match() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "icp: null result");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "icp: null points (count %zu)", count);
  if (count > TrimmedIcpOptions::kMaxPoints) {
    return Status::error(Errc::kInvalidArgument, "icp: %zu points exceed capacity %u", count, TrimmedIcpOptions::kMaxPoints);
  }
  if (!std::isfinite(guess.x) || !std::isfinite(guess.y) || !std::isfinite(guess.theta)) {
    return Status::error(Errc::kInvalidArgument, "icp: non-finite initial guess");
  }
  *out = ScanMatchResult{};
  n_ = copy_valid_points(points, count, options_.max_range, px_, py_);
  out->used_points = n_;
  if (n_ < options_.min_points) {
    return Status::error(Errc::kInvalidArgument, "icp: only %u valid points of %zu (min %u)", n_, count,
                         options_.min_points);
  }
  out->pose = guess;
  if (grid_.occupied_count() == 0) {
    out->map_was_empty = true;
    out->converged = true;
    return Status::ok();
  }
  const float cell2 = grid_.resolution() * grid_.resolution();
  double x = guess.x, y = guess.y, th = guess.theta;
  double prev_err = -1.0;
  std::uint32_t it = 0;
  std::uint32_t pairs = 0;
  double err = 0.0;
  while (it < options_.max_iterations) {
    ++it;
    const float c = static_cast<float>(std::cos(th)), s = static_cast<float>(std::sin(th));
    pairs = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      const float wx = static_cast<float>(x) + c * px_[i] - s * py_[i];
      const float wy = static_cast<float>(y) + s * px_[i] + c * py_[i];
      float mx, my, d2;
      if (!grid_.nearest_occupied(wx, wy, options_.max_correspondence_m, &mx, &my, &d2)) continue;
      mx_[pairs] = mx;
      my_[pairs] = my;
      d2_[pairs] = d2;
      pair_point_[pairs] = i;
      order_[pairs] = pairs;
      ++pairs;
    }
    if (pairs < 3) break;
    // Trimming: the best trim_fraction of the pairs by distance.
    std::uint32_t keep = static_cast<std::uint32_t>(std::ceil(options_.trim_fraction * static_cast<float>(pairs)));
    if (keep < 3) keep = pairs < 3 ? pairs : 3;
    const float* d2 = d2_;
    std::nth_element(order_, order_ + (keep - 1), order_ + pairs,
                     [d2](std::uint32_t a, std::uint32_t b) { return d2[a] < d2[b] || (d2[a] == d2[b] && a < b); });
    // Closed-form alignment of sensor points p to map points m (Arun/Horn in 2D).
    double sum = 0.0, pxm = 0, pym = 0, mxm = 0, mym = 0;
    for (std::uint32_t k = 0; k < keep; ++k) {
      const std::uint32_t q = order_[k], i = pair_point_[q];
      sum += d2_[q];
      pxm += px_[i];
      pym += py_[i];
      mxm += mx_[q];
      mym += my_[q];
    }
    const double inv = 1.0 / keep;
    pxm *= inv; pym *= inv; mxm *= inv; mym *= inv;
    err = sum * inv / cell2;
    double sxx = 0, sxy = 0, syx = 0, syy = 0;
    for (std::uint32_t k = 0; k < keep; ++k) {
      const std::uint32_t q = order_[k], i = pair_point_[q];
      const double ax = px_[i] - pxm, ay = py_[i] - pym, bx = mx_[q] - mxm, by = my_[q] - mym;
      sxx += ax * bx; sxy += ax * by; syx += ay * bx; syy += ay * by;
    }
    th = std::atan2(sxy - syx, sxx + syy);
    const double ct = std::cos(th), st = std::sin(th);
    x = mxm - (ct * pxm - st * pym);
    y = mym - (st * pxm + ct * pym);
    if (prev_err >= 0.0 && std::fabs(prev_err - err) < options_.min_error_change) {
      out->converged = true;
      break;
    }
    prev_err = err;
  }
  out->iterations = it;
  out->matched_points = pairs;
  out->pose = Se2f(static_cast<float>(x), static_cast<float>(y), wrap_angle(static_cast<float>(th)));
  out->score = n_ > 0 ? static_cast<float>(pairs) / static_cast<float>(n_) : 0.0f;
  out->effective_ratio = static_cast<float>(std::sqrt(err * cell2));
  return Status::ok();
}

Status TrimmedIcp::integrate(const Point2f* points, std::size_t count, const Se2f& pose, Point2f* new_cells,
                             std::size_t capacity, std::size_t* num_new) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "icp: integrate() before init()");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "icp: null points (count %zu)", count);
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return Status::error(Errc::kInvalidArgument, "icp: integrate at non-finite pose");
  }
  const std::size_t n =
      grid_.insert_scan(points, count, pose.x, pose.y, pose.theta, options_.max_range, new_cells, capacity);
  if (num_new) *num_new = n;
  return Status::ok();
}

}  // namespace fw
