#include "firmware/baselines/icp/pl_icp.h"

#include <algorithm>
#include <cmath>

#include "firmware/baselines/icp/valid_points.h"
#include "firmware/scan/point_to_line.h"

namespace fw {

Status PlIcpOptions::validate() const {
  if (!(max_correspondence_m > 0.0f) || !std::isfinite(max_correspondence_m)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: max_correspondence_m %g must be positive",
                         static_cast<double>(max_correspondence_m));
  }
  if (!(max_segment_m > 0.0f) || !std::isfinite(max_segment_m)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: max_segment_m %g must be positive",
                         static_cast<double>(max_segment_m));
  }
  if (search_window < 1) return Status::error(Errc::kInvalidArgument, "pl-icp: search_window must be at least 1");
  if (!(adaptive_order > 0.0f && adaptive_order <= 1.0f) || !(adaptive_mult >= 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: adaptive_order %g outside (0, 1] or adaptive_mult %g < 1",
                         static_cast<double>(adaptive_order), static_cast<double>(adaptive_mult));
  }
  if (!(trim_fraction > 0.0f && trim_fraction <= 1.0f)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: trim_fraction %g outside (0, 1]",
                         static_cast<double>(trim_fraction));
  }
  if (!(huber_m > 0.0f) || !(epsilon_xy_m > 0.0f) || !(epsilon_theta_rad > 0.0f)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: huber_m and the epsilons must be positive");
  }
  if (max_iterations < 1 || max_iterations > 1000) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: max_iterations %u outside [1, 1000]", max_iterations);
  }
  if (min_correspondences < 3) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: min_correspondences %u must be at least 3",
                         min_correspondences);
  }
  if (!(keyframe_translation_m >= 0.0f) || !(keyframe_rotation_rad >= 0.0f) || !(max_range >= 0.0f)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: keyframe thresholds and max_range must be >= 0");
  }
  return Status::ok();
}

Status PlIcp::init(const PlIcpOptions& options) {
  FW_RETURN_IF_ERROR(options.validate());
  options_ = options;
  initialized_ = true;
  reset();
  return Status::ok();
}

std::uint32_t PlIcp::lower_bound_bearing(float b) const {
  return static_cast<std::uint32_t>(std::lower_bound(kb_, kb_ + num_key_, b) - kb_);
}

Status PlIcp::match(const Point2f* points, std::size_t count, const Se2f& guess, ScanMatchResult* out) {
  if (!initialized_) return Status::error(Errc::kNotInitialized, "pl-icp: match() before init()");
  if (out == nullptr) return Status::error(Errc::kInvalidArgument, "pl-icp: null result");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "pl-icp: null points (count %zu)", count);
  if (count > PlIcpOptions::kMaxPoints) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: %zu points exceed capacity %u", count, PlIcpOptions::kMaxPoints);
  }
  if (!std::isfinite(guess.x) || !std::isfinite(guess.y) || !std::isfinite(guess.theta)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: non-finite initial guess (%g, %g, %g)",
                         static_cast<double>(guess.x), static_cast<double>(guess.y), static_cast<double>(guess.theta));
  }
  *out = ScanMatchResult{};
  n_ = copy_valid_points(points, count, options_.max_range, px_, py_);
  out->used_points = n_;
  out->pose = guess;
  if (n_ < options_.min_correspondences) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: only %u valid points of %zu (min %u)", n_, count,
                         options_.min_correspondences);
  }
  if (!has_key_ || num_key_ < 2) {
    out->map_was_empty = true;
    out->converged = true;
    return Status::ok();
  }
  // Unknown: T = key⁻¹ ⊕ pose, the scan's pose in the key scan's frame.
  Se2f t = key_pose_.between(guess);
  const float gate2 = options_.max_correspondence_m * options_.max_correspondence_m;
  const float seg2 = options_.max_segment_m * options_.max_segment_m;
  const std::int32_t win = static_cast<std::int32_t>(options_.search_window);
  PointToLineSystem sys;
  std::uint32_t it = 0, pairs = 0;
  bool converged = false;
  float rms = 0.0f;
  while (it < options_.max_iterations) {
    ++it;
    const float c = std::cos(t.theta), s = std::sin(t.theta);
    pairs = 0;
    for (std::uint32_t i = 0; i < n_; ++i) {
      const float qx = t.x + c * px_[i] - s * py_[i], qy = t.y + s * px_[i] + c * py_[i];
      // Nearest key point within ±window of q's bearing (key points in ascending bearing order).
      const std::int32_t k = static_cast<std::int32_t>(lower_bound_bearing(std::atan2(qy, qx)));
      const std::int32_t lo = std::max<std::int32_t>(0, k - win);
      const std::int32_t hi = std::min<std::int32_t>(static_cast<std::int32_t>(num_key_) - 1, k + win);
      std::int32_t j1 = -1;
      float best = gate2;
      for (std::int32_t j = lo; j <= hi; ++j) {
        const float dx = qx - kx_[j], dy = qy - ky_[j];
        const float d2 = dx * dx + dy * dy;
        if (d2 < best) {
          best = d2;
          j1 = j;
        }
      }
      if (j1 < 0) continue;
      // Second point: the nearer neighbour of j1 that lies on the same surface.
      std::int32_t j2 = -1;
      float best2 = 0.0f;
      for (std::int32_t j : {j1 - 1, j1 + 1}) {
        if (j < 0 || j >= static_cast<std::int32_t>(num_key_)) continue;
        const float sx = kx_[j] - kx_[j1], sy = ky_[j] - ky_[j1];
        if (sx * sx + sy * sy > seg2) continue;
        const float dx = qx - kx_[j], dy = qy - ky_[j];
        const float d2 = dx * dx + dy * dy;
        if (j2 < 0 || d2 < best2) {
          best2 = d2;
          j2 = j;
        }
      }
      if (j2 < 0) continue;
      const float ex = kx_[j2] - kx_[j1], ey = ky_[j2] - ky_[j1];
      const float len = std::sqrt(ex * ex + ey * ey);
      if (!(len > 1e-6f)) continue;
      nx_[pairs] = -ey / len;
      ny_[pairs] = ex / len;
      cx_[pairs] = kx_[j1];
      cy_[pairs] = ky_[j1];
      res_[pairs] = std::fabs(nx_[pairs] * (qx - kx_[j1]) + ny_[pairs] * (qy - ky_[j1]));
      pt_[pairs] = i;
      ++pairs;
    }
    if (pairs < options_.min_correspondences) break;
    // Outlier rejection: beyond adaptive_mult × the adaptive_order quantile of the residuals, and
    // at most the best trim_fraction of the pairs (CSM's outliers_adaptive_* and outliers_maxPerc).
    std::copy(res_, res_ + pairs, sorted_);
    const std::uint32_t qk = std::min(pairs - 1, static_cast<std::uint32_t>(options_.adaptive_order * static_cast<float>(pairs)));
    std::nth_element(sorted_, sorted_ + qk, sorted_ + pairs);
    float limit = options_.adaptive_mult * sorted_[qk];
    const std::uint32_t keep = std::max<std::uint32_t>(
        3, static_cast<std::uint32_t>(options_.trim_fraction * static_cast<float>(pairs)));
    if (keep < pairs) {
      std::copy(res_, res_ + pairs, sorted_);
      std::nth_element(sorted_, sorted_ + (keep - 1), sorted_ + pairs);
      limit = std::min(limit, sorted_[keep - 1]);
    }
    sys.clear();
    double sq = 0.0;
    for (std::uint32_t k = 0; k < pairs; ++k) {
      if (res_[k] > limit) continue;
      const std::uint32_t i = pt_[k];
      const float qx = t.x + c * px_[i] - s * py_[i], qy = t.y + s * px_[i] + c * py_[i];
      const float r = nx_[k] * (qx - cx_[k]) + ny_[k] * (qy - cy_[k]);
      const double w = res_[k] <= options_.huber_m ? 1.0 : static_cast<double>(options_.huber_m) / res_[k];
      sys.add(px_[i], py_[i], c, s, nx_[k], ny_[k], r, w);
      sq += static_cast<double>(r) * r;
    }
    if (sys.used < options_.min_correspondences) break;
    rms = static_cast<float>(std::sqrt(sq / sys.used));
    Eigen::Vector3d dx;
    if (!sys.solve(&dx)) break;
    t = Se2f(t.x + static_cast<float>(dx(0)), t.y + static_cast<float>(dx(1)),
             wrap_angle(t.theta + static_cast<float>(dx(2))));
    if (dx.head<2>().norm() < options_.epsilon_xy_m && std::fabs(dx(2)) < options_.epsilon_theta_rad) {
      converged = true;
      break;
    }
  }
  out->iterations = it;
  out->converged = converged;
  out->matched_points = pairs;
  out->score = static_cast<float>(sys.used) / static_cast<float>(n_);
  out->effective_ratio = rms;
  if (sys.used < options_.min_correspondences) {
    // Too little overlap with the key scan: keep the odometry guess (not an error; the front end
    // moves on and the next key scan starts from here).
    out->pose = guess;
    return Status::ok();
  }
  out->pose = key_pose_.compose(t);
  return Status::ok();
}

Status PlIcp::integrate(const Point2f* points, std::size_t count, const Se2f& pose, Point2f* new_cells,
                        std::size_t capacity, std::size_t* num_new) {
  (void)new_cells;
  (void)capacity;
  if (!initialized_) return Status::error(Errc::kNotInitialized, "pl-icp: integrate() before init()");
  if (count > 0 && points == nullptr) return Status::error(Errc::kInvalidArgument, "pl-icp: null points (count %zu)", count);
  if (count > PlIcpOptions::kMaxPoints) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: %zu points exceed capacity %u", count, PlIcpOptions::kMaxPoints);
  }
  if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta)) {
    return Status::error(Errc::kInvalidArgument, "pl-icp: integrate at non-finite pose");
  }
  if (num_new) *num_new = 0;
  if (has_key_) {
    const Se2f moved = key_pose_.between(pose);
    if (std::hypot(moved.x, moved.y) < options_.keyframe_translation_m &&
        std::fabs(moved.theta) < options_.keyframe_rotation_rad) {
      return Status::ok();
    }
  }
  // New key scan. Bearings must ascend for the window search; points of a scanner sweeping the
  // other way (or across ±π) are stored sorted by bearing, which keeps neighbours neighbours.
  const float max_r2 = options_.max_range > 0.0f ? options_.max_range * options_.max_range : 0.0f;
  std::uint32_t n = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const float px = points[i](0), py = points[i](1);
    if (!std::isfinite(px) || !std::isfinite(py)) continue;
    if (max_r2 > 0.0f && px * px + py * py > max_r2) continue;
    kx_[n] = px;
    ky_[n] = py;
    kb_[n] = std::atan2(py, px);
    ++n;
  }
  bool ascending = true;
  for (std::uint32_t i = 1; i < n && ascending; ++i) ascending = kb_[i] >= kb_[i - 1];
  if (!ascending) {
    // Insertion sort by bearing (≤ kMaxBeams, once per key scan, no allocation).
    for (std::uint32_t i = 1; i < n; ++i) {
      const float b = kb_[i], x = kx_[i], y = ky_[i];
      std::uint32_t j = i;
      for (; j > 0 && kb_[j - 1] > b; --j) {
        kb_[j] = kb_[j - 1];
        kx_[j] = kx_[j - 1];
        ky_[j] = ky_[j - 1];
      }
      kb_[j] = b;
      kx_[j] = x;
      ky_[j] = y;
    }
  }
  num_key_ = n;
  key_pose_ = pose;
  has_key_ = n >= 2;
  return Status::ok();
}

}  // namespace fw
