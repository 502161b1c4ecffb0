#include "sim/eval/mml_eval/mml_eval.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/eval/mml_eval/unmapped_scan.h"

#include "sim/viz/font5x7.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <unordered_map>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <limits>
#include <sstream>

#include "firmware/base/rng.h"
#include "firmware/map/map_image.h"
#include "sim/common/fail.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"
#include "sim/viz/picture.h"

namespace sim::mmleval {

namespace {

bool load_image(LoadedDataset* ds, std::string* err) {
  ds->arena = std::make_unique<fw::StartupArena>();
  const std::size_t bytes = ds->image.size() + (64u << 20);
  fw::Status s = ds->arena->init_mapped(bytes, false, "map");
  if (s.is_ok()) s = fw::load_map_image(ds->image.data(), ds->image.size(), *ds->arena, &ds->map, ds->name.c_str());
  if (!s.is_ok()) return fail(err, std::string("map image of ") + ds->name + ": " + s.message());
  return true;
}

// A compiled map image starts with the magic "MMLFWMAP" (firmware/map/map_image.h).
bool is_map_image_path(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;
  std::ifstream in(path, std::ios::binary);
  char magic[8] = {};
  return in.read(magic, sizeof(magic)) && std::string(magic, sizeof(magic)) == "MMLFWMAP";
}

}  // namespace

namespace {

// Cumulative odometry path length at every scan.
void fill_travelled(LoadedDataset* ds) {
  ds->travelled.clear();
  double acc = 0;
  for (std::size_t i = 0; i < ds->odometry.size(); ++i) {
    if (i > 0) acc += std::hypot(ds->odometry[i].x - ds->odometry[i - 1].x, ds->odometry[i].y - ds->odometry[i - 1].y);
    ds->travelled.push_back(acc);
  }
}

// Relations whose timestamps are scan ipc timestamps of the log: check the reference (and say so).
void check_reference_file(LoadedDataset* ds, const std::string& relations_path) {
  std::vector<Relation> rel;
  std::string e;
  if (!read_relations(relations_path, &rel, &e)) {
    ds->ref_check_note = "reference not checked: " + e;
    return;
  }
  check_reference_against_relations(ds, rel);
}

}  // namespace

std::size_t check_reference_against_relations(LoadedDataset* ds, const std::vector<Relation>& relations,
                                              double max_dt_s, double tol_m, double tol_rad) {
  const std::size_t n = ds->log.scans.size();
  ds->ref_unreliable.assign(n, 0);
  // Scan index by ipc timestamp (µs; intel's timestamps are not monotonic).
  std::unordered_map<long long, std::size_t> by_t;
  for (std::size_t i = 0; i < n; ++i) by_t.emplace(std::llround(ds->log.scans[i].ipc_timestamp * 1e6), i);
  auto find = [&](double t) -> std::size_t {
    const long long k = std::llround(t * 1e6);
    for (long long d : {0LL, -1LL, 1LL}) {
      auto it = by_t.find(k + d);
      if (it != by_t.end()) return it->second;
    }
    return TrialResult::kNone;
  };
  std::size_t checked = 0, bad = 0;
  for (const Relation& r : relations) {
    if (std::fabs(r.t2 - r.t1) > max_dt_s) continue;
    const std::size_t a = find(r.t1), b = find(r.t2);
    if (a == TrialResult::kNone || b == TrialResult::kNone || a >= ds->reference.size() || b >= ds->reference.size())
      continue;
    ++checked;
    const fw::Se2d e = r.delta.between(ds->reference[a].between(ds->reference[b]));
    if (std::hypot(e.x, e.y) > tol_m || std::fabs(fw::wrap_angle(e.theta)) > tol_rad) {
      ++bad;
      for (std::size_t i = std::min(a, b); i <= std::max(a, b); ++i) ds->ref_unreliable[i] = 1;
    }
  }
  ds->ref_excluded_scans = 0;
  for (auto u : ds->ref_unreliable) ds->ref_excluded_scans += u;
  char buf[256];
  std::snprintf(buf, sizeof(buf),
                "reference checked against %zu relations (|dt| <= %.0f s): %zu disagree by > %.2f m / %.1f deg, %zu of %zu "
                "scans excluded from error metrics",
                checked, max_dt_s, bad, tol_m, tol_rad * 180.0 / 3.14159265358979, ds->ref_excluded_scans, n);
  ds->ref_check_note = buf;
  return checked;
}

namespace {
// Reference at every scan and its own error bounds (sim/io/reference_trajectory.h). Extrapolated
// scans (before the first / after the last corrected pose) have no bound: 0 is used there, which
// counts every error against the localizer.
void set_reference(LoadedDataset* ds, const std::vector<CorrectedPose>& cp) {
  ds->reference.clear();
  ds->ref_bound_m.clear();
  ds->ref_bound_rad.clear();
  for (const ReferencePose& r : reference_with_bounds(ds->log, cp)) {
    ds->reference.push_back(r.pose);
    ds->ref_bound_m.push_back(std::isfinite(r.bound) ? r.bound : 0.0);
    ds->ref_bound_rad.push_back(std::isfinite(r.bound_theta) ? r.bound_theta : 0.0);
  }
}
}  // namespace

bool load_dataset(const std::string& name, LoadedDataset* ds, std::string* err) {
  const Dataset* d = find_dataset(name);
  if (d == nullptr || (d->raw_log.empty() && d->corrected_log.empty())) {
    std::string known;
    for (const Dataset& k : datasets()) {
      if (!k.raw_log.empty() || !k.corrected_log.empty()) known += (known.empty() ? "" : ", ") + k.name;
    }
    return fail(err, "unknown dataset or no log: '" + name + "' (known: " + known + ")");
  }
  ds->name = name;
  ds->key = name;
  std::replace(ds->key.begin(), ds->key.end(), '-', '_');
  ds->success_bound_m = name == "mit-killian" ? 1.0 : 0.5;
  std::string e;
  if (d->raw_log.empty()) {
    // fr101, fr-campus: only the corrected log. Reference = its (laser) poses — the map's frame;
    // odometry synthesised from the pose increments (documented noise model, seed 1).
    if (!read_carmen_log(data_path(d->corrected_log), CarmenReadOptions{}, &ds->log, &e)) return fail(err, e);
    ds->reference.clear();
    for (const auto& s : ds->log.scans) ds->reference.push_back(s.pose);
    ds->reference_note = "corrected log poses (no raw log); odometry synthesised (synthesize_odometry, seed 1)";
    ds->odometry = synthesize_odometry(ds->reference, 1);
    ds->synthetic_odometry = true;
    ds->ref_check_note = "reference not checked: no benchmark relations for this dataset";
    fill_travelled(ds);
    if (!ensure_global_map(name, -1.0, map_cache_dir(), &ds->ros, &e)) return fail(err, e);
    if (!ros_map_to_grid(ds->ros, &ds->grid, &e)) return fail(err, e);
    if (!read_file_bytes(global_map_image_path(name), &ds->image, &e)) return fail(err, e);
    return load_image(ds, err);
  }
  if (!read_carmen_log(data_path(d->raw_log), CarmenReadOptions{}, &ds->log, &e)) return fail(err, e);
  const bool robotlaser = !ds->log.scans.empty() && ds->log.scans[0].type == "ROBOTLASER1";
  if (!d->corrected_poses.empty()) {
    std::vector<CorrectedPose> cp;
    if (!read_corrected_poses(data_path(d->corrected_poses), &cp, &e)) return fail(err, e);
    set_reference(ds, cp);
    ds->reference_note = "corrected poses chained with odometry (sim/io/reference_trajectory.h)";
  }
  bool from_relations = false;
  if (ds->reference.empty() && !d->relations.empty()) {
    // fr-clinic: no corrected log. Its global map is built from the pose graph of the benchmark
    // relations (sim/map/global_maps.h), so the reference is that graph's robot poses chained with
    // odometry to every scan, moved to the laser by the log's mount offset — the map's own frame.
    // (The raw laser poses drift up to ~13 m from it and made correct estimates count as failures.)
    std::vector<std::size_t> idx;
    std::vector<fw::Se2d> robot;
    std::string report;
    if (relation_graph_trajectory(name, ds->log, &idx, &robot, &report, &e)) {
      std::vector<CorrectedPose> cp(idx.size());
      for (std::size_t k = 0; k < idx.size(); ++k) {
        cp[k].flaser_index = ds->log.scans[idx[k]].index;
        cp[k].ipc_timestamp = ds->log.scans[idx[k]].ipc_timestamp;
        cp[k].pose = robot[k];
      }
      set_reference(ds, cp);
      for (std::size_t i = 0; i < ds->reference.size() && robotlaser; ++i) {
        const auto& s = ds->log.scans[i];
        ds->reference[i] = ds->reference[i].compose(s.odom.between(s.pose));
      }
      ds->reference_note = "pose graph of the benchmark relations chained with odometry (as the map)";
      from_relations = true;
    } else {
      std::fprintf(stderr, "mml-eval: %s: relation graph: %s; falling back to the raw laser poses\n", name.c_str(),
                   e.c_str());
    }
  }
  if (ds->reference.empty()) {
    // No corrected log and no usable relations: the raw laser poses.
    for (const auto& s : ds->log.scans) ds->reference.push_back(s.pose);
    ds->reference_note = "raw laser poses (no corrected log, no relation graph)";
  }
  ds->odometry.clear();
  for (std::size_t i = 0; i < ds->log.scans.size(); ++i) {
    const auto& s = ds->log.scans[i];
    // ROBOTLASER1: the laser pose is the map frame's pose (map built from it); FLASER: odometry.
    ds->odometry.push_back(robotlaser ? s.pose : s.odom);
  }
  fill_travelled(ds);
  if (!d->relations.empty() && d->relations_match_log && !from_relations) {
    check_reference_file(ds, data_path(d->relations));
  } else if (from_relations) {
    ds->ref_check_note = "reference not checked: it is built from the relations themselves (circular)";
  } else {
    ds->ref_check_note = "reference not checked: the relations' timestamps are not the log's";
  }
  if (!ensure_global_map(name, -1.0, map_cache_dir(), &ds->ros, &e)) return fail(err, e);
  if (!ros_map_to_grid(ds->ros, &ds->grid, &e)) return fail(err, e);
  if (!read_file_bytes(global_map_image_path(name), &ds->image, &e)) return fail(err, e);
  return load_image(ds, err);
}

bool load_dataset_files(const DatasetFiles& f, LoadedDataset* ds, std::string* err) {
  namespace fs = std::filesystem;
  if (f.log.empty()) return fail(err, "mml-eval: --log is required");
  if (f.map_yaml.empty()) return fail(err, "mml-eval: --map is required");
  if (f.reference.empty()) return fail(err, "mml-eval: --reference is required");
  for (const std::string* p : {&f.log, &f.map_yaml, &f.reference, &f.relations}) {
    if (!p->empty() && !fs::exists(*p)) return fail(err, "mml-eval: " + *p + ": file not found");
  }
  ds->name = f.name.empty() ? "custom" : f.name;
  ds->key = ds->name;
  for (char& c : ds->key)
    if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
  ds->success_bound_m = 0.5;
  std::string e;
  if (!read_carmen_log(f.log, CarmenReadOptions{}, &ds->log, &e)) return fail(err, "mml-eval: log " + e);
  if (ds->log.scans.empty()) return fail(err, "mml-eval: " + f.log + ": no laser scans (FLASER/ROBOTLASER1) in the log");
  // Reference: corrected-poses rows, or a CARMEN log with a pose per scan.
  std::vector<CorrectedPose> cp;
  std::string e_rows;
  if (read_corrected_poses(f.reference, &cp, &e_rows)) {
    if (cp.empty()) return fail(err, "mml-eval: " + f.reference + ": no reference poses");
    if (cp.front().flaser_index >= ds->log.scans.size()) {
      return fail(err, "mml-eval: " + f.reference + ": first flaser_index " + std::to_string(cp.front().flaser_index) +
                           " is beyond the log's " + std::to_string(ds->log.scans.size()) + " scans (" + f.log + ")");
    }
    set_reference(ds, cp);
    ds->reference_note = "corrected poses " + f.reference + " chained with odometry";
  } else {
    CarmenLog ref;
    std::string e_log;
    if (!read_carmen_log(f.reference, CarmenReadOptions{}, &ref, &e_log) || ref.scans.empty()) {
      return fail(err, "mml-eval: " + f.reference +
                           ": neither 'flaser_index ipc_timestamp logger_timestamp x y theta' rows (" + e_rows +
                           ") nor a CARMEN log with laser scans" + (e_log.empty() ? "" : " (" + e_log + ")"));
    }
    if (ref.scans.size() != ds->log.scans.size()) {
      return fail(err, "mml-eval: " + f.reference + ": CARMEN reference has " + std::to_string(ref.scans.size()) +
                           " scans but " + f.log + " has " + std::to_string(ds->log.scans.size()) +
                           " (a CARMEN reference needs one pose per scan; otherwise give flaser_index rows)");
    }
    for (const auto& s : ref.scans) ds->reference.push_back(s.pose);
    ds->reference_note = "laser poses of the CARMEN log " + f.reference;
  }
  if (ds->reference.size() != ds->log.scans.size())
    return fail(err, "mml-eval: " + f.reference + ": no usable reference poses for " + f.log);
  const bool robotlaser = ds->log.scans[0].type == "ROBOTLASER1";
  if (f.synthetic_odometry) {
    ds->odometry = synthesize_odometry(ds->reference, f.odometry_seed);
    ds->synthetic_odometry = true;
  } else {
    for (const auto& s : ds->log.scans) ds->odometry.push_back(robotlaser ? s.pose : s.odom);
  }
  fill_travelled(ds);
  if (ds->travelled.back() <= 0.0) {
    return fail(err, "mml-eval: " + f.log + ": the odometry never moves (no ODOM data?); use --synthetic-odometry");
  }
  if (!f.relations.empty()) {
    std::vector<Relation> rel;
    if (!read_relations(f.relations, &rel, &e)) return fail(err, "mml-eval: relations " + e);
    if (check_reference_against_relations(ds, rel) == 0) {
      return fail(err, "mml-eval: " + f.relations + ": no relation's timestamps are scan ipc timestamps of " + f.log);
    }
  } else {
    ds->ref_check_note = "reference not checked: no --relations given";
  }
  if (is_map_image_path(f.map_yaml)) {
    // A compiled map image (mml-mapc, mml-mapbuild): used as it is, relation table included; the
    // host grid (pictures, MCL) from its occupancy.
    if (!read_file_bytes(f.map_yaml, &ds->image, &e)) return fail(err, "mml-eval: map " + e);
    if (!load_image(ds, &e)) return fail(err, "mml-eval: " + f.map_yaml + ": " + e);
    ds->grid.geometry = ds->map.geometry;
    ds->grid.cells.assign(ds->grid.geometry.cell_count(), fw::kCellUnknown);
    for (std::uint32_t cy = 0; cy < ds->grid.geometry.height; ++cy) {
      for (std::uint32_t cx = 0; cx < ds->grid.geometry.width; ++cx) {
        ds->grid.cells[ds->grid.geometry.index(cx, cy)] =
            ds->map.cell(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy));
      }
    }
    ds->ros = grid_to_ros_map(ds->grid, ds->name + ".pgm");
    return true;
  }
  if (!read_ros_map(f.map_yaml, &ds->ros, &e)) return fail(err, "mml-eval: map " + e);
  if (!ros_map_to_grid(ds->ros, &ds->grid, &e)) return fail(err, "mml-eval: " + f.map_yaml + ": " + e);
  if (!compile_map_image(ds->ros, &ds->image, &e)) return fail(err, "mml-eval: " + f.map_yaml + ": " + e);
  return load_image(ds, err);
}

bool erase_region(LoadedDataset* ds, double x0, double y0, double x1, double y1, std::string* err) {
  const fw::GridGeometry& g = ds->grid.geometry;
  for (std::uint32_t cy = 0; cy < g.height; ++cy) {
    for (std::uint32_t cx = 0; cx < g.width; ++cx) {
      const fw::Point2f c = g.cell_center(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy));
      if (c.x() >= x0 && c.x() <= x1 && c.y() >= y0 && c.y() <= y1) ds->grid.cells[g.index(cx, cy)] = fw::kCellUnknown;
    }
  }
  MapImageWriter w;
  std::string e;
  if (!w.set_grid(ds->grid, &e)) return fail(err, e);
  ds->image = w.bytes();
  ds->ros = grid_to_ros_map(ds->grid, ds->name + "-erased.pgm");
  return load_image(ds, err);
}

bool prepare_unknown_area(const std::string& name, std::uint64_t seed, std::size_t trials, UnknownArea* out,
                          std::string* err) {
  LoadedDataset* ds = &out->ds;
  double* region = out->region;
  std::vector<std::size_t>* starts = &out->starts;
  if (!load_dataset(name, ds, err)) return false;
  fw::RandomStream rng(seed, 991);
  const std::size_t n = ds->log.scans.size();
  const std::size_t c = n / 4 + rng.uniform_index(static_cast<std::uint32_t>(n / 2));
  const fw::Se2d rc = ds->reference[c];
  const double half = 4.0;
  region[0] = rc.x - half;
  region[1] = rc.y - half;
  region[2] = rc.x + half;
  region[3] = rc.y + half;
  if (!erase_region(ds, region[0], region[1], region[2], region[3], err)) return false;
  starts->clear();
  for (std::size_t k = 0; k < trials; ++k) {
    const double back = 8.0 + 10.0 * static_cast<double>(k);
    std::size_t s = c;
    while (s > 0 && ds->travelled[c] - ds->travelled[s] < back) --s;
    starts->push_back(s);
  }
  return true;
}

std::vector<std::size_t> draw_starts(const LoadedDataset& ds, std::size_t count, std::uint64_t seed,
                                     const TrialOptions& opt) {
  // Leave room for the trial: a start needs roughly max_steps·min_move metres of log after it.
  const double need = std::min(opt.max_metres, static_cast<double>(opt.max_steps) * opt.min_move_m);
  const double total = ds.travelled.empty() ? 0.0 : ds.travelled.back();
  std::size_t last = 0;
  for (std::size_t i = 0; i < ds.travelled.size(); ++i) {
    if (ds.travelled[i] <= total - need) last = i;
  }
  fw::RandomStream rng(seed, 77);
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < count; ++k) out.push_back(last > 0 ? rng.uniform_index(static_cast<std::uint32_t>(last)) : 0);
  return out;
}

const ReferenceMapFit& LoadedDataset::reference_map_fit(std::size_t scan) const {
  auto it = ref_map_checks.find(scan);
  if (it != ref_map_checks.end()) return it->second;
  return ref_map_checks.emplace(scan, check_reference_against_map(map, log.scans[scan], reference[scan])).first->second;
}

namespace {

// The odometry fed to the localizer along one trial: shift ⊕ log odometry, where the shift changes
// only at a kidnap (continuity: the wheels do not see the carrying).
struct OdometryFeed {
  fw::Se2d last_used;  // last odometry fed (after the kidnap shift)
  bool have_last = false;
  fw::Se2d shift = fw::Se2d(0, 0, 0);
  std::size_t segment = 0, seg_steps = 0;  // segment 1: after the kidnap
  double travelled_base = 0;               // travelled = travelled_base + ds.travelled[i]
};

// Running count of the localized steps: the current unbroken run and the error sum for the mean.
struct LocalizedTally {
  std::size_t run = 0;
  double err_sum = 0;
  std::size_t err_n = 0;
};

// A kidnap happens once, in the first segment: at step `kidnap_at_step`, or `kidnap_after_fix_steps`
// steps after the first fix.
bool kidnap_due(const TrialResult& tr, const OdometryFeed& feed, const TrialOptions& opt) {
  return feed.segment == 0 && ((opt.kidnap_at_step > 0 && tr.steps.size() == opt.kidnap_at_step) ||
                               (opt.kidnap_after_fix_steps > 0 && tr.localized &&
                                tr.steps.size() == tr.steps_to_localize + opt.kidnap_after_fix_steps));
}

// Kidnap: carry the robot from scan `from` to scan j, another part of the log. The new segment's
// odometry is shifted so that its first scan sits exactly at the last fed odometry pose: zero
// odometry delta at the jump.
void kidnap(const LoadedDataset& ds, std::size_t from, std::size_t j, OdometryFeed* feed, TrialResult* tr) {
  tr->kidnap_scan_from = from;
  tr->kidnap_travelled = tr->steps.empty() ? 0.0 : tr->steps.back().travelled;
  feed->shift = (feed->have_last ? feed->last_used : ds.odometry[j]).compose(ds.odometry[j].inverse());
  feed->travelled_base = tr->kidnap_travelled - ds.travelled[j];
  feed->segment = 1;
  feed->seg_steps = 0;
  tr->kidnap_step = tr->steps.size();
}

// A scan is a step once the fed odometry moved or turned enough since the last one (the same rule
// for every system).
bool moved_enough(const OdometryFeed& feed, const fw::Se2d& od, const TrialOptions& opt) {
  if (!feed.have_last) return true;
  const double dm = std::hypot(od.x - feed.last_used.x, od.y - feed.last_used.y);
  const double dt = std::fabs(fw::wrap_angle(od.theta - feed.last_used.theta));
  return !(dm < opt.min_move_m && dt < opt.min_turn_rad);
}

// mml-track's inline global steps so far, ms (their GlobalContext clock: OwnedLocalizer::make sets it);
// 0 for any other localizer.
double inline_global_ms(fw::Localizer& loc) {
  auto* owned = dynamic_cast<OwnedLocalizer*>(&loc);
  fw::track::TrackedLocalizer* t = owned != nullptr ? owned->tracked() : nullptr;
  if (t == nullptr || t->global_context().threaded()) return 0.0;
  return static_cast<double>(t->global_context().perf_step().total_ns()) * 1e-6;
}

// One localizer step on scan i with the fed odometry od; *step_ms is its wall time.
fw::Status step_localizer(fw::Localizer& loc, const LoadedDataset& ds, std::size_t i, const fw::Se2d& od,
                          hal::PoseEstimate* est, double* step_ms) {
  static hal::LaserScan scan;
  const std::uint64_t ts = static_cast<std::uint64_t>(std::llround(ds.log.scans[i].ipc_timestamp * 1e9));
  scan = to_laser_scan(ds.log.scans[i], ts);
  scan.scan_id = static_cast<std::uint32_t>(i);
  hal::Odometry o;
  o.timestamp_ns = ts;
  o.x = static_cast<float>(od.x);
  o.y = static_cast<float>(od.y);
  o.theta = static_cast<float>(od.theta);
  const auto t0 = std::chrono::steady_clock::now();
  const fw::Status s = loc.step(scan, o, est);
  const auto t1 = std::chrono::steady_clock::now();
  *step_ms = std::chrono::duration<double, std::milli>(t1 - t0).count();
  return s;
}

// The step as published, with its error against the log reference.
StepLog make_step_log(const LoadedDataset& ds, std::size_t i, const hal::PoseEstimate& est, const fw::Se2d& od,
                      std::size_t segment, double travelled, double step_ms,
                      const std::function<std::size_t()>& matched_points) {
  StepLog st;
  st.scan = i;
  st.map_err_m = st.map_err_rad = std::numeric_limits<double>::quiet_NaN();
  st.segment = segment;
  st.odom = od;
  if (matched_points) st.matched_points = matched_points();
  st.travelled = travelled;
  st.status = est.status;
  st.mode = est.mode;
  st.step_ms = step_ms;
  st.estimate = fw::Se2d(est.x, est.y, est.theta);
  st.truth = ds.reference[i];
  st.ref_ok = !ds.reference_unreliable(i);
  st.pl_xy = est.protection_xy_m;
  st.pl_theta = est.protection_theta_rad;
  st.unsupported_steps = est.unsupported_steps;
  st.reason = est.reason;
  // Searching / fault: the published pose is a placeholder (no pose); never compare it.
  st.has_pose = est.status != hal::LocalizationStatus::kSearching && est.status != hal::LocalizationStatus::kFault;
  if (st.has_pose) {
    st.err_m = std::hypot(est.x - st.truth.x, est.y - st.truth.y);
    st.err_rad = std::fabs(fw::wrap_angle(static_cast<double>(est.theta) - st.truth.theta));
  } else {
    st.err_m = st.err_rad = std::numeric_limits<double>::quiet_NaN();
  }
  return st;
}

// A failure or PL exceedance must hold against the log reference AND the map's pose for this scan
// (reference_map_check.h); a step where the map clears the estimate is excluded and counted.
void judge_against_map(const LoadedDataset& ds, std::size_t i, const hal::PoseEstimate& est, StepLog* st) {
  if (!(st->has_pose && st->ref_ok && est.status == hal::LocalizationStatus::kLocalized)) return;
  const double bound_rad = 5.0 * 3.14159265358979 / 180.0;
  // The log reference is itself off by up to its bound (closure residual, reference_trajectory.h):
  // an error counts against the localizer only beyond the limit plus that bound.
  const double rb_m = ds.reference_bound_m(i), rb_rad = ds.reference_bound_rad(i);
  const double pl_m = st->pl_xy, pl_rad = st->pl_theta;
  JudgedError je;  // against the log reference alone first: the map is asked only beyond a limit
  je.ref_m = st->err_m;
  je.ref_ang = st->err_rad;
  if (!(beyond_reference(je, ds.success_bound_m, bound_rad) || beyond_reference(je, pl_m, pl_rad))) return;
  const ReferenceMapFit& f = ds.reference_map_fit(i);
  const double em = std::hypot(est.x - f.best.x, est.y - f.best.y);
  const double er = std::fabs(fw::wrap_angle(static_cast<double>(est.theta) - f.best.theta));
  st->map_err_m = em;
  st->map_err_rad = er;
  st->ref_bound_m = rb_m;
  st->ref_bound_rad = rb_rad;
  // One rule with mml-sim (reference_map_check.h), per criterion: the step is kept while either
  // (integrity limits, protection level) is judged beyond, and only that one counts — a failure
  // the map confirms is never dropped because the map clears the other — and excluded, counted,
  // otherwise.
  je.bound_m = rb_m;
  je.bound_ang = rb_rad;
  je.map_improves = f.improves;
  je.map_m = em;
  je.map_ang = er;
  st->integrity_cleared = !judged_beyond(je, ds.success_bound_m, bound_rad);
  st->pl_cleared = !judged_beyond(je, pl_m, pl_rad);
  const bool judged = !st->integrity_cleared || !st->pl_cleared;
  const bool beyond_ref = beyond_reference(je, ds.success_bound_m, bound_rad) || beyond_reference(je, pl_m, pl_rad);
  if (!judged && beyond_ref) {
    st->ref_ok = false;
    st->ref_map_contradicted = true;
  } else if (!beyond_ref) {
    st->ref_ok = false;  // within the reference's own error bound of the limits: cannot be judged
    st->ref_within_bound = true;
  }
}

// MML_EVAL_TRACE: one line per step (n: steps so far).
void trace_step(std::size_t n, std::size_t i, const hal::PoseEstimate& est, const StepLog& st) {
  std::printf("    step %3zu scan %5zu %-11s %-18s %s est (%.2f %.2f %.2f) ref (%.2f %.2f %.2f) err %.2f m %.1f deg  hyp %u cl %u r %.2f PL %.2f m %.1f deg %.1f ms\n",
              n, i, hal::status_name(est.status), hal::reason_name(est.reason),
              est.mode == hal::LocalizationMode::kTracking ? "T" : "G", est.x, est.y, est.theta, st.truth.x,
              st.truth.y, st.truth.theta, st.err_m, st.err_rad * 57.2958, est.hypothesis_count, est.cluster_count,
              est.rating, est.protection_xy_m, est.protection_theta_rad * 57.2958, st.step_ms);
}

// Counts a recorded step: the first fix (steps, metres, right or wrong), a wrong fix before the
// kidnap as a failure, the error for the mean. True when the trial is settled and stops here.
bool tally_step(const StepLog& st, const LoadedDataset& ds, const TrialOptions& opt, LocalizedTally* tally,
                TrialResult* tr) {
  if (st.status != hal::LocalizationStatus::kLocalized) {
    tally->run = 0;
    return false;
  }
  const bool ok = !st.ref_ok || st.integrity_cleared || (st.err_m < ds.success_bound_m && st.err_rad < ds.success_bound_rad);
  if (!tr->localized) {
    tr->localized = true;
    tr->steps_to_localize = tr->steps.size();
    tr->metres_to_localize = st.travelled;
    tr->success = ok;
  }
  if (!ok && st.segment == 0) tr->failure = true;
  tally->err_sum += st.err_m;
  ++tally->err_n;
  ++tally->run;
  return opt.stop_after_localized && tally->run >= opt.settle_steps;
}

}  // namespace

TrialResult run_trial(fw::Localizer& loc, const LoadedDataset& ds, std::size_t start, const TrialOptions& opt,
                      const double* region, const std::function<std::size_t()>& matched_points) {
  TrialResult tr;
  tr.start = start;
  loc.reset();
  OdometryFeed feed;
  feed.travelled_base = -ds.travelled[start];
  LocalizedTally tally;
  const std::size_t cap = opt.max_steps == 0 ? static_cast<std::size_t>(-1) : opt.max_steps;
  for (std::size_t i = start; i < ds.log.scans.size() && tr.steps.size() < cap; ++i) {
    if (kidnap_due(tr, feed, opt)) {
      const std::size_t from = tr.steps.empty() ? start : tr.steps.back().scan;
      const std::size_t target = opt.kidnap_target ? opt.kidnap_target(from) : opt.kidnap_to_scan;
      if (target < ds.log.scans.size()) {
        kidnap(ds, from, target, &feed, &tr);
        i = target;
      }
    }
    if (feed.segment == 1 && opt.kidnap_steps_after > 0 && feed.seg_steps >= opt.kidnap_steps_after) break;
    const fw::Se2d od = feed.shift.compose(ds.odometry[i]);
    if (!moved_enough(feed, od, opt)) continue;
    const double travelled = feed.travelled_base + ds.travelled[i];
    if (travelled > opt.max_metres) break;
    feed.last_used = od;
    feed.have_last = true;
    hal::PoseEstimate est;
    double step_ms = 0;
    const double global_before_ms = inline_global_ms(loc);
    const fw::Status s = step_localizer(loc, ds, i, od, &est, &step_ms);
    if (!s.is_ok()) {
      tr.error = std::string("scan ") + std::to_string(i) + ": " + s.message();
      break;
    }
    ++feed.seg_steps;
    StepLog st = make_step_log(ds, i, est, od, feed.segment, travelled, step_ms, matched_points);
    st.global_ms = inline_global_ms(loc) - global_before_ms;
    judge_against_map(ds, i, est, &st);
    if (region) {
      st.in_region = st.truth.x >= region[0] && st.truth.x <= region[2] && st.truth.y >= region[1] && st.truth.y <= region[3];
    }
    if (!ds.reference_unreliable(i)) {
      const UnmappedScan u = unmapped_scan(ds.map, ds.log.scans[i], ds.reference[i]);
      st.ref_unmapped = in_unmapped_area(u);
      st.ref_off_map = reference_off_map(u);
    }
    tr.steps.push_back(st);
    if (std::getenv("MML_EVAL_TRACE")) trace_step(tr.steps.size(), i, est, st);
    if (tally_step(st, ds, opt, &tally, &tr)) break;
  }
  if (tr.failure) tr.success = false;
  tr.mean_err_localized = tally.err_n ? tally.err_sum / tally.err_n : std::numeric_limits<double>::quiet_NaN();
  return tr;
}

TrialMetrics trial_metrics(const TrialResult& t, const MetricBounds& b) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  TrialMetrics m;
  m.steps = t.steps.size();
  m.m_to_fix = nan;
  m.kidnap_delay_steps = nan;
  m.refix_m = nan;
  const std::size_t kid = t.kidnap_step;
  auto is_loc = [](const StepLog& s) { return s.status == hal::LocalizationStatus::kLocalized; };
  // Error-checkable: a localized pose with a reliable reference and a real error.
  auto checkable = [&](const StepLog& s) { return is_loc(s) && s.ref_ok && s.has_pose && std::isfinite(s.err_m); };
  auto wrong = [&](const StepLog& s) { return s.err_m > b.bound_m || s.err_rad > b.bound_rad; };
  const std::size_t pre = std::min(kid, t.steps.size());  // steps before the kidnap
  // First fix: the first `localized` (before any kidnap) within the window; its correctness is judged
  // at the first localized step from there on with a reliable reference, still within the window.
  for (std::size_t k = 0; k < pre && k < b.fix_within_steps; ++k) {
    if (!is_loc(t.steps[k])) continue;
    m.first_fix = true;
    m.first_fix_index = k;
    m.m_to_fix = t.steps[k].travelled;
    for (std::size_t j = k; j < pre && j < b.fix_within_steps; ++j) {
      if (checkable(t.steps[j])) {
        m.first_fix_success = !integrity_beyond(t.steps[j], b.bound_m, b.bound_rad);
        break;
      }
    }
    break;
  }
  // Availability counts from the first `localized` even when it came after the first-fix window.
  std::size_t first_loc = m.first_fix ? m.first_fix_index : TrialResult::kNone;
  for (std::size_t k = 0; k < pre && first_loc == TrialResult::kNone; ++k)
    if (is_loc(t.steps[k])) first_loc = k;
  if (first_loc != TrialResult::kNone) {
    for (std::size_t k = first_loc + 1; k < pre; ++k) {
      if (t.steps[k].in_region) continue;
      if (t.steps[k].ref_unmapped) {
        ++m.unmapped_steps;
        m.unmapped_localized += is_loc(t.steps[k]);
        continue;
      }
      ++m.avail_steps;
      m.off_map_steps += t.steps[k].ref_off_map;
      m.off_map_localized += t.steps[k].ref_off_map && is_loc(t.steps[k]);
      if (is_loc(t.steps[k])) {
        ++m.avail_localized;
      } else {
        const auto r = static_cast<std::size_t>(t.steps[k].reason);
        if (r < hal::kStatusReasonCount) ++m.unavailable_by_reason[r];
      }
    }
  }
  // The figures against the log reference alone (`*_vs_log_reference`), beside the judged ones.
  auto count_raw = [&](const StepLog& s) {
    m.integrity_failures_raw += wrong(s);
    if (s.pl_xy > 0.0f || s.pl_theta > 0.0f) {
      ++m.pl_steps_raw;
      m.pl_exceed_raw += (s.pl_xy > 0.0f && s.err_m > s.pl_xy) || (s.pl_theta > 0.0f && s.err_rad > s.pl_theta);
    }
  };
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    const StepLog& s = t.steps[k];
    if (!is_loc(s)) continue;
    if (!checkable(s)) {
      ++m.excluded_ref_steps;
      m.excluded_map_steps += s.ref_map_contradicted;
      m.excluded_bound_steps += s.ref_within_bound;
      if ((s.ref_map_contradicted || s.ref_within_bound) && std::isfinite(s.err_m)) count_raw(s);
      continue;
    }
    count_raw(s);  // a kept step counts against the log reference alone too, whatever the checks cleared
    ++m.localized_steps;
    const bool w = integrity_beyond(s, b.bound_m, b.bound_rad);
    m.integrity_failures += w;
    if (k >= kid) m.kidnap_integrity_failures += w;
    if (s.pl_xy > 0.0f || s.pl_theta > 0.0f) {
      ++m.pl_steps;
      const bool ex_xy = pl_xy_beyond(s);
      const bool ex_th = pl_theta_beyond(s);
      m.pl_exceed += ex_xy || ex_th;
      m.pl_exceed_xy += ex_xy;
      m.pl_exceed_theta += ex_th;
    }
    if (s.mode == hal::LocalizationMode::kTracking) m.track_err.push_back(s.err_m);
  }
  if (kid != TrialResult::kNone && kid < t.steps.size()) {
    m.kidnapped = true;
    for (std::size_t k = kid; k < t.steps.size(); ++k) {
      if (!is_loc(t.steps[k])) {
        m.kidnap_detected = true;
        m.kidnap_delay_steps = static_cast<double>(k - kid);
        break;
      }
    }
    for (std::size_t k = kid; k < t.steps.size() && k - kid < b.refix_within_steps; ++k) {
      if (checkable(t.steps[k]) && !integrity_beyond(t.steps[k], b.bound_m, b.bound_rad)) {
        m.kidnap_refix = true;
        m.refix_m = t.steps[k].travelled - t.kidnap_travelled;
        break;
      }
    }
  }
  return m;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());
  const double idx = p / 100.0 * (v.size() - 1);
  const std::size_t lo = static_cast<std::size_t>(std::floor(idx)), hi = static_cast<std::size_t>(std::ceil(idx));
  return v[lo] + (v[hi] - v[lo]) * (idx - lo);
}

double censored_median(std::vector<double> v) {
  if (v.empty()) return std::numeric_limits<double>::quiet_NaN();
  std::sort(v.begin(), v.end());  // +∞ (never) sorts last
  const std::size_t n = v.size();
  const double m = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  return std::isfinite(m) ? m : std::numeric_limits<double>::quiet_NaN();
}

SystemSummary summarize(const std::string& dataset, const std::string& system, const std::vector<TrialResult>& trials,
                        double memory_mib, const MetricBounds& bounds) {
  SystemSummary s;
  s.dataset = dataset;
  s.system = system;
  s.trials = trials.size();
  s.memory_mib = memory_mib;
  std::vector<double> metres, steps, ms, track_err, track_ms;
  double err_sum = 0;
  std::size_t err_n = 0, region_n = 0, region_out = 0, matched_n = 0;
  double matched_sum = 0;
  for (const auto& t : trials) {
    if (t.localized) {
      ++s.localized;
      metres.push_back(t.metres_to_localize);
      steps.push_back(static_cast<double>(t.steps_to_localize));
    }
    s.successes += t.success;
    s.failures += t.failure;
    for (const auto& st : t.steps) {
      ms.push_back(st.step_ms);
      if (st.matched_points > 0) {
        matched_sum += static_cast<double>(st.matched_points);
        ++matched_n;
      }
      if (st.status == hal::LocalizationStatus::kLocalized && st.ref_ok && std::isfinite(st.err_m)) {
        err_sum += st.err_m;
        ++err_n;
      }
      if (st.mode == hal::LocalizationMode::kTracking && st.ref_ok && std::isfinite(st.err_m)) {
        track_err.push_back(st.err_m);
        track_ms.push_back(st.step_ms);
      }
      if (st.in_region) {
        ++region_n;
        region_out += st.status == hal::LocalizationStatus::kOutsideMap;
      }
      if (st.status == hal::LocalizationStatus::kOutsideMap) {
        ++s.outside_map_steps;
        s.outside_map_false_steps += !st.in_region && !st.ref_unmapped;
      }
    }
  }
  const double n = trials.empty() ? 1.0 : static_cast<double>(trials.size());
  s.success_rate = s.successes / n;
  s.failure_rate = s.failures / n;
  s.m_to_localize_median = percentile(metres, 50);
  s.steps_to_localize_median = percentile(steps, 50);
  s.mean_err_m = err_n ? err_sum / err_n : std::numeric_limits<double>::quiet_NaN();
  s.step_ms_p50 = percentile(ms, 50);
  s.step_ms_p99 = percentile(ms, 99);
  double m = 0;
  for (double x : ms) m += x;
  s.step_ms_mean = ms.empty() ? 0 : m / ms.size();
  s.outside_map_in_region = region_n ? static_cast<double>(region_out) / region_n : std::numeric_limits<double>::quiet_NaN();
  s.matched_points_mean = matched_n ? matched_sum / matched_n : std::numeric_limits<double>::quiet_NaN();
  s.tracking_err_median_m = percentile(track_err, 50);
  s.tracking_step_ms_p50 = percentile(track_ms, 50);
  s.tracking_step_ms_p99 = percentile(track_ms, 99);
  // Product metrics.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> m_fix, terr, delays, refix_m;
  std::size_t avail_loc = 0;
  for (const auto& t : trials) {
    const TrialMetrics m = trial_metrics(t, bounds);
    s.first_fixes += m.first_fix;
    s.first_fix_successes += m.first_fix_success;
    // Metres to the first *correct* fix: a trial whose first `localized` within the window is wrong
    // (or cannot be judged), or that has none, never fixed — +∞ in the sample (a censored
    // observation). A confidently wrong fix is not a fast fix, and a trial that never fixed is not
    // left out of the median (both flattered one side of the MCL comparison before 2026-11-29).
    m_fix.push_back(m.first_fix_success ? m.m_to_fix : std::numeric_limits<double>::infinity());
    s.avail_steps += m.avail_steps;
    s.unmapped_steps += m.unmapped_steps;
    s.unmapped_localized += m.unmapped_localized;
    s.off_map_steps += m.off_map_steps;
    s.off_map_localized += m.off_map_localized;
    avail_loc += m.avail_localized;
    for (std::size_t r = 0; r < hal::kStatusReasonCount; ++r) s.unavailable_by_reason[r] += m.unavailable_by_reason[r];
    s.localized_checked += m.localized_steps;
    s.integrity_failures += m.integrity_failures;
    s.excluded_ref_steps += m.excluded_ref_steps;
    s.excluded_map_steps += m.excluded_map_steps;
    s.excluded_bound_steps += m.excluded_bound_steps;
    s.integrity_failures_raw += m.integrity_failures_raw;
    s.pl_steps_raw += m.pl_steps_raw;
    s.pl_exceed_raw += m.pl_exceed_raw;
    s.pl_steps += m.pl_steps;
    s.pl_exceed += m.pl_exceed;
    s.pl_exceed_xy += m.pl_exceed_xy;
    s.pl_exceed_theta += m.pl_exceed_theta;
    terr.insert(terr.end(), m.track_err.begin(), m.track_err.end());
    if (m.kidnapped) {
      ++s.kidnaps;
      s.kidnaps_detected += m.kidnap_detected;
      s.kidnap_refixes += m.kidnap_refix;
      s.kidnap_integrity_failures += m.kidnap_integrity_failures;
      // As the first fix: a kidnap never detected, or never re-fixed correctly within the window,
      // stays in the sample as "never" (+∞).
      const double never = std::numeric_limits<double>::infinity();
      delays.push_back(m.kidnap_detected ? m.kidnap_delay_steps : never);
      refix_m.push_back(m.kidnap_refix ? m.refix_m : never);
    }
  }
  s.first_fix_success = trials.empty() ? nan : static_cast<double>(s.first_fix_successes) / trials.size();
  s.m_to_fix_median = censored_median(m_fix);
  s.availability = s.avail_steps ? static_cast<double>(avail_loc) / s.avail_steps : nan;
  const std::size_t with_unmapped = s.avail_steps + s.unmapped_steps;
  s.availability_with_unmapped =
      with_unmapped ? static_cast<double>(avail_loc + s.unmapped_localized) / static_cast<double>(with_unmapped) : nan;
  s.integrity_failure_rate = s.localized_checked ? static_cast<double>(s.integrity_failures) / s.localized_checked : nan;
  s.pl_exceed_rate = s.pl_steps ? static_cast<double>(s.pl_exceed) / s.pl_steps : nan;
  s.track_err_median_m = percentile(terr, 50);
  s.track_err_p95_m = percentile(terr, 95);
  s.kidnap_delay_median = censored_median(delays);
  s.kidnap_refix_m_median = censored_median(refix_m);
  s.kidnap_refix_success = s.kidnaps ? static_cast<double>(s.kidnap_refixes) / s.kidnaps : nan;
  return s;
}

std::string product_markdown_table(const std::vector<SystemSummary>& rows) {
  std::ostringstream o;
  o << "| dataset | system | trials | first-fix success | m to fix (median) | availability | localized steps checked | "
       "integrity failures | PL exceed rate | track err median (m) | track err p95 (m) | kidnaps | kidnap delay "
       "(median steps) | kidnap re-fix success | re-fix m (median) | kidnap integrity failures | excluded (ref: all / map / bound) | step "
       "p50 (ms) | step p99 (ms) |\n";
  o << "|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  char buf[768];
  for (const auto& r : rows) {
    std::snprintf(buf, sizeof(buf),
                  "| %s | %s | %zu | %.2f (%zu/%zu) | %.1f | %.4f | %zu | %zu | %.4f (%zu/%zu) | %.3f | %.3f | %zu | %.0f | "
                  "%.2f | %.1f | %zu | %zu / %zu / %zu | %.2f | %.1f |\n",
                  r.dataset.c_str(), r.system.c_str(), r.trials, r.first_fix_success, r.first_fix_successes, r.trials,
                  r.m_to_fix_median, r.availability, r.localized_checked, r.integrity_failures, r.pl_exceed_rate,
                  r.pl_exceed, r.pl_steps, r.track_err_median_m, r.track_err_p95_m, r.kidnaps, r.kidnap_delay_median,
                  r.kidnap_refix_success, r.kidnap_refix_m_median, r.kidnap_integrity_failures, r.excluded_ref_steps, r.excluded_map_steps, r.excluded_bound_steps,
                  r.step_ms_p50, r.step_ms_p99);
    o << buf;
  }
  return o.str();
}

std::string markdown_table(const std::vector<SystemSummary>& rows) {
  std::ostringstream o;
  o << "| dataset | system | trials | localized | m to localize (median) | success | failure | mean err localized (m) "
       "| step p50 (ms) | step p99 (ms) | memory (MiB) | matched points (mean) |\n";
  o << "|---|---|---|---|---|---|---|---|---|---|---|---|\n";
  char buf[512];
  for (const auto& r : rows) {
    char matched[32] = "-";  // MCL matches no local map
    if (std::isfinite(r.matched_points_mean)) std::snprintf(matched, sizeof(matched), "%.0f", r.matched_points_mean);
    std::snprintf(buf, sizeof(buf), "| %s | %s | %zu | %zu | %.1f | %.2f | %.2f | %.3f | %.1f | %.1f | %.1f | %s |\n",
                  r.dataset.c_str(), r.system.c_str(), r.trials, r.localized, r.m_to_localize_median, r.success_rate,
                  r.failure_rate, r.mean_err_m, r.step_ms_p50, r.step_ms_p99, r.memory_mib, matched);
    o << buf;
  }
  return o.str();
}

namespace {

const char* status_color(hal::LocalizationStatus s, hal::LocalizationMode m) {
  if (m == hal::LocalizationMode::kTracking) return "#1f77b4";
  switch (s) {
    case hal::LocalizationStatus::kLocalized: return "#2ca02c";
    case hal::LocalizationStatus::kAmbiguous: return "#ff7f0e";
    case hal::LocalizationStatus::kOutsideMap: return "#9467bd";
    case hal::LocalizationStatus::kSearching: return "#aaaaaa";
    default: return "#d62728";
  }
}

}  // namespace

bool write_error_plot_png(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials,
                          double bound_m, std::string* err);

bool write_error_plot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials,
                      double bound_m, std::string* err) {
  const double W = 900, H = 420, L = 60, R = 20, T = 40, B = 50;
  double xmax = 1;
  for (const auto& t : trials)
    for (const auto& s : t.steps) xmax = std::max(xmax, s.travelled);
  const double ymax = 5.0;
  auto X = [&](double x) { return L + (W - L - R) * x / xmax; };
  auto Y = [&](double y) { return H - B - (H - T - B) * std::min(y, ymax) / ymax; };
  std::ofstream o(path);
  if (!o) return fail(err, "cannot write " + path);
  o << "<svg xmlns='http://www.w3.org/2000/svg' width='" << W << "' height='" << H << "' font-family='sans-serif' font-size='12'>\n";
  o << "<rect width='100%' height='100%' fill='white'/>\n";
  o << "<text x='" << L << "' y='20' font-size='14'>" << title << "</text>\n";
  o << "<line x1='" << L << "' y1='" << H - B << "' x2='" << W - R << "' y2='" << H - B << "' stroke='black'/>\n";
  o << "<line x1='" << L << "' y1='" << T << "' x2='" << L << "' y2='" << H - B << "' stroke='black'/>\n";
  for (int k = 0; k <= 5; ++k) {
    o << "<text x='" << L - 8 << "' y='" << Y(k) + 4 << "' text-anchor='end'>" << k << "</text>\n";
    o << "<line x1='" << L << "' y1='" << Y(k) << "' x2='" << W - R << "' y2='" << Y(k) << "' stroke='#eee'/>\n";
  }
  const double step = xmax > 100 ? 20 : (xmax > 40 ? 10 : 5);
  for (double x = 0; x <= xmax + 1e-9; x += step) {
    o << "<text x='" << X(x) << "' y='" << H - B + 16 << "' text-anchor='middle'>" << x << "</text>\n";
  }
  o << "<text x='" << (L + W - R) / 2 << "' y='" << H - 10 << "' text-anchor='middle'>metres travelled since the kidnapped start</text>\n";
  o << "<text x='15' y='" << (T + H - B) / 2 << "' transform='rotate(-90 15 " << (T + H - B) / 2
    << ")' text-anchor='middle'>position error (m, clipped at 5)</text>\n";
  o << "<line x1='" << L << "' y1='" << Y(bound_m) << "' x2='" << W - R << "' y2='" << Y(bound_m)
    << "' stroke='#d62728' stroke-dasharray='4 3'/>\n";
  for (const auto& t : trials) {
    o << "<polyline fill='none' stroke='#bbb' stroke-width='1' points='";
    for (const auto& s : t.steps)
      if (std::isfinite(s.err_m)) o << X(s.travelled) << "," << Y(s.err_m) << " ";
    o << "'/>\n";
    for (const auto& s : t.steps) {
      if (!std::isfinite(s.err_m)) continue;  // no pose (searching)
      o << "<circle cx='" << X(s.travelled) << "' cy='" << Y(s.err_m) << "' r='2' fill='" << status_color(s.status, s.mode)
        << "'/>\n";
    }
  }
  const char* names[] = {"searching", "ambiguous", "localized", "outside-map", "tracking (hand-off)"};
  const char* cols[] = {"#aaaaaa", "#ff7f0e", "#2ca02c", "#9467bd", "#1f77b4"};
  for (int k = 0; k < 5; ++k) {
    o << "<circle cx='" << W - 170 << "' cy='" << T + 10 + 16 * k << "' r='4' fill='" << cols[k] << "'/>"
      << "<text x='" << W - 160 << "' y='" << T + 14 + 16 * k << "'>" << names[k] << "</text>\n";
  }
  o << "</svg>\n";
  o.close();
  if (!o) return fail(err, "write failed: " + path);
  // A raster twin (x: metres 0..max, y: error 0..5 m; same colours) for quick viewing.
  std::string png = path;
  if (png.size() > 4 && png.compare(png.size() - 4, 4, ".svg") == 0) png.replace(png.size() - 4, 4, ".png");
  return png == path || write_error_plot_png(png, title, trials, bound_m, err);
}

bool write_error_plot_png(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials,
                          double bound_m, std::string* err) {
  const int W = 900, H = 420, L = 60, R = 20, T = 40, B = 50;
  std::vector<std::uint8_t> rgb(static_cast<std::size_t>(W) * H * 3, 255);
  double xmax = 1;
  for (const auto& t : trials)
    for (const auto& s : t.steps) xmax = std::max(xmax, s.travelled);
  auto X = [&](double x) { return static_cast<int>(L + (W - L - R) * x / xmax); };
  auto Y = [&](double y) { return static_cast<int>(H - B - (H - T - B) * std::min(y, 5.0) / 5.0); };
  auto put = [&](int x, int y, Rgb c) {
    if (x < 0 || y < 0 || x >= W || y >= H) return;
    std::uint8_t* p = &rgb[(static_cast<std::size_t>(y) * W + x) * 3];
    p[0] = c.r; p[1] = c.g; p[2] = c.b;
  };
  // Text with the pictures' 5×7 font (scale 1 or 2), so the PNG reads like the SVG.
  auto text = [&](int x, int y, const std::string& str, int scale, Rgb c) {
    for (char ch : str) {
      const std::uint8_t* g = font5x7_glyph(ch);
      for (int col = 0; col < 5; ++col)
        for (int row = 0; row < 7; ++row)
          if (g[col] & (1u << row))
            for (int sy = 0; sy < scale; ++sy)
              for (int sx = 0; sx < scale; ++sx) put(x + col * scale + sx, y + row * scale + sy, c);
      x += 6 * scale;
    }
  };
  const Rgb black{0, 0, 0};
  text(L, 8, title, 2, black);
  for (int k = 0; k <= 5; ++k) text(L - 14, Y(k) - 3, std::to_string(k), 1, black);
  const double tick = xmax > 100 ? 20 : (xmax > 40 ? 10 : 5);
  for (double x = 0; x <= xmax + 1e-9; x += tick) {
    const std::string lab = std::to_string(static_cast<int>(x));
    text(X(x) - 3 * static_cast<int>(lab.size()), H - B + 6, lab, 1, black);
  }
  text(L + 180, H - 18, "metres travelled since the kidnapped start", 1, black);
  text(4, T - 12, "error (m, clipped at 5)", 1, black);
  const char* names[] = {"searching", "ambiguous", "localized", "outside-map", "tracking (hand-off)"};
  const Rgb cols[] = {{170, 170, 170}, {255, 127, 14}, {44, 160, 44}, {148, 103, 189}, {31, 119, 180}};
  for (int k = 0; k < 5; ++k) {
    for (int dy = -3; dy <= 3; ++dy)
      for (int dx = -3; dx <= 3; ++dx) put(W - 170 + dx, T + 10 + 14 * k + dy, cols[k]);
    text(W - 160, T + 7 + 14 * k, names[k], 1, black);
  }
  for (int k = 0; k <= 5; ++k)
    for (int x = L; x < W - R; ++x) put(x, Y(k), k == 0 ? Rgb{0, 0, 0} : Rgb{230, 230, 230});
  for (int y = T; y <= H - B; ++y) put(L, y, {0, 0, 0});
  for (int x = L; x < W - R; x += 4) put(x, Y(bound_m), {214, 39, 40});
  for (const auto& t : trials) {
    for (const auto& s : t.steps) {
      if (!std::isfinite(s.err_m)) continue;  // no pose (searching)
      Rgb c{170, 170, 170};
      if (s.mode == hal::LocalizationMode::kTracking) c = {31, 119, 180};
      else if (s.status == hal::LocalizationStatus::kLocalized) c = {44, 160, 44};
      else if (s.status == hal::LocalizationStatus::kAmbiguous) c = {255, 127, 14};
      else if (s.status == hal::LocalizationStatus::kOutsideMap) c = {148, 103, 189};
      for (int dy = -2; dy <= 2; ++dy)
        for (int dx = -2; dx <= 2; ++dx) put(X(s.travelled) + dx, Y(s.err_m) + dy, c);
    }
  }
  std::vector<std::uint8_t> png;
  if (!encode_png_rgb(W, H, rgb, &png, err)) return false;
  std::ofstream o(path, std::ios::binary);
  o.write(reinterpret_cast<const char*>(png.data()), static_cast<std::streamsize>(png.size()));
  return static_cast<bool>(o) || fail(err, "write failed: " + path);
}

bool write_map_plot(const std::string& path_svg, const std::string& path_png, const LoadedDataset& ds,
                    const std::string& title, const std::vector<TrialResult>& trials, const double* region,
                    std::string* err) {
  Picture pic;
  pic.title = title;
  pic.map = &ds.grid;
  if (region) pic.boxes.push_back({region[0], region[1], region[2], region[3], {200, 60, 200}, "erased from the map"});
  PointSet loc{{}, {44, 160, 44}, 2.5, "estimate: localized"};
  PointSet trk{{}, {31, 119, 180}, 2.0, "estimate: tracking"};
  PointSet amb{{}, {255, 127, 14}, 1.5, "estimate: ambiguous"};
  PointSet out{{}, {148, 103, 189}, 2.0, "estimate: outside-map"};
  for (std::size_t k = 0; k < trials.size(); ++k) {
    const auto& t = trials[k];
    Polyline pl;
    pl.color = {220, 40, 40};
    pl.width_px = 1.5;
    if (k == 0) pl.label = "true path";
    for (const auto& s : t.steps) pl.points.push_back({s.truth.x, s.truth.y});
    pic.lines.push_back(pl);
    if (!t.steps.empty()) {
      Marker m;
      m.x = t.steps[0].truth.x;
      m.y = t.steps[0].truth.y;
      m.theta = t.steps[0].truth.theta;
      m.color = {220, 40, 40};
      m.text = "start " + std::to_string(k);
      pic.markers.push_back(m);
    }
    for (const auto& s : t.steps) {
      const PicturePoint p{s.estimate.x, s.estimate.y};
      if (s.mode == hal::LocalizationMode::kTracking) trk.points.push_back(p);
      else if (s.status == hal::LocalizationStatus::kLocalized) loc.points.push_back(p);
      else if (s.status == hal::LocalizationStatus::kOutsideMap) out.points.push_back(p);
    }
    if (t.localized) {
      const auto& s = t.steps[t.steps_to_localize - 1];
      Marker m;
      m.x = s.estimate.x;
      m.y = s.estimate.y;
      m.theta = s.estimate.theta;
      m.color = {44, 160, 44};
      char buf[64];
      std::snprintf(buf, sizeof(buf), "localized %.0f m", t.metres_to_localize);
      m.text = buf;
      pic.markers.push_back(m);
    }
  }
  (void)amb;
  pic.point_sets = {loc, trk, out};
  std::string e;
  if (!write_svg(pic, path_svg, &e)) return fail(err, e);
  if (!path_png.empty() && !write_png(pic, path_png, &e)) return fail(err, e);
  return true;
}

}  // namespace sim::mmleval
