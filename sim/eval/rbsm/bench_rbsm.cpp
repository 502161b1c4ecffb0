// bench_rbsm: per-match timing of RBSM (250/500/1000/2000 particles, one thread and over a 2-worker
// fw::WorkerPool, median and p99) and the scan-matcher-only odometry accuracy on intel, fr079 and
// aces (relations metric overall and split by relation length, ≤ 10 s / > 10 s (issue 15): RBSM
// averaged over kSeeds seeds, the ICP baseline, raw odometry; CPU per scan including the map
// update), RBSM with Alg. 1's
// stop rule alone (one seed), and the pairwise experiment (150 pairs). Writes the flat JSON of
// issue 4 to argv[1]. Wall-clock figures (ms) plus thread-CPU figures (cpu_ms: robust when the
// machine is shared). Budget: < 10 min on 2 cores (7.2 min wall / 2.1 min CPU measured with load average ~10).
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "sim/common/bench_json.h"
#include "sim/eval/rbsm/rbsm_eval_lib.h"
#include "sim/common/cli_main.h"

namespace {

using sim::mean;
using sim::stddev;

constexpr int kSeeds = 3;             // the full tool uses 20 (mml-rbsm-eval odometry --seeds 20)
constexpr size_t kTimingScans = 800;  // intel prefix used for the particle-count table


// A data set of the bench: its raw log and the relations to score on.
struct BenchCase {
  std::string ds;
  sim::EvalDataset d;
  sim::CarmenLog log;
  std::vector<sim::Relation> rel;
};

bool load_case(const std::string& ds, BenchCase* c, std::string* err) {
  c->ds = ds;
  return sim::find_eval_dataset(ds, &c->d, err) && sim::read_carmen_log(c->d.raw_log, {}, &c->log, err) &&
         sim::read_relations(c->d.relations, &c->rel, err);
}

// Scan-matcher-only odometry over the first n scans (0: all); a failure is printed.
bool run_odometry(const sim::CarmenLog& log, sim::MatcherKind kind, const sim::MatcherConfig& cfg, size_t n,
                  sim::OdometryRun* run, std::string* err) {
  if (sim::run_scan_matching_odometry(log, kind, cfg, n, run, err)) return true;
  std::fprintf(stderr, "bench_rbsm: %s\n", err->c_str());
  return false;
}

// Timing table on the intel prefix (real scans, real map growth): one thread and a 2-worker pool.
bool add_timing_table(const sim::CarmenLog& log, const sim::MatcherConfig& cfg, sim::BenchJson* json,
                      std::string* err) {
  for (int particles : {250, 500, 1000, 2000}) {
    for (int workers : {1, 2}) {
      sim::MatcherConfig c = cfg;
      c.rbsm.num_particles = particles;
      c.workers = workers;
      sim::OdometryRun run;
      if (!run_odometry(log, sim::MatcherKind::kRbsm, c, kTimingScans, &run, err)) return false;
      const std::string suffix = workers == 1 ? "" : "_pool";
      json->add("rbsm_match_ms_p50_" + std::to_string(particles) + suffix, sim::percentile(run.match_ms, 50));
      json->add("rbsm_match_ms_p99_" + std::to_string(particles) + suffix, sim::percentile(run.match_ms, 99));
      if (workers == 1) {
        json->add("rbsm_match_cpu_ms_p50_" + std::to_string(particles), sim::percentile(run.match_cpu_ms, 50));
      }
      if (particles == 1000 && workers == 2) {
        json->add("rbsm_match_ms_p50_pool", sim::percentile(run.match_ms, 50));
        json->add("rbsm_match_ms_p99_pool", sim::percentile(run.match_ms, 99));
      }
    }
  }
  return true;
}

// Issue 15: every figure overall and split by relation length (≤ 10 s: single-alignment precision;
// > 10 s: drift), all with the same scorer.
void add_split(const std::string& ds, const std::string& who, const sim::RelationsMetricSplit& m,
               sim::BenchJson* json) {
  json->add(ds + "_trans_err_" + who, m.all.trans_mean);
  json->add(ds + "_rot_err_" + who, m.all.rot_mean_deg);
  json->add(ds + "_short_trans_err_" + who, m.short_rel.trans_mean);
  json->add(ds + "_short_rot_err_" + who, m.short_rel.rot_mean_deg);
  json->add(ds + "_long_trans_err_" + who, m.long_rel.trans_mean);
  json->add(ds + "_long_rot_err_" + who, m.long_rel.rot_mean_deg);
}

sim::RelationsMetricSplit score(const BenchCase& c, const std::vector<fw::Se2d>& poses) {
  return sim::evaluate_relations_split(c.rel, sim::make_trajectory(c.log, poses));
}

// The ICP baselines: "icp" = PL-ICP laser-to-laser (the honest baseline, issue 15), "trimicp" = the
// dissertation's trimmed ICP against the end-point map (the figure "icp" meant before). *pl_icp:
// PL-ICP's figures, poses and CPU per scan (the fusion below runs both matchers).
struct PlIcpRun {
  sim::RelationsMetricSplit m;
  std::vector<fw::Se2d> poses;
  double cpu_ms_per_scan = 0;
};
bool add_icp_baselines(const BenchCase& c, const sim::MatcherConfig& cfg, const sim::RelationsMetricSplit& mo,
                       PlIcpRun* pl_icp, sim::BenchJson* json, std::string* err) {
  for (sim::MatcherKind k : sim::icp_baselines()) {
    const std::string who = k == sim::MatcherKind::kPlIcp ? "icp" : "trimicp";
    sim::OdometryRun icp;
    if (!run_odometry(c.log, k, cfg, 0, &icp, err)) return false;
    const auto m = score(c, icp.poses);
    add_split(c.ds, who, m, json);
    json->add(c.ds + "_" + who + "_match_ms_p50", sim::percentile(icp.match_ms, 50));
    json->add(who + "_cpu_ms_per_scan_" + c.ds, sim::cpu_ms_per_scan(icp));
    json->add(c.ds + "_" + who + "_vs_odom_factor", mo.all.trans_mean / m.all.trans_mean);
    std::printf("%s %s:\n%s\n", c.ds.c_str(), sim::matcher_name(k), sim::to_string(m).c_str());
    if (k == sim::MatcherKind::kPlIcp) {
      pl_icp->m = m;
      pl_icp->poses = icp.poses;
      pl_icp->cpu_ms_per_scan = sim::cpu_ms_per_scan(icp);
    }
  }
  return true;
}

// RBSM over kSeeds seeds: per-seed relation errors, and every match's times pooled.
struct RbsmSeedFigures {
  std::vector<double> tm, rm, tmax, ms, cpu_ms, scan_cpu, st, sr, lt, lr;
  // RBSM fused with PL-ICP's increments (fw::IncrementFusion), when PL-ICP's poses are given.
  std::vector<double> ftm, frm, fst, fsr, flt;  // fused and smoothed (the default)
  std::vector<double> fftm, ffst, ffsr, fflt;     // fused, the filter alone
  uint32_t fused_gated = 0;
  double pl_icp_cpu_ms_per_scan = 0;
  size_t failures = 0;
};

// Leaves cfg->rbsm.seed at the last seed (the pairwise experiment runs with it).
bool run_rbsm_seeds(const BenchCase& c, sim::MatcherConfig* cfg, RbsmSeedFigures* f, std::string* err,
                    const std::vector<fw::Se2d>* pl_icp_poses = nullptr) {
  for (int s = 1; s <= kSeeds; ++s) {
    cfg->rbsm.seed = static_cast<uint64_t>(s);
    sim::OdometryRun run;
    if (!run_odometry(c.log, sim::MatcherKind::kRbsm, *cfg, 0, &run, err)) return false;
    const auto m = score(c, run.poses);
    std::printf("%s rbsm seed %d:\n%s\n", c.ds.c_str(), s, sim::to_string(m).c_str());
    f->tm.push_back(m.all.trans_mean);
    f->rm.push_back(m.all.rot_mean_deg);
    f->tmax.push_back(m.all.trans_max);
    f->st.push_back(m.short_rel.trans_mean);
    f->sr.push_back(m.short_rel.rot_mean_deg);
    f->lt.push_back(m.long_rel.trans_mean);
    f->lr.push_back(m.long_rel.rot_mean_deg);
    f->ms.insert(f->ms.end(), run.match_ms.begin(), run.match_ms.end());
    f->cpu_ms.insert(f->cpu_ms.end(), run.match_cpu_ms.begin(), run.match_cpu_ms.end());
    f->scan_cpu.push_back(sim::cpu_ms_per_scan(run));
    f->failures += run.failures;
    if (pl_icp_poses == nullptr) continue;
    std::vector<fw::Se2d> fused;
    uint32_t gated = 0;
    if (!sim::fuse_increments(run.poses, *pl_icp_poses, cfg->fusion, false, &fused, &gated, err)) return false;
    const auto ff = score(c, fused);  // the filter alone, for comparison
    f->fftm.push_back(ff.all.trans_mean);
    f->ffst.push_back(ff.short_rel.trans_mean);
    f->ffsr.push_back(ff.short_rel.rot_mean_deg);
    f->fflt.push_back(ff.long_rel.trans_mean);
    if (!sim::fuse_increments(run.poses, *pl_icp_poses, cfg->fusion, true, &fused, &gated, err)) return false;
    const auto fm = score(c, fused);
    std::printf("%s rbsm seed %d fused with pl-icp increments (%u gated updates):\n%s\n", c.ds.c_str(), s, gated,
                sim::to_string(fm).c_str());
    f->ftm.push_back(fm.all.trans_mean);
    f->frm.push_back(fm.all.rot_mean_deg);
    f->fst.push_back(fm.short_rel.trans_mean);
    f->fsr.push_back(fm.short_rel.rot_mean_deg);
    f->flt.push_back(fm.long_rel.trans_mean);
    f->fused_gated += gated;
  }
  return true;
}

void add_rbsm_figures(const std::string& ds, const RbsmSeedFigures& f, const sim::RelationsMetricSplit& mi,
                      const sim::RelationsMetricSplit& mo, sim::BenchJson* json) {
  json->add(ds + "_trans_err_rbsm", mean(f.tm));
  json->add(ds + "_trans_err_rbsm_std", stddev(f.tm));
  json->add(ds + "_rot_err_rbsm", mean(f.rm));
  json->add(ds + "_rot_err_rbsm_std", stddev(f.rm));
  json->add(ds + "_short_trans_err_rbsm", mean(f.st));
  json->add(ds + "_short_rot_err_rbsm", mean(f.sr));
  json->add(ds + "_long_trans_err_rbsm", mean(f.lt));
  json->add(ds + "_long_rot_err_rbsm", mean(f.lr));
  // The largest relation error over every seed (a maximum), and the seeds' mean of their maxima.
  json->add(ds + "_trans_err_max_rbsm", *std::max_element(f.tmax.begin(), f.tmax.end()));
  json->add(ds + "_trans_err_max_rbsm_seed_mean", mean(f.tmax));
  json->add(ds + "_trans_err_max_icp", mi.all.trans_max);
  json->add(ds + "_trans_err_max_odom", mo.all.trans_max);
  json->add_int(ds + "_rbsm_failures", static_cast<long long>(f.failures));
  json->add_int(ds + "_relations_used", static_cast<long long>(mo.all.used));
  json->add_int(ds + "_short_relations_used", static_cast<long long>(mo.short_rel.used));
  json->add(ds + "_rbsm_match_ms_p50_full", sim::percentile(f.ms, 50));
  json->add(ds + "_rbsm_match_cpu_ms_p50_full", sim::percentile(f.cpu_ms, 50));
  // CPU per scan including the map update (integrate), mean over all scans and seeds.
  json->add("rbsm_cpu_ms_per_scan_" + ds, mean(f.scan_cpu));
  if (f.ftm.empty()) return;
  // RBSM fused with PL-ICP's increments (extension, fw::IncrementFusion): same seeds.
  json->add(ds + "_trans_err_fused", mean(f.ftm));
  json->add(ds + "_rot_err_fused", mean(f.frm));
  json->add(ds + "_short_trans_err_fused", mean(f.fst));
  json->add(ds + "_short_rot_err_fused", mean(f.fsr));
  json->add(ds + "_long_trans_err_fused", mean(f.flt));
  json->add_int(ds + "_fused_gated_updates", static_cast<long long>(f.fused_gated));
  // The same fusion without the backward smoothing pass (the filter's poses).
  json->add(ds + "_trans_err_fused_filter", mean(f.fftm));
  json->add(ds + "_short_trans_err_fused_filter", mean(f.ffst));
  json->add(ds + "_short_rot_err_fused_filter", mean(f.ffsr));
  json->add(ds + "_long_trans_err_fused_filter", mean(f.fflt));
  json->add("fused_cpu_ms_per_scan_" + ds, mean(f.scan_cpu) + f.pl_icp_cpu_ms_per_scan);
}

// Pure Alg. 1 (refine = false, motion_prior = false: both extensions off), one seed: what they change.
bool add_pure_alg1(const BenchCase& c, const sim::MatcherConfig& cfg, sim::BenchJson* json, std::string* err) {
  sim::MatcherConfig pure = cfg;
  pure.rbsm.refine = false;
  pure.rbsm.motion_prior = false;
  pure.rbsm.seed = 1;
  sim::OdometryRun run;
  if (!run_odometry(c.log, sim::MatcherKind::kRbsm, pure, 0, &run, err)) return false;
  const auto m = score(c, run.poses);
  std::printf("%s rbsm pure Alg. 1 (no refinement, no motion prior), seed 1:\n%s\n", c.ds.c_str(), sim::to_string(m).c_str());
  add_split(c.ds, "rbsm_alg1", m, json);
  json->add("rbsm_alg1_cpu_ms_per_scan_" + c.ds, sim::cpu_ms_per_scan(run));
  return true;
}

// The odometry motion prior (extension, RbsmOptions::motion_prior, off by default): the same
// kSeeds seeds with it on, so its effect on the short relations is read against the default.
bool add_motion_prior(const BenchCase& c, const sim::MatcherConfig& cfg, sim::BenchJson* json, std::string* err) {
  sim::MatcherConfig with = cfg;
  with.rbsm.motion_prior = true;
  RbsmSeedFigures f;
  if (!run_rbsm_seeds(c, &with, &f, err)) return false;
  json->add(c.ds + "_trans_err_rbsm_prior", mean(f.tm));
  json->add(c.ds + "_short_trans_err_rbsm_prior", mean(f.st));
  json->add(c.ds + "_short_rot_err_rbsm_prior", mean(f.sr));
  json->add(c.ds + "_long_trans_err_rbsm_prior", mean(f.lt));
  json->add("rbsm_prior_cpu_ms_per_scan_" + c.ds, mean(f.scan_cpu));
  return true;
}

// Alg. 1's stop rule alone (min_iterations = 1), one seed: shows what the 3-round minimum buys.
bool add_stop_rule_alone(const BenchCase& c, const sim::MatcherConfig& cfg, sim::BenchJson* json, std::string* err) {
  sim::MatcherConfig min1 = cfg;
  min1.rbsm.min_iterations = 1;
  min1.rbsm.seed = 1;
  sim::OdometryRun run;
  if (!run_odometry(c.log, sim::MatcherKind::kRbsm, min1, 0, &run, err)) return false;
  const auto m = sim::evaluate_relations(c.rel, sim::make_trajectory(c.log, run.poses));
  json->add(c.ds + "_trans_err_rbsm_min1", m.trans_mean);
  json->add(c.ds + "_rot_err_rbsm_min1", m.rot_mean_deg);
  return true;
}

// Pairwise experiment (consecutive corrected scans, guess ⊕ N(0, 10 cm, 6°)), one seed; skipped
// without reference poses, a matcher that fails is left out.
void add_pairwise(const BenchCase& c, const sim::MatcherConfig& cfg, sim::BenchJson* json, std::string* err) {
  std::vector<sim::CorrectedPose> ref;
  if (!sim::read_corrected_poses(c.d.corrected_poses, &ref, err)) return;
  for (sim::MatcherKind k : {sim::MatcherKind::kRbsm, sim::MatcherKind::kPlIcp, sim::MatcherKind::kIcp}) {
    sim::PairwiseResult pr;
    if (!sim::run_pairwise(c.log, ref, k, cfg, 150, 99, 0.10, 6.0, &pr, err)) continue;
    const auto t = sim::summarize(pr.trans_err_m), r = sim::summarize(pr.rot_err_deg);
    const std::string p = c.ds + "_pairwise_" +
                          (k == sim::MatcherKind::kRbsm ? "rbsm" : k == sim::MatcherKind::kPlIcp ? "icp" : "trimicp");
    json->add(p + "_trans_mean", t.mean);
    json->add(p + "_trans_p95", t.p95);
    json->add(p + "_trans_max", t.max);
    json->add(p + "_rot_mean_deg", r.mean);
    json->add(p + "_rot_p95_deg", r.p95);
    json->add(p + "_rot_max_deg", r.max);
  }
}

// Every figure of one data set; false (printed) when a matcher run fails.
bool bench_case(const BenchCase& c, sim::BenchJson* json, std::string* err) {
  sim::MatcherConfig cfg = sim::default_matcher_config();
  if (c.ds == "intel" && !add_timing_table(c.log, cfg, json, err)) return false;
  std::vector<fw::Se2d> odom;
  for (const auto& s : c.log.scans) odom.push_back(s.odom);
  const auto mo = score(c, odom);
  add_split(c.ds, "odom", mo, json);
  PlIcpRun pl;
  if (!add_icp_baselines(c, cfg, mo, &pl, json, err)) return false;
  const sim::RelationsMetricSplit& mi = pl.m;
  RbsmSeedFigures f;
  f.pl_icp_cpu_ms_per_scan = pl.cpu_ms_per_scan;
  if (!run_rbsm_seeds(c, &cfg, &f, err, &pl.poses)) return false;
  add_rbsm_figures(c.ds, f, mi, mo, json);
  if (!add_pure_alg1(c, cfg, json, err)) return false;
  if (!add_motion_prior(c, cfg, json, err)) return false;
  // intel and fr079 only, as before: the bench has a time budget.
  if (c.ds != "aces" && !add_stop_rule_alone(c, cfg, json, err)) return false;
  add_pairwise(c, cfg, json, err);
  if (c.ds == "intel") {
    // The headline figures: 1000 particles, one thread, over the full intel runs.
    json->add("rbsm_match_ms_p50", sim::percentile(f.ms, 50));
    json->add("rbsm_match_ms_p99", sim::percentile(f.ms, 99));
    json->add("rbsm_match_cpu_ms_p50", sim::percentile(f.cpu_ms, 50));
  }
  return true;
}

}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_rbsm OUT.json\n");
    return 2;
  }
  std::setvbuf(stdout, nullptr, _IOLBF, 0);  // progress visible when redirected
  const auto t_start = std::chrono::steady_clock::now();
  sim::BenchJson json;
  std::string err;
  json.add_int("rbsm_bench_seeds", kSeeds);
  bool all_ok = true;
  for (const std::string ds : {"intel", "fr079", "aces"}) {
    BenchCase c;
    if (!load_case(ds, &c, &err)) {
      std::fprintf(stderr, "bench_rbsm: %s (is MMLFW_DATA_DIR set?)\n", err.c_str());
      all_ok = false;
      continue;
    }
    if (!bench_case(c, &json, &err)) return 1;
  }
  json.add("rbsm_bench_seconds",
           std::chrono::duration<double>(std::chrono::steady_clock::now() - t_start).count());
  if (!json.write(argv[1])) return 1;
  return all_ok ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_rbsm", [&] { return run_main(argc, argv); });
}
