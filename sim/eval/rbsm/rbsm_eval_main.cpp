// mml-rbsm-eval: evaluates RBSM against the ICP baselines and raw odometry on the real logs (issue 4, 15).
//   mml-rbsm-eval odometry DATASET [--seeds N] [--scans N] [--particles N] [--workers N] [--out DIR] [--no-icp]
//   mml-rbsm-eval odometry --log LOG --relations RELATIONS [--name NAME] …   (any building, by path)
//     scan-matcher-only odometry; relations metric (Kümmerle et al. 2009) per seed and mean ± std,
//     overall and split by relation length (≤ 10 s / > 10 s); CPU per scan including the map update;
//     writes DIR/NAME_{rbsm_best,rbsm_worst,icp,odom}.png and trajectories DIR/NAME_odom.txt,
//     DIR/NAME_<icp>.txt and one per seed, DIR/NAME_rbsm_seedNN.txt (mml-carmen eval rescores them);
//     with the ICP baselines also RBSM fused with PL-ICP's increments per seed (fw::IncrementFusion, an
//     extension), DIR/NAME_fused_seedNN.txt.
//   mml-rbsm-eval pairwise DATASET [--pairs N] [--seeds N] [--particles N]
//   mml-rbsm-eval fuse RBSM.txt PL-ICP.txt OUT.txt [--relations RELATIONS] [--set fuse_KEY=VALUE …]
//     fuses two saved trajectories of the same scans (RBSM's poses, PL-ICP's increments) with
//     fw::IncrementFusion and writes OUT.txt; --relations prints its relations metric (as
//     mml-carmen eval RELATIONS OUT.txt does).
//   --set KEY=VALUE overrides the matcher configuration (max_range, resolution, size_log2, subcell_log2,
//     shrink, accept_ratio, min_iterations, max_iterations, sigma_xy2, sigma_psi2, hill_climbing, mahalanobis,
//     min_translation, min_rotation_deg, icp_max_corr, refine (0: pure Alg. 1 with prior=0), prior (odometry motion prior, 0/1), prior_xy (its σ in m), refine_radius, refine_iterations,
//     refine_gate, refine_eigen, refine_score_loss, chain_refined, plicp_max_corr, plicp_kf_dist, plicp_kf_deg, plicp_trim,
//     fuse_abs_xy, fuse_abs_deg (RBSM's σ in the fusion), fuse_rel_xy, fuse_rel_per_m, fuse_rel_deg, fuse_gate, fuse_smooth (0: the filter alone)); --no-maps skips the PNGs.
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

using sim::mean;
using sim::stddev;

int usage() {
  std::fprintf(stderr,
               "usage: mml-rbsm-eval odometry DATASET [--seeds N] [--scans N] [--particles N] [--workers N] "
               "[--out DIR] [--no-icp]\n"
               "       mml-rbsm-eval odometry --log LOG --relations RELATIONS [--name NAME] [options as above]\n"
               "       mml-rbsm-eval pairwise DATASET [--pairs N] [--seeds N] [--particles N]\n"
               "       mml-rbsm-eval fuse RBSM.txt PL-ICP.txt OUT.txt [--relations RELATIONS] [--set fuse_KEY=VALUE ...]\n");
  return 2;
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

// The command line: DATASET (a built-in name) or --log/--relations by path, and the options.
struct EvalArgs {
  std::string cmd;
  std::string ds;  // the dataset; for a log given by path, its --name (or file name)
  std::string log_path, rel_path;
  int seeds = 20, particles = 1000, workers = 1;
  size_t scans = 0, pairs = 300;
  bool icp = true, maps = true;
  std::vector<std::string> sets;  // key=value overrides of the matcher configuration
  std::string out_dir = "build/rbsm-eval";
  std::string name;
};

// Returned by the steps below to go on; any other value is the exit code.
constexpr int kGoOn = -1;

int parse_args(int argc, char** argv, EvalArgs* a) {
  if (argc < 3) return usage();
  a->cmd = argv[1];
  // The first argument after the command is the dataset unless it is an option.
  a->ds = argv[2][0] == '-' ? "" : argv[2];
  for (int i = a->ds.empty() ? 2 : 3; i < argc; ++i) {
    const std::string arg = argv[i];
    auto next = [&]() -> const char* {
      if (i + 1 >= argc) {
        std::fprintf(stderr, "mml-rbsm-eval: %s needs a value\n", arg.c_str());
        std::exit(2);
      }
      return argv[++i];
    };
    if (arg == "--seeds") a->seeds = std::atoi(next());
    else if (arg == "--scans") a->scans = std::strtoul(next(), nullptr, 10);
    else if (arg == "--pairs") a->pairs = std::strtoul(next(), nullptr, 10);
    else if (arg == "--particles") a->particles = std::atoi(next());
    else if (arg == "--workers") a->workers = std::atoi(next());
    else if (arg == "--out") a->out_dir = next();
    else if (arg == "--no-icp") a->icp = false;
    else if (arg == "--no-maps") a->maps = false;
    else if (arg == "--set") a->sets.push_back(next());
    else if (arg == "--log") a->log_path = next();
    else if (arg == "--relations") a->rel_path = next();
    else if (arg == "--name") a->name = next();
    else {
      std::fprintf(stderr, "mml-rbsm-eval: unknown option '%s'\n", arg.c_str());
      return usage();
    }
  }
  if (a->seeds < 0 || a->particles < 1 || a->workers < 1) {
    std::fprintf(stderr, "mml-rbsm-eval: --particles and --workers must be positive, --seeds >= 0 (0: baselines only)\n");
    return 2;
  }
  return kGoOn;
}

// The log and relations to use: a built-in dataset (--relations overrides its relations), or a log
// by path named by --name or its file name.
int resolve_dataset(EvalArgs* a, sim::EvalDataset* d, std::string* err) {
  if (!a->log_path.empty()) {
    if (!a->ds.empty()) {
      std::fprintf(stderr, "mml-rbsm-eval: give either DATASET or --log, not both\n");
      return 2;
    }
    d->raw_log = a->log_path;
    d->relations = a->rel_path;
    if (a->name.empty()) {  // file name up to the first dot: /x/y/intel.clf.gz → intel
      const size_t slash = a->log_path.find_last_of('/');
      a->name = a->log_path.substr(slash == std::string::npos ? 0 : slash + 1);
      a->name = a->name.substr(0, a->name.find('.'));
    }
    a->ds = a->name.empty() ? "log" : a->name;
  } else if (a->ds.empty()) {
    return usage();
  } else if (!sim::find_eval_dataset(a->ds, d, err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s\n", err->c_str());
    return 1;
  } else if (!a->rel_path.empty()) {
    d->relations = a->rel_path;
  }
  return kGoOn;
}

// --set keys of the grid and range shared by RBSM and trimmed ICP (max_range also the front end's).
bool apply_shared_setting(const std::string& key, double v, sim::MatcherConfig* cfg) {
  if (key == "max_range") {
    cfg->rbsm.max_range = cfg->icp.max_range = cfg->front.scan.max_range = static_cast<float>(v);
  } else if (key == "resolution") {
    cfg->rbsm.grid.resolution = cfg->icp.grid.resolution = static_cast<float>(v);
  } else if (key == "size_log2") {
    cfg->rbsm.grid.size_log2 = cfg->icp.grid.size_log2 = static_cast<uint32_t>(v);
  } else if (key == "subcell_log2") {
    cfg->rbsm.grid.subcell_log2 = cfg->icp.grid.subcell_log2 = static_cast<uint32_t>(v);
  } else {
    return false;
  }
  return true;
}

// --set keys of RBSM (Alg. 1) and its point-to-line refinement.
bool apply_rbsm_setting(const std::string& key, double v, fw::RbsmOptions* rbsm) {
  if (key == "shrink") rbsm->shrink = static_cast<float>(v);
  else if (key == "accept_ratio") rbsm->accept_ratio = static_cast<float>(v);
  else if (key == "min_iterations") rbsm->min_iterations = static_cast<uint32_t>(v);
  else if (key == "particles") rbsm->num_particles = static_cast<uint32_t>(v);
  else if (key == "max_iterations") rbsm->max_iterations = static_cast<uint32_t>(v);
  else if (key == "sigma_xy2") rbsm->sigma_xy2_cells2 = static_cast<float>(v);
  else if (key == "sigma_psi2") rbsm->sigma_psi2_deg2 = static_cast<float>(v);
  else if (key == "hill_climbing") rbsm->hill_climbing = v != 0;
  else if (key == "mahalanobis") rbsm->mahalanobis = v != 0;
  else if (key == "refine") rbsm->refine = v != 0;
  else if (key == "prior") rbsm->motion_prior = v != 0;
  else if (key == "prior_xy") rbsm->prior_sigma_xy_m = static_cast<float>(v);

  else if (key == "refine_radius") rbsm->refine_radius_cells = static_cast<uint32_t>(v);
  else if (key == "refine_iterations") rbsm->refine_iterations = static_cast<uint32_t>(v);
  else if (key == "refine_score_loss") rbsm->refine_max_score_loss = static_cast<float>(v);
  else if (key == "refine_eigen") rbsm->refine_min_eigen_ratio = static_cast<float>(v);
  else if (key == "refine_gate") rbsm->refine_gate_cells = static_cast<float>(v);
  else return false;
  return true;
}

// --set keys of the odometry front end and the ICP baselines.
bool apply_front_and_icp_setting(const std::string& key, double v, sim::MatcherConfig* cfg) {
  if (key == "min_translation") cfg->front.min_translation_m = static_cast<float>(v);
  else if (key == "min_rotation_deg") cfg->front.min_rotation_rad = static_cast<float>(v * M_PI / 180.0);
  else if (key == "chain_refined") cfg->front.chain_on_refined = v != 0;
  else if (key == "icp_max_corr") cfg->icp.max_correspondence_m = static_cast<float>(v);
  else if (key == "plicp_max_corr") cfg->plicp.max_correspondence_m = static_cast<float>(v);
  else if (key == "plicp_kf_dist") cfg->plicp.keyframe_translation_m = static_cast<float>(v);
  else if (key == "plicp_kf_deg") cfg->plicp.keyframe_rotation_rad = static_cast<float>(v * M_PI / 180.0);
  else if (key == "plicp_trim") cfg->plicp.trim_fraction = static_cast<float>(v);
  else if (key == "fuse_abs_xy") cfg->fusion.absolute_sigma_m = v;
  else if (key == "fuse_abs_deg") cfg->fusion.absolute_sigma_rad = v * M_PI / 180.0;
  else if (key == "fuse_rel_xy") cfg->fusion.relative_sigma_m = v;
  else if (key == "fuse_rel_per_m") cfg->fusion.relative_sigma_per_m = v;
  else if (key == "fuse_rel_deg") cfg->fusion.relative_sigma_rad = v * M_PI / 180.0;
  else if (key == "fuse_gate") cfg->fusion.gate_chi2 = v;
  else if (key == "fuse_smooth") cfg->fusion_smooth = v != 0;
  else return false;
  return true;
}

// The default matcher configuration with --particles, --workers and the --set overrides.
int make_matcher_config(const EvalArgs& a, sim::MatcherConfig* cfg) {
  *cfg = sim::default_matcher_config();
  cfg->rbsm.num_particles = static_cast<uint32_t>(a.particles);
  cfg->workers = a.workers;
  for (const std::string& kv : a.sets) {
    const size_t eq = kv.find('=');
    const std::string key = kv.substr(0, eq);
    const double v = eq == std::string::npos ? NAN : std::atof(kv.c_str() + eq + 1);
    if (std::isnan(v)) {
      std::fprintf(stderr, "mml-rbsm-eval: --set %s: expected key=value\n", kv.c_str());
      return 2;
    }
    if (!apply_shared_setting(key, v, cfg) && !apply_rbsm_setting(key, v, &cfg->rbsm) &&
        !apply_front_and_icp_setting(key, v, cfg)) {
      std::fprintf(stderr, "mml-rbsm-eval: --set: unknown key '%s'\n", key.c_str());
      return 2;
    }
  }
  return kGoOn;
}

// Consecutive corrected-scan pairs, guess perturbed by N(0, 10 cm, 6°), per matcher: RBSM over the
// seeds, the ICPs once (deterministic).
int run_pairwise(const EvalArgs& a, const sim::EvalDataset& d, const sim::CarmenLog& log, sim::MatcherConfig cfg,
                 std::string* err) {
  std::vector<sim::CorrectedPose> ref;
  if (d.corrected_poses.empty() || !sim::read_corrected_poses(d.corrected_poses, &ref, err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s: no reference poses (%s)\n", a.ds.c_str(), err->c_str());
    return 1;
  }
  for (sim::MatcherKind k : {sim::MatcherKind::kRbsm, sim::MatcherKind::kPlIcp, sim::MatcherKind::kIcp}) {
    std::vector<double> te, re, ms;
    size_t fails = 0;
    const int runs = k != sim::MatcherKind::kRbsm ? 1 : a.seeds;  // ICP is deterministic
    for (int s = 1; s <= runs; ++s) {
      sim::PairwiseResult r;
      cfg.rbsm.seed = static_cast<uint64_t>(s);
      // Same perturbations for every matcher and seed: the noise seed is fixed.
      if (!sim::run_pairwise(log, ref, k, cfg, a.pairs, 99, 0.10, 6.0, &r, err)) {
        std::fprintf(stderr, "mml-rbsm-eval: %s\n", err->c_str());
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
                a.ds.c_str(), sim::matcher_name(k), t.n, fails, t.mean, t.p95, t.max, r.mean, r.p95, r.max,
                sim::percentile(ms, 50));
  }
  return 0;
}

// What the odometry runs share: the log, its first n scans (head) and the relations to score on.
struct OdometryInput {
  const sim::CarmenLog& log;
  sim::CarmenLog head;
  size_t n = 0;
  std::vector<sim::Relation> rel;
  std::vector<fw::Se2d> pl_icp;  // PL-ICP's poses (for the fusion), when the baselines ran
};

// Raw odometry scored: the reference every matcher is compared with.
sim::RelationsMetricSplit evaluate_raw_odometry(const EvalArgs& a, const OdometryInput& in, std::string* err) {
  std::vector<fw::Se2d> odom_poses;
  for (size_t i = 0; i < in.n; ++i) odom_poses.push_back(in.log.scans[i].odom);
  const auto mo = sim::evaluate_relations_split(in.rel, sim::make_trajectory(in.head, odom_poses));
  std::printf("%s odom:\n%s\n", a.ds.c_str(), sim::to_string(mo).c_str());
  write_traj(a.out_dir + "/" + a.ds + "_odom.txt", in.log, odom_poses);
  if (a.maps) sim::write_map_png(a.out_dir + "/" + a.ds + "_odom.png", in.log, odom_poses, nullptr, 0.05, 15.0f, 1, err);
  return mo;
}

int run_icp_baselines(const EvalArgs& a, OdometryInput* in_out, const sim::MatcherConfig& cfg,
                      const sim::RelationsMetricSplit& mo, std::string* err) {
  const OdometryInput& in = *in_out;
  for (sim::MatcherKind k : sim::icp_baselines()) {
    sim::OdometryRun run;
    if (!sim::run_scan_matching_odometry(in.log, k, cfg, in.n, &run, err)) {
      std::fprintf(stderr, "mml-rbsm-eval: %s\n", err->c_str());
      return 1;
    }
    const auto m = sim::evaluate_relations_split(in.rel, sim::make_trajectory(in.head, run.poses));
    const std::string kn = sim::matcher_name(k);
    std::printf("%s %s: %.2f ms/match p50, %.3f ms CPU/scan (with map update), %zu failures, %.1fx better than "
                "odometry\n%s\n",
                a.ds.c_str(), kn.c_str(), sim::percentile(run.match_ms, 50), sim::cpu_ms_per_scan(run), run.failures,
                mo.all.trans_mean / m.all.trans_mean, sim::to_string(m).c_str());
    if (a.maps) {
      sim::write_map_png(a.out_dir + "/" + a.ds + "_" + kn + ".png", in.log, run.poses, nullptr, 0.05, 15.0f, 1, err);
    }
    write_traj(a.out_dir + "/" + a.ds + "_" + kn + ".txt", in.log, run.poses);
    if (k == sim::MatcherKind::kPlIcp) in_out->pl_icp = run.poses;
  }
  return kGoOn;
}

// Per-seed figures of the RBSM runs (relations metric overall, short, long; CPU per scan) and the
// best and worst seed so far (by mean translation error) for the pictures.
struct SeedFigures {
  std::vector<double> tm, rm, stm, srm, ltm, lrm, cpu;
  std::vector<double> ftm, frm, fstm, fsrm, fltm;  // RBSM fused with PL-ICP's increments
  double best = 1e9, worst = -1;
};

void print_seed_line(const EvalArgs& a, int s, const sim::OdometryRun& run, double cpu_per_scan,
                     const sim::RelationsMetricSplit& ms) {
  double it_mean = 0;
  for (uint32_t k : run.iterations) it_mean += k;
  it_mean /= std::max<size_t>(1, run.iterations.size());
  std::printf("%s rbsm seed %2d: %.2f ms/match p50 p99 %.2f (cpu p50 %.2f), %.3f ms CPU/scan (with map update), %.1f "
              "rounds/match, %zu of %zu at the cap, %zu failures\n%s\n",
              a.ds.c_str(), s, sim::percentile(run.match_ms, 50), sim::percentile(run.match_ms, 99),
              sim::percentile(run.match_cpu_ms, 50), cpu_per_scan, it_mean, run.not_converged, run.iterations.size(),
              run.failures, sim::to_string(ms).c_str());
  std::fflush(stdout);
}

// One RBSM seed: run, score, print, write its trajectory and, when it is the best or worst so far,
// the pictures.
int run_rbsm_seed(const EvalArgs& a, const OdometryInput& in, sim::MatcherConfig* cfg, int s, SeedFigures* f,
                  std::string* err) {
  cfg->rbsm.seed = static_cast<uint64_t>(s);
  sim::OdometryRun run;
  if (!sim::run_scan_matching_odometry(in.log, sim::MatcherKind::kRbsm, *cfg, in.n, &run, err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s\n", err->c_str());
    return 1;
  }
  const auto ms = sim::evaluate_relations_split(in.rel, sim::make_trajectory(in.head, run.poses));
  const auto& m = ms.all;
  f->tm.push_back(m.trans_mean);
  f->rm.push_back(m.rot_mean_deg);
  f->stm.push_back(ms.short_rel.trans_mean);
  f->srm.push_back(ms.short_rel.rot_mean_deg);
  f->ltm.push_back(ms.long_rel.trans_mean);
  f->lrm.push_back(ms.long_rel.rot_mean_deg);
  f->cpu.push_back(sim::cpu_ms_per_scan(run));
  print_seed_line(a, s, run, f->cpu.back(), ms);
  char seed_name[32];
  std::snprintf(seed_name, sizeof seed_name, "_rbsm_seed%02d.txt", s);
  if (!write_traj(a.out_dir + "/" + a.ds + seed_name, in.log, run.poses)) {
    std::fprintf(stderr, "mml-rbsm-eval: cannot write %s/%s%s\n", a.out_dir.c_str(), a.ds.c_str(), seed_name);
    return 1;
  }
  if (!in.pl_icp.empty()) {
    std::vector<fw::Se2d> fused;
    uint32_t gated = 0;
    if (!sim::fuse_increments(run.poses, in.pl_icp, cfg->fusion, cfg->fusion_smooth, &fused, &gated, err)) {
      std::fprintf(stderr, "mml-rbsm-eval: %s\n", err->c_str());
      return 1;
    }
    const auto fm = sim::evaluate_relations_split(in.rel, sim::make_trajectory(in.head, fused));
    f->ftm.push_back(fm.all.trans_mean);
    f->frm.push_back(fm.all.rot_mean_deg);
    f->fstm.push_back(fm.short_rel.trans_mean);
    f->fsrm.push_back(fm.short_rel.rot_mean_deg);
    f->fltm.push_back(fm.long_rel.trans_mean);
    std::printf("%s rbsm seed %2d fused with pl-icp increments (%u gated updates):\n%s\n", a.ds.c_str(), s, gated,
                sim::to_string(fm).c_str());
    std::snprintf(seed_name, sizeof seed_name, "_fused_seed%02d.txt", s);
    write_traj(a.out_dir + "/" + a.ds + seed_name, in.log, fused);
  }
  if (a.maps && m.trans_mean < f->best) {
    f->best = m.trans_mean;
    sim::write_map_png(a.out_dir + "/" + a.ds + "_rbsm_best.png", in.log, run.poses, nullptr, 0.05, 15.0f, 1, err);
    write_traj(a.out_dir + "/" + a.ds + "_rbsm_best.txt", in.log, run.poses);
  }
  if (a.maps && m.trans_mean > f->worst) {
    f->worst = m.trans_mean;
    sim::write_map_png(a.out_dir + "/" + a.ds + "_rbsm_worst.png", in.log, run.poses, nullptr, 0.05, 15.0f, 1, err);
  }
  return kGoOn;
}

// Scan-matcher-only odometry: raw odometry, the ICP baselines (unless --no-icp) and RBSM over the
// seeds, scored with the relations metric; mean ± std over the seeds last.
int run_odometry(const EvalArgs& a, const sim::EvalDataset& d, const sim::CarmenLog& log, sim::MatcherConfig cfg,
                 std::string* err) {
  OdometryInput in{log, {}, 0, {}};
  if (d.relations.empty() || !sim::read_relations(d.relations, &in.rel, err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s: no relations (%s)\n", a.ds.c_str(),
                 d.relations.empty() ? "give --relations PATH" : err->c_str());
    return 1;
  }
  std::system(("mkdir -p '" + a.out_dir + "'").c_str());
  in.n = a.scans == 0 ? log.scans.size() : std::min(a.scans, log.scans.size());
  in.head = log;
  in.head.scans.resize(in.n);
  const sim::RelationsMetricSplit mo = evaluate_raw_odometry(a, in, err);
  if (a.icp) {
    const int rc = run_icp_baselines(a, &in, cfg, mo, err);
    if (rc != kGoOn) return rc;
  }
  SeedFigures f;
  for (int s = 1; s <= a.seeds; ++s) {
    const int rc = run_rbsm_seed(a, in, &cfg, s, &f, err);
    if (rc != kGoOn) return rc;
  }
  if (a.seeds == 0) return 0;
  std::printf("%s rbsm over %d seeds: trans %.4f ± %.4f m, rot %.3f ± %.3f deg (odom %.4f m %.3f deg) | short (<= 10 s) "
              "trans %.4f m rot %.3f deg | long (> 10 s) trans %.4f m rot %.3f deg | %.3f ms CPU/scan\n",
              a.ds.c_str(), a.seeds, mean(f.tm), stddev(f.tm), mean(f.rm), stddev(f.rm), mo.all.trans_mean,
              mo.all.rot_mean_deg, mean(f.stm), mean(f.srm), mean(f.ltm), mean(f.lrm), mean(f.cpu));
  if (!f.ftm.empty()) {
    std::printf("%s rbsm fused with pl-icp increments over %d seeds: trans %.4f ± %.4f m, rot %.3f deg | short (<= 10 s) "
                "trans %.4f m rot %.3f deg | long (> 10 s) trans %.4f m\n",
                a.ds.c_str(), a.seeds, mean(f.ftm), stddev(f.ftm), mean(f.frm), mean(f.fstm), mean(f.fsrm),
                mean(f.fltm));
  }
  return 0;
}

}  // namespace

// mml-rbsm-eval fuse RBSM.txt PL-ICP.txt OUT.txt [--set fuse_KEY=VALUE …]
int run_fuse(int argc, char** argv) {
  if (argc < 5) return usage();
  sim::MatcherConfig cfg = sim::default_matcher_config();
  std::string relations_path;
  for (int i = 5; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--relations" && i + 1 < argc) {
      relations_path = argv[++i];
      continue;
    }
    const std::string kv = arg == "--set" && i + 1 < argc ? argv[++i] : "";
    const size_t eq = kv.find('=');
    const double v = eq == std::string::npos ? NAN : std::atof(kv.c_str() + eq + 1);
    if (kv.compare(0, 5, "fuse_") != 0 || std::isnan(v) || !apply_front_and_icp_setting(kv.substr(0, eq), v, &cfg)) {
      std::fprintf(stderr, "mml-rbsm-eval fuse: '%s': expected --set fuse_KEY=VALUE\n", arg == "--set" ? kv.c_str() : arg.c_str());
      return 2;
    }
  }
  std::string err;
  std::vector<sim::Relation> rel;  // --relations: the fused trajectory scored as `odometry` scores it
  if (!relations_path.empty() && !sim::read_relations(relations_path, &rel, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval fuse: %s\n", err.c_str());
    return 1;
  }
  sim::Trajectory rb, pl;
  if (!sim::read_trajectory(argv[2], &rb, &err) || !sim::read_trajectory(argv[3], &pl, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval fuse: %s\n", err.c_str());
    return 1;
  }
  for (size_t i = 0; i < rb.size() && i < pl.size(); ++i) {
    if (std::fabs(rb[i].t - pl[i].t) > 1e-5) {
      std::fprintf(stderr, "mml-rbsm-eval fuse: pose %zu of %s (t %.6f) and of %s (t %.6f) are not the same scan\n", i + 1,
                   argv[2], rb[i].t, argv[3], pl[i].t);
      return 1;
    }
  }
  std::vector<fw::Se2d> a, b, fused;
  for (const auto& p : rb) a.push_back(p.pose);
  for (const auto& p : pl) b.push_back(p.pose);
  uint32_t gated = 0;
  if (!sim::fuse_increments(a, b, cfg.fusion, cfg.fusion_smooth, &fused, &gated, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval fuse: %s\n", err.c_str());
    return 1;
  }
  sim::Trajectory out = rb;
  for (size_t i = 0; i < out.size(); ++i) out[i].pose = fused[i];
  if (!sim::write_trajectory(argv[4], out, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval fuse: %s\n", err.c_str());
    return 1;
  }
  std::printf("%zu poses fused, %u updates down-weighted at the gate\n", fused.size(), gated);
  if (!relations_path.empty()) std::printf("%s\n", sim::to_string(sim::evaluate_relations_split(rel, out)).c_str());
  return 0;
}

static int run_main(int argc, char** argv) {
  if (argc > 1 && std::strcmp(argv[1], "fuse") == 0) return run_fuse(argc, argv);
  EvalArgs a;
  int rc = parse_args(argc, argv, &a);
  if (rc != kGoOn) return rc;
  std::string err;
  sim::EvalDataset d;
  rc = resolve_dataset(&a, &d, &err);
  if (rc != kGoOn) return rc;
  sim::CarmenLog log;
  sim::CarmenReadOptions ro;
  if (!sim::read_carmen_log(d.raw_log, ro, &log, &err)) {
    std::fprintf(stderr, "mml-rbsm-eval: %s\n", err.c_str());
    return 1;
  }
  sim::MatcherConfig cfg;
  rc = make_matcher_config(a, &cfg);
  if (rc != kGoOn) return rc;
  if (a.cmd == "pairwise") return run_pairwise(a, d, log, cfg, &err);
  if (a.cmd != "odometry") return usage();
  return run_odometry(a, d, log, cfg, &err);
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-rbsm-eval", [&] { return run_main(argc, argv); });
}
