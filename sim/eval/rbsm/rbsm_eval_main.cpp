// mml-rbsm-eval: evaluates RBSM against the ICP baselines and raw odometry on the real logs (issue 4, 15).
//   mml-rbsm-eval odometry DATASET [--seeds N] [--scans N] [--particles N] [--workers N] [--out DIR] [--no-icp]
//   mml-rbsm-eval odometry --log LOG --relations RELATIONS [--name NAME] …   (any building, by path)
//     scan-matcher-only odometry; relations metric (Kümmerle et al. 2009) per seed and mean ± std,
//     overall and split by relation length (≤ 10 s / > 10 s); CPU per scan including the map update;
//     writes DIR/NAME_{rbsm_best,rbsm_worst,icp,odom}.png and trajectories DIR/NAME_odom.txt,
//     DIR/NAME_<icp>.txt and one per seed, DIR/NAME_rbsm_seedNN.txt (mml-carmen eval rescores them).
//   mml-rbsm-eval pairwise DATASET [--pairs N] [--seeds N] [--particles N]
//   --set KEY=VALUE overrides the matcher configuration (max_range, resolution, size_log2, subcell_log2,
//     shrink, accept_ratio, min_iterations, max_iterations, sigma_xy2, sigma_psi2, hill_climbing, mahalanobis,
//     min_translation, min_rotation_deg, icp_max_corr, refine (0: pure Alg. 1), refine_radius, refine_iterations,
//     refine_gate, refine_eigen, refine_score_loss, chain_refined, plicp_max_corr, plicp_kf_dist, plicp_kf_deg, plicp_trim); --no-maps skips the PNGs.
//     consecutive corrected-scan pairs, guess perturbed by N(0, 10 cm, 6°): mean/p95/max errors.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>
#include <vector>

#include "sim/eval/rbsm/rbsm_eval_lib.h"
#include "sim/common/cli_main.h"

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: mml-rbsm-eval odometry DATASET [--seeds N] [--scans N] [--particles N] [--workers N] "
               "[--out DIR] [--no-icp]\n"
               "       mml-rbsm-eval odometry --log LOG --relations RELATIONS [--name NAME] [options as above]\n"
               "       mml-rbsm-eval pairwise DATASET [--pairs N] [--seeds N] [--particles N]\n");
  return 2;
}

double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return v.empty() ? NAN : s / v.size();
}
double stddev(const std::vector<double>& v) {
  const double m = mean(v);
  double s = 0;
  for (double x : v) s += (x - m) * (x - m);
  return v.empty() ? NAN : std::sqrt(s / v.size());
}

bool write_traj(const std::string& path, const sim::CarmenLog& log, const std::vector<fw::Se2d>& poses) {
  std::ofstream f(path);
  if (!f) return false;
  f << "# ipc_timestamp x y theta\n";
  char buf[160];
  for (size_t i = 0; i < poses.size(); ++i) {
    std::snprintf(buf, sizeof buf, "%.6f %.5f %.5f %.6f\n", log.scans[i].ipc_timestamp, poses[i].x, poses[i].y,
                  poses[i].theta);
    f << buf;
  }
  return static_cast<bool>(f);
}

}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 3) return usage();
  const std::string cmd = argv[1];
  // DATASET (a built-in name) or --log/--relations by path; the first argument after the command
  // is the dataset unless it is an option.
  std::string ds = argv[2][0] == '-' ? "" : argv[2];
  std::string log_path, rel_path;
  int seeds = 20, particles = 1000, workers = 1;
  size_t scans = 0, pairs = 300;
  bool icp = true, maps = true;
  std::vector<std::string> sets;  // key=value overrides of the matcher configuration
  std::string out_dir = "build/rbsm-eval";
  std::string name;
  for (int i = ds.empty() ? 2 : 3; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "mml-rbsm-eval: %s needs a value\n", a.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (a == "--seeds") seeds = std::atoi(next());
    else if (a == "--scans") scans = std::strtoul(next(), nullptr, 10);
    else if (a == "--pairs") pairs = std::strtoul(next(), nullptr, 10);
    else if (a == "--particles") particles = std::atoi(next());
    else if (a == "--workers") workers = std::atoi(next());
    else if (a == "--out") out_dir = next();
    else if (a == "--no-icp") icp = false;
    else if (a == "--no-maps") maps = false;
    else if (a == "--set") sets.push_back(next());
    else if (a == "--log") log_path = next();
    else if (a == "--relations") rel_path = next();
    else if (a == "--name") name = next();
    else {
      std::fprintf(stderr, "mml-rbsm-eval: unknown option '%s'\n", a.c_str());
      return usage();
    }
  }
  if (seeds < 0 || particles < 1 || workers < 1) {
    std::fprintf(stderr, "mml-rbsm-eval: --particles and --workers must be positive, --seeds >= 0 (0: baselines only)\n");
    return 2;
  }
  std::string err;
  sim::EvalDataset d;
  if (!log_path.empty()) {
    if (!ds.empty()) {
      std::fprintf(stderr, "mml-rbsm-eval: give either DATASET or --log, not both\n");
      return 2;
    }
    d.raw_log = log_path;
    d.relations = rel_path;
    if (name.empty()) {  // file name up to the first dot: /x/y/intel.clf.gz → intel
      const size_t slash = log_path.find_last_of('/');
      name = log_path.substr(slash == std::string::npos ? 0 : slash + 1);
      name = name.substr(0, name.find('.'));
    }
    ds = name.empty() ? "log" : name;
  } else if (ds.empty()) {
    return usage();
  } else if (!sim::find_eval_dataset(ds, &d, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
    return 1;
  } else if (!rel_path.empty()) {
    d.relations = rel_path;
  }
  sim::CarmenLog log;
  sim::CarmenReadOptions ro;
  if (!sim::read_carmen_log(d.raw_log, ro, &log, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
    return 1;
  }
  sim::MatcherConfig cfg = sim::default_matcher_config();
  cfg.rbsm.num_particles = static_cast<uint32_t>(particles);
  cfg.workers = workers;
  for (const std::string& kv : sets) {
    const size_t eq = kv.find('=');
    const std::string key = kv.substr(0, eq);
    const double v = eq == std::string::npos ? NAN : std::atof(kv.c_str() + eq + 1);
    if (std::isnan(v)) {
      std::fprintf(stderr, "mml-rbsm-eval: --set %s: expected key=value\n", kv.c_str());
      return 2;
    }
    if (key == "max_range") {
      cfg.rbsm.max_range = cfg.icp.max_range = cfg.front.scan.max_range = static_cast<float>(v);
    } else if (key == "resolution") {
      cfg.rbsm.grid.resolution = cfg.icp.grid.resolution = static_cast<float>(v);
    } else if (key == "size_log2") {
      cfg.rbsm.grid.size_log2 = cfg.icp.grid.size_log2 = static_cast<uint32_t>(v);
    } else if (key == "subcell_log2") {
      cfg.rbsm.grid.subcell_log2 = cfg.icp.grid.subcell_log2 = static_cast<uint32_t>(v);
    } else if (key == "shrink") {
      cfg.rbsm.shrink = static_cast<float>(v);
    } else if (key == "accept_ratio") {
      cfg.rbsm.accept_ratio = static_cast<float>(v);
    } else if (key == "min_iterations") {
      cfg.rbsm.min_iterations = static_cast<uint32_t>(v);
    } else if (key == "particles") {
      cfg.rbsm.num_particles = static_cast<uint32_t>(v);
    } else if (key == "max_iterations") {
      cfg.rbsm.max_iterations = static_cast<uint32_t>(v);
    } else if (key == "sigma_xy2") {
      cfg.rbsm.sigma_xy2_cells2 = static_cast<float>(v);
    } else if (key == "sigma_psi2") {
      cfg.rbsm.sigma_psi2_deg2 = static_cast<float>(v);
    } else if (key == "hill_climbing") {
      cfg.rbsm.hill_climbing = v != 0;
    } else if (key == "mahalanobis") {
      cfg.rbsm.mahalanobis = v != 0;
    } else if (key == "min_translation") {
      cfg.front.min_translation_m = static_cast<float>(v);
    } else if (key == "min_rotation_deg") {
      cfg.front.min_rotation_rad = static_cast<float>(v * M_PI / 180.0);
    } else if (key == "icp_max_corr") {
      cfg.icp.max_correspondence_m = static_cast<float>(v);
    } else if (key == "refine") {
      cfg.rbsm.refine = v != 0;
    } else if (key == "refine_radius") {
      cfg.rbsm.refine_radius_cells = static_cast<uint32_t>(v);
    } else if (key == "refine_iterations") {
      cfg.rbsm.refine_iterations = static_cast<uint32_t>(v);
    } else if (key == "chain_refined") {
      cfg.front.chain_on_refined = v != 0;
    } else if (key == "refine_score_loss") {
      cfg.rbsm.refine_max_score_loss = static_cast<float>(v);
    } else if (key == "refine_eigen") {
      cfg.rbsm.refine_min_eigen_ratio = static_cast<float>(v);
    } else if (key == "refine_gate") {
      cfg.rbsm.refine_gate_cells = static_cast<float>(v);
    } else if (key == "plicp_max_corr") {
      cfg.plicp.max_correspondence_m = static_cast<float>(v);
    } else if (key == "plicp_kf_dist") {
      cfg.plicp.keyframe_translation_m = static_cast<float>(v);
    } else if (key == "plicp_kf_deg") {
      cfg.plicp.keyframe_rotation_rad = static_cast<float>(v * M_PI / 180.0);
    } else if (key == "plicp_trim") {
      cfg.plicp.trim_fraction = static_cast<float>(v);
    } else {
      std::fprintf(stderr, "mml-rbsm-eval: --set: unknown key '%s'\n", key.c_str());
      return 2;
    }
  }

  if (cmd == "pairwise") {
    std::vector<sim::CorrectedPose> ref;
    if (d.corrected_poses.empty() || !sim::read_corrected_poses(d.corrected_poses, &ref, &err)) {
      std::fprintf(stderr, "mml-rbsm-eval: %s: no reference poses (%s)\n", ds.c_str(), err.c_str());
      return 1;
    }
    for (sim::MatcherKind k : {sim::MatcherKind::kRbsm, sim::MatcherKind::kPlIcp, sim::MatcherKind::kIcp}) {
      std::vector<double> te, re, ms;
      size_t fails = 0;
      const int runs = k != sim::MatcherKind::kRbsm ? 1 : seeds;  // ICP is deterministic
      for (int s = 1; s <= runs; ++s) {
        sim::PairwiseResult r;
        cfg.rbsm.seed = static_cast<uint64_t>(s);
        // Same perturbations for every matcher and seed: the noise seed is fixed.
        if (!sim::run_pairwise(log, ref, k, cfg, pairs, 99, 0.10, 6.0, &r, &err)) {
          std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
          return 1;
        }
        te.insert(te.end(), r.trans_err_m.begin(), r.trans_err_m.end());
        re.insert(re.end(), r.rot_err_deg.begin(), r.rot_err_deg.end());
        ms.insert(ms.end(), r.ms.begin(), r.ms.end());
        fails += r.failures;
      }
      const auto t = sim::summarize(te), r = sim::summarize(re);
      std::printf("%s pairwise %-4s n=%zu fail=%zu  trans mean %.4f p95 %.4f max %.4f m | rot mean %.3f p95 %.3f max "
                  "%.3f deg | %.2f ms/match (p50)\n",
                  ds.c_str(), sim::matcher_name(k), t.n, fails, t.mean, t.p95, t.max, r.mean, r.p95, r.max,
                  sim::percentile(ms, 50));
    }
    return 0;
  }
  if (cmd != "odometry") return usage();

  std::vector<sim::Relation> rel;
  if (d.relations.empty() || !sim::read_relations(d.relations, &rel, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s: no relations (%s)\n", ds.c_str(),
                 d.relations.empty() ? "give --relations PATH" : err.c_str());
    return 1;
  }
  std::system(("mkdir -p '" + out_dir + "'").c_str());
  const size_t n = scans == 0 ? log.scans.size() : std::min(scans, log.scans.size());
  sim::CarmenLog head = log;
  head.scans.resize(n);
  std::vector<fw::Se2d> odom_poses;
  for (size_t i = 0; i < n; ++i) odom_poses.push_back(log.scans[i].odom);
  const auto mo = sim::evaluate_relations_split(rel, sim::make_trajectory(head, odom_poses));
  std::printf("%s odom:\n%s\n", ds.c_str(), sim::to_string(mo).c_str());
  write_traj(out_dir + "/" + ds + "_odom.txt", log, odom_poses);
  if (maps) sim::write_map_png(out_dir + "/" + ds + "_odom.png", log, odom_poses, nullptr, 0.05, 15.0f, 1, &err);
  if (icp) {
    for (sim::MatcherKind k : sim::icp_baselines()) {
      sim::OdometryRun run;
      if (!sim::run_scan_matching_odometry(log, k, cfg, n, &run, &err)) {
        std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
        return 1;
      }
      const auto m = sim::evaluate_relations_split(rel, sim::make_trajectory(head, run.poses));
      const std::string kn = sim::matcher_name(k);
      std::printf("%s %s: %.2f ms/match p50, %.3f ms CPU/scan (with map update), %zu failures, %.1fx better than "
                  "odometry\n%s\n",
                  ds.c_str(), kn.c_str(), sim::percentile(run.match_ms, 50), sim::cpu_ms_per_scan(run), run.failures,
                  mo.all.trans_mean / m.all.trans_mean, sim::to_string(m).c_str());
      if (maps) sim::write_map_png(out_dir + "/" + ds + "_" + kn + ".png", log, run.poses, nullptr, 0.05, 15.0f, 1, &err);
      write_traj(out_dir + "/" + ds + "_" + kn + ".txt", log, run.poses);
    }
  }
  std::vector<double> tm, rm, stm, srm, ltm, lrm, cpu;
  double best = 1e9, worst = -1;
  for (int s = 1; s <= seeds; ++s) {
    cfg.rbsm.seed = static_cast<uint64_t>(s);
    sim::OdometryRun run;
    if (!sim::run_scan_matching_odometry(log, sim::MatcherKind::kRbsm, cfg, n, &run, &err)) {
      std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
      return 1;
    }
    const auto ms = sim::evaluate_relations_split(rel, sim::make_trajectory(head, run.poses));
    const auto& m = ms.all;
    tm.push_back(m.trans_mean);
    rm.push_back(m.rot_mean_deg);
    stm.push_back(ms.short_rel.trans_mean);
    srm.push_back(ms.short_rel.rot_mean_deg);
    ltm.push_back(ms.long_rel.trans_mean);
    lrm.push_back(ms.long_rel.rot_mean_deg);
    cpu.push_back(sim::cpu_ms_per_scan(run));
    double it_mean = 0;
    for (uint32_t k : run.iterations) it_mean += k;
    it_mean /= std::max<size_t>(1, run.iterations.size());
    std::printf("%s rbsm seed %2d: %.2f ms/match p50 p99 %.2f (cpu p50 %.2f), %.3f ms CPU/scan (with map update), %.1f "
                "rounds/match, %zu of %zu at the cap, %zu failures\n%s\n",
                ds.c_str(), s, sim::percentile(run.match_ms, 50), sim::percentile(run.match_ms, 99),
                sim::percentile(run.match_cpu_ms, 50), cpu.back(), it_mean, run.not_converged, run.iterations.size(),
                run.failures, sim::to_string(ms).c_str());
    std::fflush(stdout);
    char seed_name[32];
    std::snprintf(seed_name, sizeof seed_name, "_rbsm_seed%02d.txt", s);
    if (!write_traj(out_dir + "/" + ds + seed_name, log, run.poses)) {
      std::fprintf(stderr, "mml-rbsm-eval: cannot write %s/%s%s\n", out_dir.c_str(), ds.c_str(), seed_name);
      return 1;
    }
    if (maps && m.trans_mean < best) {
      best = m.trans_mean;
      sim::write_map_png(out_dir + "/" + ds + "_rbsm_best.png", log, run.poses, nullptr, 0.05, 15.0f, 1, &err);
      write_traj(out_dir + "/" + ds + "_rbsm_best.txt", log, run.poses);
    }
    if (maps && m.trans_mean > worst) {
      worst = m.trans_mean;
      sim::write_map_png(out_dir + "/" + ds + "_rbsm_worst.png", log, run.poses, nullptr, 0.05, 15.0f, 1, &err);
    }
  }
  if (seeds == 0) return 0;
  std::printf("%s rbsm over %d seeds: trans %.4f ± %.4f m, rot %.3f ± %.3f deg (odom %.4f m %.3f deg) | short (<= 10 s) "
              "trans %.4f m rot %.3f deg | long (> 10 s) trans %.4f m rot %.3f deg | %.3f ms CPU/scan\n",
              ds.c_str(), seeds, mean(tm), stddev(tm), mean(rm), stddev(rm), mo.all.trans_mean, mo.all.rot_mean_deg,
              mean(stm), mean(srm), mean(ltm), mean(lrm), mean(cpu));
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-rbsm-eval", [&] { return run_main(argc, argv); });
}
