#include "sim/slam/selfmap.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "sim/io/reference_trajectory.h"
#include "sim/map/global_maps.h"
#include "sim/slam/slam_pipeline.h"

namespace sim {

bool align_rigid_2d(const std::vector<fw::Se2d>& from, const std::vector<fw::Se2d>& to, RigidAlignment2d* out,
                    std::string* error) {
  const std::size_t n = std::min(from.size(), to.size());
  if (n < 2) {
    *error = "rigid alignment: " + std::to_string(n) + " pose pairs (need at least 2)";
    return false;
  }
  double fx = 0, fy = 0, tx = 0, ty = 0;
  for (std::size_t i = 0; i < n; ++i) {
    fx += from[i].x;
    fy += from[i].y;
    tx += to[i].x;
    ty += to[i].y;
  }
  fx /= static_cast<double>(n);
  fy /= static_cast<double>(n);
  tx /= static_cast<double>(n);
  ty /= static_cast<double>(n);
  // Cross-covariance of the centred positions: dot (cos part) and cross (sin part).
  double sdot = 0, scross = 0, spread = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double ax = from[i].x - fx, ay = from[i].y - fy;
    const double bx = to[i].x - tx, by = to[i].y - ty;
    sdot += ax * bx + ay * by;
    scross += ax * by - ay * bx;
    spread += ax * ax + ay * ay;
  }
  if (!(spread > 1e-12 * static_cast<double>(n)) || !(std::hypot(sdot, scross) > 0)) {
    *error = "rigid alignment: the trajectory has no spread (rotation undefined)";
    return false;
  }
  const double th = std::atan2(scross, sdot);
  const double c = std::cos(th), s = std::sin(th);
  out->transform = fw::Se2d(tx - (c * fx - s * fy), ty - (s * fx + c * fy), th);
  double sq = 0, mx = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double px = out->transform.x + c * from[i].x - s * from[i].y;
    const double py = out->transform.y + s * from[i].x + c * from[i].y;
    const double d2 = (px - to[i].x) * (px - to[i].x) + (py - to[i].y) * (py - to[i].y);
    sq += d2;
    mx = std::max(mx, std::sqrt(d2));
  }
  out->rms_m = std::sqrt(sq / static_cast<double>(n));
  out->max_m = mx;
  out->pairs = n;
  return true;
}

bool reference_at_every_scan_of(const CarmenLog& log, const EvalDataset& d, std::vector<fw::Se2d>* out,
                                std::string* error) {
  if (d.corrected_poses.empty()) {
    *error = d.name + ": no public corrected poses (no reference to align)";
    return false;
  }
  std::vector<CorrectedPose> cp;
  if (!read_corrected_poses(d.corrected_poses, &cp, error)) return false;
  *out = reference_at_every_scan(log, cp);
  if (out->size() != log.scans.size()) {
    *error = d.corrected_poses + ": no reference at every scan of " + log.path;
    return false;
  }
  return true;
}

bool write_selfmap(const CarmenLog& log, const EvalDataset& d, const std::vector<fw::Se2d>& poses,
                   const std::string& dir, const std::string& name, SelfMapFiles* out, std::string* error) {
  std::vector<fw::Se2d> ref;
  if (!reference_at_every_scan_of(log, d, &ref, error)) return false;
  std::vector<CorrectedPose> cp;  // the rows written below, moved into the map's frame
  if (!read_corrected_poses(d.corrected_poses, &cp, error)) return false;
  // Reference (all scans the SLAM run covers) → AntSLAM trajectory.
  if (!align_rigid_2d(ref, poses, &out->alignment, error)) {
    *error = d.name + ": " + *error;
    return false;
  }
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec) {
    *error = dir + ": cannot create: " + ec.message();
    return false;
  }
  out->map_yaml = dir + "/" + name + ".yaml";
  out->reference = dir + "/" + name + ".reference.txt";
  // The reference map's builder parameters (0.05 m, 25 m for intel, fr079, aces).
  const double res = default_map_resolution(d.name);
  const OccupancyBuildOptions o = global_map_options(d.name, res);
  if (!write_slam_map(log, poses, o.resolution, o.max_usable_range, out->map_yaml, error)) return false;
  std::FILE* f = std::fopen(out->reference.c_str(), "w");
  if (f == nullptr) {
    *error = out->reference + ": cannot write";
    return false;
  }
  const fw::Se2d& T = out->alignment.transform;
  std::fprintf(f,
               "# %s corrected poses moved into the AntSLAM map's frame by the least-squares rigid transform\n"
               "# T = (%.6f, %.6f, %.6f rad) aligning the reference at every scan to the AntSLAM trajectory\n"
               "# (%zu scans; residual RMS %.4f m, max %.4f m); sim/slam/selfmap.h\n"
               "# columns: flaser_index ipc_timestamp logger_timestamp x y theta\n",
               d.corrected_poses.c_str(), T.x, T.y, T.theta, out->alignment.pairs, out->alignment.rms_m,
               out->alignment.max_m);
  for (const CorrectedPose& c : cp) {
    const fw::Se2d p = T.compose(c.pose);
    std::fprintf(f, "%zu %.6f %.6f %.6f %.6f %.6f\n", c.flaser_index, c.ipc_timestamp, c.logger_timestamp, p.x, p.y,
                 p.theta);
  }
  if (std::fclose(f) != 0) {
    *error = out->reference + ": write error";
    return false;
  }
  // Per-scan residual of the alignment (where the self-built map is distorted).
  out->residual_csv = dir + "/" + name + ".residual.csv";
  f = std::fopen(out->residual_csv.c_str(), "w");
  if (f == nullptr) {
    *error = out->residual_csv + ": cannot write";
    return false;
  }
  std::fprintf(f, "scan,slam_x,slam_y,slam_theta,ref_x,ref_y,ref_theta,residual_m,residual_deg\n");
  for (std::size_t i = 0; i < out->alignment.pairs; ++i) {
    const fw::Se2d r = T.compose(ref[i]);
    const fw::Se2d& p = poses[i];
    std::fprintf(f, "%zu,%.4f,%.4f,%.5f,%.4f,%.4f,%.5f,%.4f,%.3f\n", i, p.x, p.y, p.theta, r.x, r.y, r.theta,
                 std::hypot(r.x - p.x, r.y - p.y), std::fabs(fw::wrap_angle(r.theta - p.theta)) * 57.29577951308232);
  }
  if (std::fclose(f) != 0) {
    *error = out->residual_csv + ": write error";
    return false;
  }
  return true;
}

}  // namespace sim
