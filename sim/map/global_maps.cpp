#include "sim/map/global_maps.h"

#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include "sim/common/fail.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/file_io.h"
#include "sim/io/relations.h"
#include "sim/map/map_image_writer.h"
#include "sim/map/png_writer.h"
#include "sim/map/pose_graph.h"

#ifndef MMLFW_SOURCE_DIR
#define MMLFW_SOURCE_DIR "."
#endif

namespace sim {
namespace {

bool known(const std::string& ds) {
  for (const std::string& d : global_map_datasets()) {
    if (d == ds) return true;
  }
  return false;
}

std::string build_signature(const std::string& ds, const OccupancyBuildOptions& o) {
  std::ostringstream s;
  s.precision(17);
  s << "mmlfw global map v2 dataset=" << ds << " resolution=" << o.resolution << " max_usable_range="
    << o.max_usable_range << " free_on_no_return=" << o.free_on_no_return << " margin=" << o.margin
    << " l_occ=" << o.l_occ << " l_free=" << o.l_free << " occupied_logodds=" << o.occupied_logodds
    << " beam_stride=" << o.beam_stride << " source=" << global_map_source(ds);
  return s.str();
}

// The cache's parameter file; anything but a small regular file (missing, a FIFO someone put in
// MMLFW_MAP_DIR, …) reads as "" and the map is rebuilt.
std::string read_text(const std::string& path) {
  std::string text, err;
  return read_regular_file(path, std::uint64_t(1) << 20, &text, &err) ? text : std::string();
}

}  // namespace

const std::vector<std::string>& global_map_datasets() {
  static const std::vector<std::string> k = {"intel", "fr079", "aces", "mit-killian", "fr-clinic", "fr101",
                                             "fr-campus"};
  return k;
}

double default_map_resolution(const std::string& dataset) {
  // fr-campus: outdoor campus, large extent (see global_maps.h).
  return (dataset == "mit-killian" || dataset == "fr-clinic" || dataset == "fr-campus") ? 0.10 : 0.05;
}

OccupancyBuildOptions global_map_options(const std::string& dataset, double resolution) {
  OccupancyBuildOptions o;
  o.resolution = resolution;
  // Indoor office logs: the far returns are few and noisy (and 81.8 m means "no return");
  // MIT Killian Court is a large open courtyard with long corridors.
  o.max_usable_range = (dataset == "mit-killian" || dataset == "fr-campus") ? 40.0 : 25.0;
  return o;
}

std::string global_map_source(const std::string& dataset) {
  if (dataset == "fr-clinic") {
    return "fr-clinic/fr-clinic_robotlaser.clf.gz scans at the 1316 relation timestamps, poses from a pose graph of "
           "fr-clinic/fr-clinic.relations (no corrected log exists)";
  }
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr || d->corrected_log.empty()) return "";
  return d->corrected_log + " FLASER poses (GMapping-corrected)";
}

bool build_global_map(const std::string& dataset, double resolution, RosMap* out, std::string* error,
                      OccupancyBuildStats* stats, std::string* report_out) {
  if (!known(dataset)) {
    return fail(error, "unknown dataset '" + dataset + "' (known: intel, fr079, aces, mit-killian, fr-clinic, fr101, fr-campus)");
  }
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr) return fail(error, "dataset '" + dataset + "' missing from sim/io/datasets.h");
  const std::string log_path = data_path(dataset == "fr-clinic" ? d->raw_log : d->corrected_log);
  if (!std::filesystem::exists(log_path)) {
    return fail(error, "dataset '" + dataset + "': log '" + log_path + "' not found (MMLFW_DATA_DIR=" + data_dir() + ")");
  }
  CarmenLog log;
  if (!read_carmen_log(log_path, CarmenReadOptions{}, &log, error)) return false;
  std::vector<const CarmenScan*> used;
  std::vector<fw::Se2d> laser_poses;
  if (dataset == "fr-clinic") {
    std::vector<std::size_t> idx;
    std::vector<fw::Se2d> robot;
    std::string report;
    if (!relation_graph_trajectory(dataset, log, &idx, &robot, &report, error)) return false;
    if (report_out != nullptr) *report_out = report;
    for (std::size_t k = 0; k < idx.size(); ++k) {
      const CarmenScan& s = log.scans[idx[k]];
      // ROBOTLASER1: pose = laser pose, odom = robot pose (same odometry frame): mount offset.
      laser_poses.push_back(robot[k].compose(s.odom.between(s.pose)));
      used.push_back(&s);
    }
  } else {
    for (const CarmenScan& s : log.scans) {
      used.push_back(&s);
      laser_poses.push_back(s.pose);
    }
  }
  std::vector<PosedScan> scans;
  scans.reserve(used.size());
  for (std::size_t k = 0; k < used.size(); ++k) {
    const CarmenScan& s = *used[k];
    PosedScan p;
    p.pose = laser_poses[k];
    p.angle_min = s.angle_min;
    p.angle_increment = s.angle_increment;
    p.max_range = s.max_range;
    p.ranges = s.ranges.data();
    p.count = s.ranges.size();
    scans.push_back(p);
  }
  OccupancyGrid grid;
  if (!build_occupancy_grid(scans, global_map_options(dataset, resolution), &grid, stats, error)) {
    if (error != nullptr) *error = log_path + ": " + *error;
    return false;
  }
  *out = grid_to_ros_map(grid, dataset + ".pgm");
  return true;
}

bool relation_graph_trajectory(const std::string& dataset, std::vector<std::size_t>* scan_indices,
                               std::vector<fw::Se2d>* robot_poses, std::string* report, std::string* error) {
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr || d->raw_log.empty()) return fail(error, "dataset '" + dataset + "': no raw log");
  CarmenLog log;
  if (!read_carmen_log(data_path(d->raw_log), CarmenReadOptions{}, &log, error)) return false;
  return relation_graph_trajectory(dataset, log, scan_indices, robot_poses, report, error);
}

bool relation_graph_trajectory(const std::string& dataset, const CarmenLog& log,
                               std::vector<std::size_t>* scan_indices, std::vector<fw::Se2d>* robot_poses,
                               std::string* report, std::string* error) {
  const Dataset* d = find_dataset(dataset);
  if (d == nullptr || d->relations.empty() || d->raw_log.empty() || !d->relations_match_log) {
    return fail(error, "dataset '" + dataset + "': no relations that match its raw log");
  }
  std::vector<Relation> rel;
  if (!read_relations(data_path(d->relations), &rel, error)) return false;
  // Scan lookup by ipc timestamp (the relation files print the log's 6-decimal timestamps).
  std::map<long long, std::size_t> by_time;
  for (std::size_t k = 0; k < log.scans.size(); ++k) by_time.emplace(std::llround(log.scans[k].ipc_timestamp * 1e6), k);
  std::map<long long, std::size_t> node_of;  // timestamp -> node
  for (const Relation& r : rel) {
    for (double t : {r.t1, r.t2}) {
      const long long key = std::llround(t * 1e6);
      if (by_time.count(key) == 0) {
        char buf[64];
        std::snprintf(buf, sizeof(buf), "%.6f", t);
        return fail(error, data_path(d->relations) + ": timestamp " + buf + " is not a scan of " + data_path(d->raw_log));
      }
      node_of.emplace(key, 0);
    }
  }
  std::vector<std::size_t> idx;
  for (auto& [key, node] : node_of) {
    node = idx.size();
    idx.push_back(by_time[key]);
  }
  const std::size_t n = idx.size();
  std::vector<PoseGraphEdge> edges;
  // σ 5 cm / 0.02 rad per relation: only the ratio matters for the optimum.
  Eigen::Matrix3d info = Eigen::Matrix3d::Zero();
  info(0, 0) = info(1, 1) = 1.0 / (0.05 * 0.05);
  info(2, 2) = 1.0 / (0.02 * 0.02);
  std::vector<const PoseGraphEdge*> next(n, nullptr);
  for (const Relation& r : rel) {
    PoseGraphEdge e;
    e.i = node_of[std::llround(r.t1 * 1e6)];
    e.j = node_of[std::llround(r.t2 * 1e6)];
    e.z = r.delta;
    e.information = info;
    if (e.i == e.j) continue;
    edges.push_back(e);
  }
  for (const PoseGraphEdge& e : edges) {
    if (e.j == e.i + 1) next[e.i] = &e;
  }
  // Initial guess: chain the consecutive relations (odometry where a link is missing).
  std::vector<fw::Se2d> x(n);
  x[0] = log.scans[idx[0]].odom;
  std::size_t odometry_links = 0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    fw::Se2d step;
    if (next[k] != nullptr) {
      step = next[k]->z;
    } else {
      step = log.scans[idx[k]].odom.between(log.scans[idx[k + 1]].odom);
      ++odometry_links;
    }
    x[k + 1] = x[k].compose(step);
  }
  PoseGraphResult pg;
  if (!optimize_pose_graph(&x, edges, PoseGraphOptions{}, &pg, error)) return false;
  Trajectory traj, odom;
  for (std::size_t k = 0; k < n; ++k) {
    traj.push_back({log.scans[idx[k]].ipc_timestamp, x[k]});
    odom.push_back({log.scans[idx[k]].ipc_timestamp, log.scans[idx[k]].odom});
  }
  const RelationsMetric m = evaluate_relations(rel, traj);
  const RelationsMetric mo = evaluate_relations(rel, odom);
  if (report != nullptr) {
    char buf[512];
    std::snprintf(buf, sizeof(buf),
                  "%s: pose graph of %zu relation scans, %zu relations (%zu links from odometry); chi2 %.4g -> %.4g in "
                  "%d GN iterations (last solve %d CG iterations); relation error of the result: %.4f m / %.3f deg mean (max %.3f m / %.2f deg); "
                  "raw odometry: %.4f m / %.3f deg",
                  dataset.c_str(), n, edges.size(), odometry_links, pg.initial_chi2, pg.final_chi2, pg.iterations,
                  pg.cg_iterations_last, m.trans_mean, m.rot_mean_deg, m.trans_max, m.rot_max_deg, mo.trans_mean, mo.rot_mean_deg);
    *report = buf;
  }
  *scan_indices = std::move(idx);
  *robot_poses = std::move(x);
  return true;
}

std::string map_cache_dir() {
  const char* env = std::getenv("MMLFW_MAP_DIR");
  if (env != nullptr && *env != '\0') return env;
  return std::string(MMLFW_SOURCE_DIR) + "/build/maps";
}

std::string global_map_yaml_path(const std::string& dataset, const std::string& dir) {
  return dir + "/" + dataset + ".yaml";
}
std::string global_map_image_path(const std::string& dataset, const std::string& dir) {
  return dir + "/" + dataset + ".mmap";
}

bool write_map_png(const std::string& path, const RosMap& map, std::string* error) {
  std::vector<std::uint8_t> px(map.pixels.size());
  const int maxval = map.maxval > 0 ? map.maxval : 255;
  for (std::size_t i = 0; i < px.size(); ++i) px[i] = static_cast<std::uint8_t>(map.pixels[i] * 255 / maxval);
  return write_png(path, map.width, map.height, 1, px, error);
}

bool write_global_map(const std::string& dataset, double resolution, const std::string& dir, RosMap* out,
                      std::string* error, OccupancyBuildStats* stats, std::string* report) {
  if (resolution <= 0.0) resolution = default_map_resolution(dataset);
  RosMap map;
  if (!build_global_map(dataset, resolution, &map, error, stats, report)) return false;
  // Written into a private folder, then renamed into place (atomic per file, build.txt last), so
  // a concurrent reader (tests of other modules share build/maps) never sees a half-written file.
  const std::string tmp = dir + "/.tmp-" + dataset + "-" + std::to_string(::getpid());
  std::error_code ec;
  std::filesystem::create_directories(tmp, ec);
  if (ec) return fail(error, tmp + ": cannot create directory: " + ec.message());
  std::vector<std::uint8_t> image;
  const std::string sig = build_signature(dataset, global_map_options(dataset, resolution));
  bool ok = write_ros_map(global_map_yaml_path(dataset, tmp), map, error) &&
            write_map_png(tmp + "/" + dataset + ".png", map, error) && compile_map_image(map, &image, error) &&
            write_file_bytes(global_map_image_path(dataset, tmp), image, error);
  if (ok) {
    std::ofstream s(tmp + "/" + dataset + ".build.txt", std::ios::trunc);
    s << sig << "\n";
    s.close();
    ok = static_cast<bool>(s) || fail(error, tmp + ": write failed");
  }
  for (const char* ext : {".pgm", ".png", ".mmap", ".yaml", ".build.txt"}) {
    if (!ok) break;
    std::filesystem::rename(tmp + "/" + dataset + ext, dir + "/" + dataset + ext, ec);
    if (ec) ok = fail(error, dir + "/" + dataset + ext + ": cannot move into place: " + ec.message());
  }
  std::filesystem::remove_all(tmp, ec);
  if (!ok) return false;
  map.yaml_path = global_map_yaml_path(dataset, dir);
  *out = std::move(map);
  return true;
}

bool ensure_global_map(const std::string& dataset, double resolution, const std::string& dir, RosMap* out,
                       std::string* error, bool* rebuilt) {
  if (resolution <= 0.0) resolution = default_map_resolution(dataset);
  if (rebuilt != nullptr) *rebuilt = false;
  if (!known(dataset)) {
    return fail(error, "unknown dataset '" + dataset + "' (known: intel, fr079, aces, mit-killian, fr-clinic, fr101, fr-campus)");
  }
  const std::string yaml = global_map_yaml_path(dataset, dir);
  const std::string sig_path = dir + "/" + dataset + ".build.txt";
  const std::string sig = build_signature(dataset, global_map_options(dataset, resolution));
  if (std::filesystem::exists(yaml) && std::filesystem::exists(global_map_image_path(dataset, dir)) &&
      read_text(sig_path) == sig + "\n") {
    if (read_ros_map(yaml, out, error)) return true;
    // Unreadable cache: rebuild below.
  }
  RosMap built;
  if (!write_global_map(dataset, resolution, dir, &built, error)) return false;
  if (rebuilt != nullptr) *rebuilt = true;
  return read_ros_map(yaml, out, error);
}

}  // namespace sim
