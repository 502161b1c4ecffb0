#include "sim/eval/grounding/grounding.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <random>

#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/map/global_maps.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace sim::ground {

namespace {

bool fail(std::string* err, const std::string& msg) {
  if (err != nullptr) *err = msg;
  return false;
}

// The reference's motion between consecutive pairs where the odometry did not move (< 1 mm, 0.001 rad).
void rest_floor(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref, OdometryMeasure* out) {
  std::vector<double> m, deg;
  for (std::size_t i = 1; i < odom.size() && i < ref.size(); ++i) {
    const fw::Se2d o = odom[i - 1].between(odom[i]);
    if (std::hypot(o.x, o.y) >= 0.001 || std::fabs(o.theta) >= 0.001) continue;
    const fw::Se2d r = ref[i - 1].between(ref[i]);
    m.push_back(std::hypot(r.x, r.y));
    deg.push_back(std::fabs(r.theta) * 180.0 / M_PI);
  }
  out->rest_pairs = m.size();
  out->rest_m_p95 = quantile(m, 0.95);
  out->rest_deg_p95 = quantile(deg, 0.95);
}

// Evenly spaced indices: at most `want` of [0, n).
std::vector<std::size_t> sample_indices(std::size_t n, std::size_t want) {
  std::vector<std::size_t> out;
  if (n == 0 || want == 0) return out;
  const std::size_t step = std::max<std::size_t>(1, n / want);
  for (std::size_t i = step / 2; i < n && out.size() < want; i += step) out.push_back(i);
  return out;
}

// The pose pairs of a raw log at the instants where the reference is measured: FLASER logs, the
// corrected (laser) poses with the raw log's laser pose in the odometry frame; fr-clinic
// (ROBOTLASER1, no corrected log), the relation-graph robot poses with the raw robot pose.
bool log_pairs(const std::string& dataset, std::vector<fw::Se2d>* odom, std::vector<fw::Se2d>* ref, std::string* err) {
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr || d->raw_log.empty()) return fail(err, dataset + ": no raw log");
  CarmenLog log;
  if (!read_carmen_log(data_path(d->raw_log), CarmenReadOptions{}, &log, err)) return false;
  if (dataset == "fr-clinic") {
    std::vector<std::size_t> idx;
    std::vector<fw::Se2d> robot;
    std::string report;
    if (!relation_graph_trajectory(dataset, log, &idx, &robot, &report, err)) return false;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      odom->push_back(log.scans[idx[k]].odom);
      ref->push_back(robot[k]);
    }
    return true;
  }
  std::vector<CorrectedPose> corrected;
  if (d->corrected_poses.empty()) return fail(err, dataset + ": no corrected poses");
  if (!read_corrected_poses(data_path(d->corrected_poses), &corrected, err)) return false;
  for (const CorrectedPose& c : corrected) {
    if (c.flaser_index >= log.scans.size() || log.scans[c.flaser_index].index != c.flaser_index) continue;
    odom->push_back(log.scans[c.flaser_index].pose);
    ref->push_back(c.pose);
  }
  return true;
}

// The truth seen through a reference with iid per-pose errors (seeded per run).
std::vector<fw::Se2d> noisy_reference(const std::vector<fw::Se2d>& ref, const GroundOptions& opt, int seed) {
  std::mt19937_64 rng(0x9e3779b97f4a7c15ull ^ static_cast<std::uint64_t>(seed));
  std::normal_distribution<double> g(0.0, 1.0);
  std::vector<fw::Se2d> out;
  out.reserve(ref.size());
  for (const fw::Se2d& p : ref) {
    // One draw per declarator: sequenced, the same order on every compiler (check_draw_order.py).
    const double nx = g(rng), ny = g(rng), nt = g(rng);
    out.emplace_back(p.x + opt.ref_sigma_m * nx, p.y + opt.ref_sigma_m * ny,
                     fw::wrap_angle(p.theta + opt.ref_sigma_deg * M_PI / 180.0 * nt));
  }
  return out;
}

}  // namespace

void rest_noise_from(const OdometryMeasure& log, double* sigma_m, double* sigma_deg) {
  *sigma_m = *sigma_deg = 0;
  if (log.rest_pairs < 20 || !std::isfinite(log.rest_m_p95) || !std::isfinite(log.rest_deg_p95)) return;
  *sigma_m = log.rest_m_p95 / (2.4477 * std::sqrt(2.0));
  *sigma_deg = log.rest_deg_p95 / (1.96 * std::sqrt(2.0));
}

const std::vector<std::string>& odometry_datasets() {
  static const std::vector<std::string> v = {"intel", "fr079", "aces", "fr-clinic"};
  return v;
}

const std::vector<std::string>& residual_datasets() {
  static const std::vector<std::string> v = {"intel", "fr079", "aces", "fr-clinic", "mit-killian", "fr101", "fr-campus"};
  return v;
}

void summarize_pairs(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref, const GroundOptions& opt,
                     OdometryMeasure* out) {
  out->pairs = std::min(odom.size(), ref.size());
  out->path_m = 0;
  for (std::size_t i = 1; i < out->pairs; ++i) out->path_m += std::hypot(ref[i].x - ref[i - 1].x, ref[i].y - ref[i - 1].y);
  WindowOptions ws;
  ws.window_m = opt.short_window_m;
  out->short_w = summarize(odometry_windows(odom, ref, ws));
  WindowOptions wl;
  wl.window_m = opt.long_window_m;
  wl.stride_m = opt.long_stride_m;
  out->long_w = summarize(odometry_windows(odom, ref, wl));
  rest_floor(odom, ref, out);
  out->measured = out->short_w.windows > 0;
}

bool measure_log_odometry(const std::string& dataset, const GroundOptions& opt, OdometryMeasure* out,
                          std::string* err) {
  *out = OdometryMeasure{};
  out->name = dataset;
  out->is_log = true;
  std::vector<fw::Se2d> odom, ref;
  if (!log_pairs(dataset, &odom, &ref, err)) {
    out->note = err != nullptr ? *err : "not measured";
    return false;
  }
  summarize_pairs(odom, ref, opt, out);
  out->note = dataset == "fr-clinic"
                  ? "reference: the relation-graph poses of the 1316 relation scans; the log's ROBOTLASER1 robot pose "
                    "agrees with them far better than wheel odometry does elsewhere (it is probably scan-matched "
                    "odometry, or the relations were derived from it): a lower bound, not a wheel-odometry sample"
                  : "reference: the " + std::to_string(ref.size()) + " corrected poses";
  return true;
}

bool measure_log_residuals(const std::string& dataset, const GroundOptions& opt, ResidualMeasure* out,
                           std::string* err) {
  *out = ResidualMeasure{};
  out->name = dataset;
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr) return fail(err, "unknown dataset " + dataset);
  RosMap ros;
  if (!ensure_global_map(dataset, 0, map_cache_dir(), &ros, err)) return false;
  OccupancyGrid grid;
  if (!ros_map_to_grid(ros, &grid, err)) return false;
  const MapDistance dist(grid);
  CarmenLog log;
  std::vector<const CarmenScan*> scans;
  std::vector<fw::Se2d> poses;  // laser poses in the map frame
  if (dataset == "fr-clinic") {
    if (!read_carmen_log(data_path(d->raw_log), CarmenReadOptions{}, &log, err)) return false;
    std::vector<std::size_t> idx;
    std::vector<fw::Se2d> robot;
    std::string report;
    if (!relation_graph_trajectory(dataset, log, &idx, &robot, &report, err)) return false;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const CarmenScan& s = log.scans[idx[k]];
      scans.push_back(&s);
      poses.push_back(robot[k].compose(s.odom.between(s.pose)));
    }
  } else {
    if (!read_carmen_log(data_path(d->corrected_log), CarmenReadOptions{}, &log, err)) return false;
    for (const CarmenScan& s : log.scans) {
      scans.push_back(&s);
      poses.push_back(s.pose);
    }
  }
  ResidualSample sample;
  for (const std::size_t i : sample_indices(scans.size(), opt.residual_scans)) {
    const CarmenScan& s = *scans[i];
    sample.add_scan(dist, poses[i], s.angle_min, s.angle_increment, 0.0f, s.max_range, s.ranges.data(),
                    s.ranges.size(), opt.residual);
  }
  out->s = summarize(sample, opt.residual);
  out->measured = out->s.points > 0;
  out->note = dataset == "fr-clinic" ? "relation-graph poses on the map built from them"
                                     : "corrected poses on the map built from the corrected log";
  return true;
}

bool measure_profile_odometry(const std::string& name, const OdometryNoiseOptions& wheels, const GroundOptions& opt,
                              OdometryMeasure* out, std::string* err) {
  *out = OdometryMeasure{};
  out->name = name;
  out->is_log = false;
  World world;
  if (!make_builtin_world(opt.world, &world, err)) return false;
  std::vector<OdometryWindow> ws, wl, wr;
  std::vector<fw::Se2d> all_odom, all_ref;
  for (int seed = 1; seed <= opt.sim_seeds; ++seed) {
    SyntheticRunOptions ro;
    ro.seed = static_cast<std::uint64_t>(seed);
    ro.odometry = wheels;
    ro.laser.beams = 2;  // the odometry is what is measured here: a cheap laser
    ro.people = 0;
    SyntheticRun run;
    if (!run.init(world, ro, err)) return false;
    std::vector<fw::Se2d> odom, ref;
    SyntheticFrame f;
    while (run.next(&f)) {
      if (f.odometry.empty()) continue;
      const hal::Odometry& h = f.odometry.back();
      const double tau = (static_cast<double>(h.timestamp_ns) - static_cast<double>(ro.start_time_ns)) * 1e-9;
      odom.emplace_back(h.x, h.y, h.theta);
      ref.push_back(run.truth_at(tau));
    }
    WindowOptions s;
    s.window_m = opt.short_window_m;
    WindowOptions l;
    l.window_m = opt.long_window_m;
    l.stride_m = opt.long_stride_m;
    for (const OdometryWindow& w : odometry_windows(odom, ref, s)) ws.push_back(w);
    for (const OdometryWindow& w : odometry_windows(odom, ref, l)) wl.push_back(w);
    if (opt.ref_sigma_m > 0 || opt.ref_sigma_deg > 0) {
      for (const OdometryWindow& w : odometry_windows(odom, noisy_reference(ref, opt, seed), l)) wr.push_back(w);
    }
    all_odom.insert(all_odom.end(), odom.begin(), odom.end());
    all_ref.insert(all_ref.end(), ref.begin(), ref.end());
    out->pairs += odom.size();
  }
  out->short_w = summarize(ws);
  out->long_w = summarize(wl);
  out->through_ref = !wr.empty();
  out->long_w_ref = summarize(wr);
  out->path_m = 0;
  for (std::size_t i = 1; i < all_ref.size(); ++i) {
    const double step = std::hypot(all_ref[i].x - all_ref[i - 1].x, all_ref[i].y - all_ref[i - 1].y);
    if (step < 5.0) out->path_m += step;  // not across the runs' joins
  }
  rest_floor(all_odom, all_ref, out);
  out->measured = out->short_w.windows > 0;
  out->note = "synthetic runs in " + opt.world + ", seeds 1.." + std::to_string(opt.sim_seeds) + ", exact truth";
  return true;
}

bool measure_sensor_residuals(const std::string& name, const LaserModelOptions& laser, const GroundOptions& opt,
                              ResidualMeasure* out, std::string* err) {
  *out = ResidualMeasure{};
  out->name = name;
  out->is_log = false;
  World world;
  if (!make_builtin_world(opt.world, &world, err)) return false;
  OccupancyGrid grid;
  if (!rasterize_world(world, RasterOptions{}, &grid, err)) return false;
  const MapDistance dist(grid);
  SyntheticRunOptions ro;
  ro.seed = 1;
  ro.laser = laser;
  SyntheticRun run;
  if (!run.init(world, ro, err)) return false;
  const std::vector<std::size_t> pick = sample_indices(run.num_scans(), opt.residual_scans);
  ResidualSample sample;
  SyntheticFrame f;
  while (run.next(&f)) {
    if (!std::binary_search(pick.begin(), pick.end(), static_cast<std::size_t>(f.index))) continue;
    sample.add_scan(dist, f.truth, f.scan.angle_min, f.scan.angle_increment, f.scan.range_min, f.scan.range_max,
                    f.scan.ranges, f.scan.beam_count, opt.residual);
  }
  out->s = summarize(sample, opt.residual);
  out->measured = out->s.points > 0;
  out->note = "simulated scans at the exact pose in " + opt.world + " (people walking, default count)";
  return true;
}

}  // namespace sim::ground
