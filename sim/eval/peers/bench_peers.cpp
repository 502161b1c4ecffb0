// bench_peers OUT.json (scripts/bench.sh peers; issue 58, item 3): LaMa's Loc2D and AMCL's core,
// built from ../shared/peers (peer_drivers.h), beside mml-track in one process, on the same raw
// CARMEN logs, the same 5 cm maps and the same per-scan reference (sim::mmleval::load_dataset, as
// mml-eval and bench_localize load them). Per dataset D (MMLFW_PEERS_DATASETS, default
// intel,aces,fr079) and system P:
//   lama, amcl       started at the reference pose of the first scan, driven as their ROS nodes
//                    drive them (their update thresholds and defaults; the drivers cite the source);
//   amcl_norecovery  amcl with recovery_alpha_slow/fast 0 (the .cfg's and the wiki's defaults);
//   lama_global, amcl_global   started without a pose: LaMa's triggerGlobalLocalization (its
//                    sampling over the free cells) / AMCL's global localization (pf_init_model, a
//                    uniform spread over the free cells);
//   ours             mml-track as shipped (mml_track_config(3, seed 1), TrackOptions{}), one thread,
//                    switched on anywhere (no start pose) at the first scan, fed every scan.
// Per-scan error = |position of the published pose − reference| at every scan with a reliable
// reference (the peers publish a pose at every scan: the tf of their last update ∘ the scan's
// odometry; ours publishes one only while `localized`, and only those are scored). CPU time is
// the thread's (CLOCK_THREAD_CPUTIME_ID) around each call; the peers run single-threaded, and for
// ours the process CPU over the log is checked against the thread's sum (D_ours_log_cpu_s is the
// larger). Keys in README.md of this folder. Progress lines go to stderr.
#include <time.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "firmware/track/track_options.h"
#include "sim/common/bench_json.h"
#include "sim/common/cli_main.h"
#include "sim/eval/mml_eval/mml_eval.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/eval/peers/peer_drivers.h"
#include "sim/io/carmen_log.h"

namespace {

using sim::mmleval::LoadedDataset;
using sim::mmleval::percentile;

double cpu_now(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}
double thread_cpu() { return cpu_now(CLOCK_THREAD_CPUTIME_ID); }

constexpr double kOffM = 0.5;

struct Figures {
  std::vector<double> err;        // per scored scan (m)
  std::vector<double> update_ms;  // thread CPU per filter update / per step (ours: every scan)
  std::vector<double> track_ms;   // ours: steps in tracking mode
  std::size_t scans = 0, updates = 0, scored = 0, no_pose = 0, over = 0;
  double log_cpu_s = 0;
  double thread_cpu_s = 0;  // ours: the sum of the steps' thread CPU (log_cpu_s: the larger of it and the process CPU)
  // Global runs: the first scan from which every scored scan is within kOffM (npos: never).
  std::size_t settled_scan = static_cast<std::size_t>(-1);
  double first_over_m = std::numeric_limits<double>::quiet_NaN();  // odometry metres at the first scan > 0.5 m off
  double settled_m = std::numeric_limits<double>::quiet_NaN();
};

sim::peers::ScanView view(const sim::CarmenScan& s) {
  sim::peers::ScanView v;
  v.ranges = s.ranges.data();
  v.count = s.ranges.size();
  v.angle_min = s.angle_min;
  v.angle_increment = s.angle_increment;
  v.range_min = 0.01;  // as sim::to_laser_scan gives mml-track
  v.range_max = s.max_range;
  return v;
}

void progress(const LoadedDataset& ds, const char* sys, std::size_t i, double t0) {
  if (i % 2000 == 0 && i > 0) {
    std::fprintf(stderr, "bench_peers: %s %s scan %zu / %zu, %.1f s CPU\n", ds.name.c_str(), sys, i,
                 ds.log.scans.size(), thread_cpu() - t0);
  }
}

// One peer over the whole log: `step` returns the published pose and whether the filter updated.
Figures run_peer(const LoadedDataset& ds, const char* sys, const std::function<sim::peers::StepOut(std::size_t)>& step) {
  Figures f;
  std::vector<char> wrong(ds.log.scans.size(), 0);
  const double t0 = thread_cpu();
  for (std::size_t i = 0; i < ds.log.scans.size(); ++i) {
    const double c0 = thread_cpu();
    const sim::peers::StepOut o = step(i);
    const double c1 = thread_cpu();
    ++f.scans;
    if (o.updated) {
      ++f.updates;
      f.update_ms.push_back(1e3 * (c1 - c0));
    }
    progress(ds, sys, i, t0);
    if (ds.reference_unreliable(i)) continue;
    ++f.scored;
    if (!std::isfinite(o.pose.x)) {
      ++f.no_pose;
      wrong[i] = 1;
      continue;
    }
    const double e = std::hypot(o.pose.x - ds.reference[i].x, o.pose.y - ds.reference[i].y);
    f.err.push_back(e);
    if (e > kOffM) {
      if (f.over == 0) f.first_over_m = ds.travelled[i];
      ++f.over;
      wrong[i] = 1;
    }
  }
  f.log_cpu_s = thread_cpu() - t0;
  std::size_t k = wrong.size();
  while (k > 0 && !wrong[k - 1]) --k;
  if (k < wrong.size()) {
    f.settled_scan = k;
    f.settled_m = ds.travelled[k];
  }
  return f;
}

Figures run_ours(const LoadedDataset& ds, std::string* err) {
  Figures f;
  auto loc = sim::mmleval::OwnedLocalizer::make_track(ds.map, ds.image, sim::mmleval::mml_track_config(3, 1),
                                                     fw::track::TrackOptions{}, 1, err);
  if (!loc) return f;
  loc->reset();
  static hal::LaserScan scan;  // large: not on the stack
  const double t0 = thread_cpu(), p0 = cpu_now(CLOCK_PROCESS_CPUTIME_ID);
  double sum = 0;
  for (std::size_t i = 0; i < ds.log.scans.size(); ++i) {
    const std::uint64_t ts = static_cast<std::uint64_t>(std::llround(ds.log.scans[i].ipc_timestamp * 1e9));
    scan = sim::to_laser_scan(ds.log.scans[i], ts);
    scan.scan_id = static_cast<std::uint32_t>(i);
    hal::Odometry o;
    o.timestamp_ns = ts;
    o.x = static_cast<float>(ds.odometry[i].x);
    o.y = static_cast<float>(ds.odometry[i].y);
    o.theta = static_cast<float>(ds.odometry[i].theta);
    hal::PoseEstimate est;
    const double c0 = thread_cpu();
    const fw::Status s = loc->step(scan, o, &est);
    const double c1 = thread_cpu();
    if (!s.is_ok()) {
      *err = ds.name + " scan " + std::to_string(i) + ": " + s.message();
      return f;
    }
    sum += c1 - c0;
    ++f.scans;
    ++f.updates;
    f.update_ms.push_back(1e3 * (c1 - c0));
    if (est.mode == hal::LocalizationMode::kTracking) f.track_ms.push_back(1e3 * (c1 - c0));
    progress(ds, "ours", i, t0);
    if (ds.reference_unreliable(i)) continue;
    ++f.scored;
    if (est.status != hal::LocalizationStatus::kLocalized) {
      ++f.no_pose;
      continue;
    }
    const double e = std::hypot(est.x - ds.reference[i].x, est.y - ds.reference[i].y);
    f.err.push_back(e);
    if (e > kOffM) ++f.over;
  }
  f.thread_cpu_s = sum;
  f.log_cpu_s = std::max(sum, cpu_now(CLOCK_PROCESS_CPUTIME_ID) - p0);
  return f;
}

void report(sim::BenchJson* json, const std::string& key, const std::string& sys, const Figures& f, bool global) {
  const std::string k = key + "_" + sys;
  json->add(k + "_err_median_m", percentile(f.err, 50));
  json->add(k + "_err_p95_m", percentile(f.err, 95));
  json->add(k + "_err_max_m", f.err.empty() ? std::nan("") : *std::max_element(f.err.begin(), f.err.end()));
  json->add_int(k + "_over_0_5m", static_cast<long long>(f.over));
  if (sys != "ours") json->add(k + "_first_over_0_5m_at_m", f.first_over_m);
  json->add_int(k + "_scored_scans", static_cast<long long>(f.scored));
  json->add_int(k + (sys == "ours" ? "_not_localized_scans" : "_no_pose_scans"), static_cast<long long>(f.no_pose));
  json->add(k + "_update_ms_p50", percentile(f.update_ms, 50));
  json->add(k + "_update_ms_p95", percentile(f.update_ms, 95));
  json->add(k + "_update_ms_max", percentile(f.update_ms, 100));
  if (!global) json->add(k + "_track_ms_p50", sys == "ours" ? percentile(f.track_ms, 50) : percentile(f.update_ms, 50));
  if (sys == "ours") json->add(k + "_track_ms_p99", percentile(f.track_ms, 99));
  json->add(k + "_cpu_per_scan_ms", f.scans ? 1e3 * f.log_cpu_s / static_cast<double>(f.scans) : std::nan(""));
  json->add(k + "_log_cpu_s", f.log_cpu_s);
  json->add_int(k + "_updates", static_cast<long long>(f.updates));
  json->add_int(k + "_scans", static_cast<long long>(f.scans));
  if (global) {
    // Share of scored scans more than 0.5 m off (or with no pose) over the whole log, and where the
    // pose settled within 0.5 m for good (scan, odometry metres; null: it never did).
    json->add(k + "_wrong_rate", f.scored ? static_cast<double>(f.over + f.no_pose) / static_cast<double>(f.scored)
                                           : std::nan(""));
    json->add(k + "_settled_m", f.settled_m);
  }
  std::fprintf(stderr,
               "bench_peers: %-6s %-12s err median %.3f p95 %.3f max %.2f m, >0.5 m %zu, no pose %zu of %zu; "
               "CPU/update p50 %.3f ms (%zu updates / %zu scans), log CPU %.2f s\n",
               key.c_str(), sys.c_str(), percentile(f.err, 50), percentile(f.err, 95),
               f.err.empty() ? std::nan("") : *std::max_element(f.err.begin(), f.err.end()), f.over, f.no_pose,
               f.scored, percentile(f.update_ms, 50), f.updates, f.scans, f.log_cpu_s);
}

sim::peers::GridView grid_view(const LoadedDataset& ds) {
  sim::peers::GridView g;
  g.cells = ds.grid.cells.data();
  g.width = ds.grid.geometry.width;
  g.height = ds.grid.geometry.height;
  g.resolution = ds.grid.geometry.resolution;
  g.origin_x = ds.grid.geometry.origin_x;
  g.origin_y = ds.grid.geometry.origin_y;
  return g;
}

bool run_dataset(const std::string& name, sim::BenchJson* json, std::string* err) {
  LoadedDataset ds;
  std::fprintf(stderr, "bench_peers: loading %s ...\n", name.c_str());
  if (!sim::mmleval::load_dataset(name, &ds, err)) return false;
  const std::string& key = ds.key;
  const double log_s = ds.log.scans.back().ipc_timestamp - ds.log.scans.front().ipc_timestamp;
  json->add(key + "_log_s", log_s);
  json->add_int(key + "_scans", static_cast<long long>(ds.log.scans.size()));
  json->add(key + "_map_resolution_m", ds.grid.geometry.resolution);
  const sim::peers::GridView g = grid_view(ds);
  const sim::peers::Pose start{ds.reference[0].x, ds.reference[0].y, ds.reference[0].theta};
  auto odom = [&ds](std::size_t i) {
    return sim::peers::Pose{ds.odometry[i].x, ds.odometry[i].y, ds.odometry[i].theta};
  };
  {
    std::fprintf(stderr, "bench_peers: %s lama (distance map ...)\n", name.c_str());
    sim::peers::LamaDriver lama(g, sim::peers::LamaDriver::Options{}, 1);
    lama.set_pose(start);
    report(json, key, "lama", run_peer(ds, "lama", [&](std::size_t i) { return lama.step(view(ds.log.scans[i]), odom(i)); }),
           false);
  }
  {
    // AMCL is a particle filter: whether it keeps the track on a log depends on its random draws, so it
    // runs with seeds 1..MMLFW_PEERS_AMCL_SEEDS (default 5); the full figures are seed 1's, and the
    // spread over the seeds is given beside them (D_amcl_over_0_5m_by_seed, D_amcl_lost_seeds).
    const char* env = std::getenv("MMLFW_PEERS_AMCL_SEEDS");
    const int seeds = std::max(1, env ? std::atoi(env) : 5);
    std::string over_by_seed, median_by_seed;
    int lost = 0;
    for (int seed = 1; seed <= seeds; ++seed) {
      std::fprintf(stderr, "bench_peers: %s amcl seed %d (likelihood field ...)\n", name.c_str(), seed);
      sim::peers::AmclDriver amcl(g, sim::peers::AmclDriver::Options{}, seed);
      amcl.set_pose(start);
      const Figures f =
          run_peer(ds, "amcl", [&](std::size_t i) { return amcl.step(view(ds.log.scans[i]), odom(i)); });
      if (seed == 1) report(json, key, "amcl", f, false);
      char buf[64];
      std::snprintf(buf, sizeof buf, "%s%zu", seed > 1 ? "," : "", f.over);
      over_by_seed += buf;
      std::snprintf(buf, sizeof buf, "%s%.3f", seed > 1 ? "," : "", percentile(f.err, 50));
      median_by_seed += buf;
      if (f.over > f.scored / 100) ++lost;  // more than 1 % of the scans off by > 0.5 m
      std::fprintf(stderr, "bench_peers: %s amcl seed %d: %zu scans > 0.5 m, error median %.3f m\n", name.c_str(), seed,
                   f.over, percentile(f.err, 50));
    }
    json->add_int(key + "_amcl_seeds", seeds);
    json->add_string(key + "_amcl_over_0_5m_by_seed", over_by_seed);
    json->add_string(key + "_amcl_err_median_m_by_seed", median_by_seed);
    json->add_int(key + "_amcl_lost_seeds", lost);
  }
  {
    // The same with AMCL's recovery off (recovery_alpha_slow = fast = 0: cfg/AMCL.cfg's defaults and the
    // ROS wiki's; amcl_node.cpp's own param defaults, used above, are 0.001 / 0.1, which inject uniform
    // random particles when the short-term likelihood falls below the long-term one).
    std::fprintf(stderr, "bench_peers: %s amcl_norecovery\n", name.c_str());
    sim::peers::AmclDriver::Options o;
    o.alpha_slow = o.alpha_fast = 0.0;
    sim::peers::AmclDriver amcl(g, o, 1);
    amcl.set_pose(start);
    report(json, key, "amcl_norecovery",
           run_peer(ds, "amcl_norecovery", [&](std::size_t i) { return amcl.step(view(ds.log.scans[i]), odom(i)); }),
           false);
  }
  {
    std::fprintf(stderr, "bench_peers: %s amcl_global\n", name.c_str());
    sim::peers::AmclDriver amcl(g, sim::peers::AmclDriver::Options{}, 1);
    amcl.global_localization();
    report(json, key, "amcl_global",
           run_peer(ds, "amcl_global", [&](std::size_t i) { return amcl.step(view(ds.log.scans[i]), odom(i)); }), true);
  }
  {
    std::fprintf(stderr, "bench_peers: %s lama_global\n", name.c_str());
    sim::peers::LamaDriver lama(g, sim::peers::LamaDriver::Options{}, 1);
    lama.set_pose(sim::peers::Pose{});
    lama.trigger_global_localization();
    report(json, key, "lama_global",
           run_peer(ds, "lama_global", [&](std::size_t i) { return lama.step(view(ds.log.scans[i]), odom(i)); }), true);
  }
  std::fprintf(stderr, "bench_peers: %s ours (mml-track, one thread, switched on anywhere)\n", name.c_str());
  const Figures ours = run_ours(ds, err);
  if (!err->empty()) return false;
  report(json, key, "ours", ours, false);
  json->add(key + "_ours_localized_share",
            ours.scored ? 1.0 - static_cast<double>(ours.no_pose) / static_cast<double>(ours.scored) : std::nan(""));
  json->add(key + "_ours_steps_thread_cpu_s", ours.thread_cpu_s);
  json->add(key + "_ours_log_cpu_share", ours.log_cpu_s / log_s);
  return true;
}

int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_peers OUTPUT.json   (MMLFW_PEERS_DATASETS=intel,aces,fr079)\n");
    return 2;
  }
  std::vector<std::string> names;
  const char* env = std::getenv("MMLFW_PEERS_DATASETS");
  std::stringstream list(env && *env ? env : "intel,aces,fr079");
  for (std::string n; std::getline(list, n, ',');)
    if (!n.empty()) names.push_back(n);
  sim::BenchJson json;
  json.add_string("lama_source", "iris_lama fd60e55 (BSD 3-clause), ../shared/peers");
  json.add_string("amcl_source", "ros-planning/navigation amcl 9ad6441 (LGPL), ../shared/peers");
  for (const std::string& n : names) {
    std::string err;
    if (!run_dataset(n, &json, &err)) {
      std::fprintf(stderr, "bench_peers: %s: %s\n", n.c_str(), err.c_str());
      return 1;
    }
    if (!json.write(argv[1])) return 1;  // partial results survive a later failure
  }
  return json.write(argv[1]) ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  return sim::guarded_main("bench_peers", [&] { return run_main(argc, argv); });
}
