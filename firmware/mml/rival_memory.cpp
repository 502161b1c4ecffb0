#include "firmware/mml/rival_memory.h"

#include <algorithm>
#include <cmath>

#include "firmware/map/paired_fit_test.h"
#include "firmware/mml/pose_refiner.h"

namespace fw {
namespace mml {

bool RivalMemory::separated(const Se2f& a, const Se2f& b, const MmlOptions& o) const {
  const float dx = a.x - b.x, dy = a.y - b.y;
  return dx * dx + dy * dy > o.rival_separation_m * o.rival_separation_m ||
         std::fabs(wrap_angle(a.theta - b.theta)) > o.rival_separation_rad;
}

void RivalMemory::observe(const Cluster* clusters, std::size_t n, const Se2f& local_pose, const MmlOptions& o,
                          std::uint64_t step) {
  if (n == 0) return;
  float best = 0.0f;
  for (std::size_t i = 0; i < n; ++i) best = std::fmax(best, clusters[i].rating);
  if (!(best > 0.0f)) return;
  const Se2f local_inv = local_pose.inverse();
  for (std::size_t i = 0; i < n; ++i) {
    const float strength = clusters[i].rating / best;
    if (strength < o.rival_min_rating_ratio) continue;
    const Se2f robot(clusters[i].x, clusters[i].y, clusters[i].theta);
    std::size_t k = 0;
    while (k < count_ && separated(rivals_[k].h.compose(local_pose), robot, o)) ++k;
    if (k == count_) {
      if (count_ < kMaxRivals) {
        ++count_;
      } else {
        // Full: the weakest (then the longest unseen) entry makes room.
        k = 0;
        for (std::size_t j = 1; j < count_; ++j) {
          const Rival& a = rivals_[j];
          const Rival& b = rivals_[k];
          if (a.strength < b.strength || (a.strength == b.strength && a.last_seen < b.last_seen)) k = j;
        }
        if (rivals_[k].strength > strength) continue;
      }
      rivals_[k].strength = 0.0f;
    }
    rivals_[k].h = robot.compose(local_inv);
    rivals_[k].strength = std::fmax(rivals_[k].strength, strength);
    rivals_[k].last_seen = step;
  }
}

// Distinct correlation cells of pts_[0, n) (local frame): neighbouring points of one wall share
// their errors, the cells are the independent observations of the paired test.
std::uint32_t RivalMemory::count_cells(std::size_t n, float cell_m) {
  for (std::size_t i = 0; i < n; ++i) {
    const std::int64_t cx = static_cast<std::int64_t>(std::floor(pts_[i].x() / cell_m));
    const std::int64_t cy = static_cast<std::int64_t>(std::floor(pts_[i].y() / cell_m));
    keys_[i] = cx * 2000003 + cy;
  }
  std::sort(keys_, keys_ + n);
  return static_cast<std::uint32_t>(std::unique(keys_, keys_ + n) - keys_);
}

RivalCheck RivalMemory::check(const GlobalMap& map, const Point2f* local_pts, std::size_t n, const Se2f& h_best,
                              const Se2f& local_pose, const MmlOptions& o) {
  RivalCheck r;
  if (count_ == 0 || n < 2) return r;
  const std::size_t cap = std::min<std::size_t>(o.rival_points, kMaxRivalPoints);
  const std::size_t stride = (n + cap - 1) / cap;
  std::size_t m = 0;
  for (std::size_t i = 0; i < n && m < cap; i += stride) pts_[m++] = local_pts[i];
  r.independent = count_cells(m, o.rival_cell_m);
  RefineOptions ro;
  ro.clip_m = o.rival_clip_m;
  const RefineResult best = refine_pose(map, pts_, m, h_best, ro);
  const Se2f hb = best.accepted ? best.pose : h_best;
  const Se2f best_robot = hb.compose(local_pose);
  std::size_t kept = 0;
  for (std::size_t k = 0; k < count_; ++k) {
    const Rival rv = rivals_[k];
    bool keep = true;
    if (separated(rv.h.compose(local_pose), best_robot, o)) {
      ++r.checked;
      const RefineResult rr = refine_pose(map, pts_, m, rv.h, ro);
      const Se2f hr = rr.accepted ? rr.pose : rv.h;
      if (rival_significantly_better(map, pts_, m, hr, hb, o.rival_clip_m, r.independent, o.rival_z)) {
        ++r.contradicted;
        keep = false;
      } else {
        if (r.resolved) {
          r.resolved = false;
          r.open_rival = hr.compose(local_pose);
        }
        if (rival_significantly_better(map, pts_, m, hb, hr, o.rival_clip_m, r.independent, o.rival_z)) {
          r.candidate_rejected = true;
        }
      }
    }
    if (keep) rivals_[kept++] = rv;
  }
  count_ = kept;
  return r;
}

}  // namespace mml
}  // namespace fw
