// mml-slam: AntSLAM (Ch. 3) from a raw CARMEN log — the map of your own building. See --help.
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <utility>
#include <string>

#include "sim/common/cli_main.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/slam/selfmap.h"
#include "sim/slam/slam_pipeline.h"

namespace {

const char* kHelp =
    "usage: mml-slam --log RAW.clf[.gz] [options]\n"
    "       mml-slam --dataset intel|fr079|aces|mit-killian|fr-clinic [options]\n"
    "\n"
    "AntSLAM (dissertation Ch. 3): RBSM scan matching builds the map in fragments, pRANSAM closes\n"
    "loops between fragments, an ant colony (or Levenberg-Marquardt) corrects every loop.\n"
    "\n"
    "outputs (each optional; nothing is written unless asked):\n"
    "  --trajectory FILE     corrected pose of every scan, 't x y theta' per line (t = ipc timestamp);\n"
    "                        score it with: mml-carmen eval RELATIONS FILE\n"
    "  --rbsm-trajectory FILE  the same for the front end alone (before AntSLAM; see --front)\n"
    "  --map FILE.yaml       ROS map_server map (YAML + PGM beside it); compile it with mml-mapc\n"
    "  --svg FILE.svg        picture of fragments, edges and closed loops (FILE.png: a PNG)\n"
    "  --relations FILE      print the relations metric (Kuemmerle et al. 2009) of the front end and AntSLAM\n"
    "                        (default with --dataset: the data set's relations; mit-killian: relations\n"
    "                        between its consecutive GMapping-corrected poses); with --dataset also the whole\n"
    "                        trajectory against the data set's corrected poses (RMS after a rigid alignment)\n"
    "options:\n"
    "  --optimizer aco|lm    loop optimiser (default aco: the ant colony of Eq. 3.13-3.14)\n"
    "  --final-refine on|off  at the end of the run, refine every fragment frame against every edge at once\n"
    "                        (Gauss-Newton on the whole graph, frozen loops included; an extension of Alg. 3,\n"
    "                        fw::antslam::GraphRefine; default on; off = Alg. 3 as published)\n"
    "  --pair-closures on|off  a loop closure outside the drift gate is still closed when it agrees with one of\n"
    "                        the last two fragments' through the short chains between them (an extension of\n"
    "                        Alg. 3, firmware/antslam/closure_pairs.h; default on; off = the gate alone)\n"
    "  --pair-isolation on|off  such a pair is closed only when both fragments' points fit nowhere else on the old\n"
    "                        map around the candidate as well (firmware/antslam/closure_isolation.h; default on)\n"
    "  --gate-isolation on|off  a closure within the gate must be isolated too, among the rivals the gate also\n"
    "                        admits; if not, it waits for a pair (default on; off = Alg. 3's gate alone)\n"
    "  --edge-model sensor|motion  edge covariance: from poses weighted by the sensor model (Eq. 3.9, default)\n"
    "                        or the front end's propagated motion covariance (Eq. 3.4; closures: --closure-sigma)\n"
    "  --front fused|fused-filter|rbsm  front end: RBSM fused with PL-ICP's laser-to-laser increments and\n"
    "                        smoothed backwards (default; fw::IncrementFusion + fw::smooth_fusion_steps, an\n"
    "                        extension: firmware/rbsm/README.md), the same without the backward pass, or RBSM\n"
    "                        alone (the dissertation's)\n"
    "  --traversal off|on|tracked  fragment borders, convex hulls and EXPLORE -> TRAVERSAL (Sec. 3.4): a\n"
    "                        revisited fragment is traversed, not mapped again (tracked: the scan is also fitted\n"
    "                        on the fragment every keyframe step); off (default, measured better on the logs):\n"
    "                        every revisit opens new fragments that close loops with the old ones\n"
    "  --ants N              ants per iteration (default 20)\n"
    "  --iterations N        ant-colony iterations per loop (default 5000)\n"
    "  --fragment-length M   metres travelled per fragment (default 5; 10 for long loops)\n"
    "  --seed N              seed (same seed, same log: same map; default 1)\n"
    "  --workers N           threads for RBSM, pRANSAM and the ants (default 2; results do not depend on it)\n"
    "  --max-scans N         only the first N scans (default: all)\n"
    "  --resolution M        map cell size (default 0.05)\n"
    "  --max-range M         laser range used for the map (default 25)\n"
    "  --quiet               no progress line\n"
    "tuning (defaults in fw::antslam::AntSlamOptions):\n"
    "  --sigma-xy M          front-end drift, metres per sqrt(metre travelled) (Eq. 3.4 G; default 0.02)\n"
    "  --sigma-theta R       front-end drift, radians per sqrt(metre travelled) (default 0.004)\n"
    "  --gate CHI2           loop-closure gate on (h - x) (default 16.3)\n"
    "  --closure-sigma M     loop-closure std in metres (Sigma_h; the angle scales with it, 0.05 m = 1 deg)\n"
    "  --closure-refine none|pransam|both  refine the loop closure on the distance field: not at all, pRANSAM's\n"
    "                        hypothesis, or both it and the prediction, keeping the better fit (default pransam)\n"
    "  --min-gap N           fragments between the two ends of a loop, at least (default 3)\n"
    "  --min-quality Q       pRANSAM quality a closure needs, 0..1 (default 0.55)\n"
    "  --verbose             one line per closed loop\n"
    "  --help                this text\n";

int fail(const std::string& msg) {
  std::fprintf(stderr, "mml-slam: %s\n", msg.c_str());
  return 2;
}

bool parse_u64(const std::string& s, unsigned long long lo, unsigned long long hi, unsigned long long* out) {
  if (s.empty() || s[0] == '-' || s[0] == '+') return false;
  char* end = nullptr;
  errno = 0;
  const unsigned long long v = std::strtoull(s.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < lo || v > hi) return false;
  *out = v;
  return true;
}

bool parse_pos(const std::string& s, double lo, double hi, double* out) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || *end != '\0' || !std::isfinite(v) || v < lo || v > hi) return false;
  *out = v;
  return true;
}

// The command line: what to read, what to write and how to map.
struct SlamArgs {
  std::string log_path, dataset;
  std::string traj_path, rbsm_traj_path, map_path, svg_path, rel_path;
  sim::SlamConfig cfg;
  double resolution = 0.05, max_range = 25.0;
  bool quiet = false, verbose = false;
};

// An option group's verdict on one option and its value.
enum class Parsed { kNotMine, kOk, kFailed };

Parsed failed(const std::string& msg) {
  fail(msg);
  return Parsed::kFailed;
}

// The input and the output files.
Parsed parse_file_option(const std::string& a, const std::string& v, SlamArgs* o) {
  if (a == "--log") {
    o->log_path = v;
  } else if (a == "--dataset") {
    o->dataset = v;
  } else if (a == "--trajectory") {
    o->traj_path = v;
  } else if (a == "--rbsm-trajectory") {
    o->rbsm_traj_path = v;
  } else if (a == "--map") {
    if (v.size() < 6 || v.substr(v.size() - 5) != ".yaml") return failed("--map: '" + v + "' must end in .yaml");
    o->map_path = v;
  } else if (a == "--svg") {
    o->svg_path = v;
  } else if (a == "--relations") {
    o->rel_path = v;
  } else {
    return Parsed::kNotMine;
  }
  return Parsed::kOk;
}

// An on|off switch.
Parsed parse_on_off(const std::string& a, const std::string& v, bool* flag) {
  if (v != "on" && v != "off") return failed(a + ": '" + v + "' is not on or off");
  *flag = v == "on";
  return Parsed::kOk;
}

// The "options" of the help text: optimiser, colony size, fragments, seed, threads, map raster.
Parsed parse_run_option(const std::string& a, const std::string& v, SlamArgs* o) {
  sim::SlamConfig& cfg = o->cfg;
  unsigned long long u = 0;
  double d = 0;
  if (a == "--optimizer") {
    if (v == "aco") cfg.slam.optimizer = fw::antslam::LoopOptimizer::kAntColony;
    else if (v == "lm") cfg.slam.optimizer = fw::antslam::LoopOptimizer::kLevenbergMarquardt;
    else return failed("--optimizer: '" + v + "' is not aco or lm");
  } else if (a == "--final-refine") {
    return parse_on_off(a, v, &cfg.slam.final_refinement);
  } else if (a == "--pair-closures") {
    return parse_on_off(a, v, &cfg.slam.pair_closures);
  } else if (a == "--pair-isolation") {
    return parse_on_off(a, v, &cfg.slam.pair_isolation);
  } else if (a == "--gate-isolation") {
    return parse_on_off(a, v, &cfg.slam.gate_isolation);
  } else if (a == "--edge-model") {
    if (v == "sensor") cfg.slam.edge_model = fw::antslam::EdgeModel::kSensorModel;
    else if (v == "motion") cfg.slam.edge_model = fw::antslam::EdgeModel::kMotionModel;
    else return failed("--edge-model: '" + v + "' is not sensor or motion");
  } else if (a == "--traversal") {
    cfg.slam.traversal = v == "on" || v == "tracked";
    cfg.slam.traversal_tracking = v == "tracked";
    if (!cfg.slam.traversal && v != "off") return failed("--traversal: '" + v + "' is not off, on or tracked");
  } else if (a == "--front") {
    cfg.fuse_front = v == "fused" || v == "fused-filter";
    cfg.front.fusion_smooth = v == "fused";
    if (!cfg.fuse_front && v != "rbsm") return failed("--front: '" + v + "' is not fused, fused-filter or rbsm");
  } else if (a == "--ants") {
    if (!parse_u64(v, 1, 1024, &u)) return failed("--ants: '" + v + "' is not an integer in 1..1024");
    cfg.slam.aco.ants = static_cast<std::uint32_t>(u);
  } else if (a == "--iterations") {
    if (!parse_u64(v, 1, 1000000, &u)) return failed("--iterations: '" + v + "' is not an integer in 1..1000000");
    cfg.slam.aco.iterations = static_cast<std::uint32_t>(u);
  } else if (a == "--fragment-length") {
    if (!parse_pos(v, 0.5, 100.0, &d)) return failed("--fragment-length: '" + v + "' is not a number of metres in 0.5..100");
    cfg.slam.fragment_length_m = d;
  } else if (a == "--seed") {
    if (!parse_u64(v, 0, ~0ull, &u)) return failed("--seed: '" + v + "' is not a non-negative integer");
    cfg.slam.seed = u;
    cfg.slam.aco.seed = u;
    cfg.front.rbsm.seed = u;
  } else if (a == "--workers") {
    if (!parse_u64(v, 1, 16, &u)) return failed("--workers: '" + v + "' is not an integer in 1..16");
    cfg.workers = static_cast<int>(u);
  } else if (a == "--max-scans") {
    if (!parse_u64(v, 1, 10000000, &u)) return failed("--max-scans: '" + v + "' is not a positive integer");
    cfg.max_scans = u;
  } else if (a == "--resolution") {
    if (!parse_pos(v, 0.01, 1.0, &o->resolution)) return failed("--resolution: '" + v + "' is not a cell size in 0.01..1 m");
  } else if (a == "--max-range") {
    if (!parse_pos(v, 1.0, 100.0, &o->max_range)) return failed("--max-range: '" + v + "' is not a range in 1..100 m");
  } else {
    return Parsed::kNotMine;
  }
  return Parsed::kOk;
}

// The "tuning" of the help text: drift, loop-closure gate and acceptance.
Parsed parse_tuning_option(const std::string& a, const std::string& v, fw::antslam::AntSlamOptions* slam) {
  unsigned long long u = 0;
  double d = 0;
  if (a == "--sigma-xy") {
    if (!parse_pos(v, 1e-4, 10.0, &d)) return failed("--sigma-xy: '" + v + "' is not a number in 1e-4..10");
    slam->var_xy_per_m = d * d;
  } else if (a == "--sigma-theta") {
    if (!parse_pos(v, 1e-5, 1.0, &d)) return failed("--sigma-theta: '" + v + "' is not a number in 1e-5..1");
    slam->var_theta_per_m = d * d;
  } else if (a == "--gate") {
    if (!parse_pos(v, 0.1, 1e6, &d)) return failed("--gate: '" + v + "' is not a number in 0.1..1e6");
    slam->closure_gate_chi2 = d;
  } else if (a == "--closure-sigma") {
    if (!parse_pos(v, 1e-3, 10.0, &d)) return failed("--closure-sigma: '" + v + "' is not a number of metres in 0.001..10");
    slam->closure_sigma_xy = d;
    slam->closure_sigma_theta = d * 0.349;  // 5 cm ↔ 1°
  } else if (a == "--closure-refine") {
    if (v == "none") {
      slam->refine_closure = false;
    } else if (v == "pransam") {
      slam->refine_closure = true;
      slam->prefer_prediction_margin = -1.0f;
    } else if (v == "both") {
      slam->refine_closure = true;
      slam->prefer_prediction_margin = 0.02f;
    } else {
      return failed("--closure-refine: '" + v + "' is not none, pransam or both");
    }
  } else if (a == "--min-gap") {
    if (!parse_u64(v, 1, 100000, &u)) return failed("--min-gap: '" + v + "' is not a positive integer");
    slam->min_fragment_gap = static_cast<std::uint32_t>(u);
  } else if (a == "--min-quality") {
    if (!parse_pos(v, 0.0, 1.0, &d)) return failed("--min-quality: '" + v + "' is not a number in 0..1");
    slam->min_closure_quality = static_cast<float>(d);
  } else {
    return Parsed::kNotMine;
  }
  return Parsed::kOk;
}

// Reads the command line into *o. Set: the run ends here with that exit code (--help, or an error
// already reported).
std::optional<int> parse_args(int argc, char** argv, SlamArgs* o) {
  o->cfg.workers = 2;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kHelp, stdout);
      return 0;
    }
    if (a == "--quiet") {
      o->quiet = true;
      continue;
    }
    if (a == "--verbose") {
      o->verbose = true;
      continue;
    }
    if (a.rfind("--", 0) != 0) return fail("unexpected argument '" + a + "' (see --help)");
    if (i + 1 >= argc) return fail(a + ": missing value (see --help)");
    const std::string v = argv[++i];
    Parsed p = parse_file_option(a, v, o);
    if (p == Parsed::kNotMine) p = parse_run_option(a, v, o);
    if (p == Parsed::kNotMine) p = parse_tuning_option(a, v, &o->cfg.slam);
    if (p == Parsed::kFailed) return 2;
    if (p == Parsed::kNotMine) return fail("unknown option '" + a + "' (see --help)");
  }
  if (o->log_path.empty() == o->dataset.empty()) {
    return fail("give exactly one of --log FILE or --dataset NAME (see --help)");
  }
  return std::nullopt;
}

// Outputs go into existing directories: say so now, not after minutes of mapping. Empty: all exist.
std::string missing_output_dir(const SlamArgs& o) {
  for (const auto& [opt, path] : {std::pair<const char*, const std::string*>{"--trajectory", &o.traj_path},
                                  {"--rbsm-trajectory", &o.rbsm_traj_path},
                                  {"--map", &o.map_path},
                                  {"--svg", &o.svg_path}}) {
    if (path->empty()) continue;
    const std::filesystem::path dir = std::filesystem::path(*path).parent_path();
    std::error_code ec;
    if (!dir.empty() && !std::filesystem::is_directory(dir, ec)) {
      return std::string(opt) + ": directory '" + dir.string() + "' does not exist";
    }
  }
  return "";
}

// The log and the relations to score against. Set: the exit code of a failure already reported.
// *reference: the data set's corrected poses at every scan (--dataset with corrected poses; else empty).
std::optional<int> load_inputs(SlamArgs* o, sim::CarmenLog* log, std::vector<sim::Relation>* rel,
                               std::vector<fw::Se2d>* reference) {
  std::string err;
  sim::EvalDataset ds;
  std::string ds_relations;
  if (!o->dataset.empty()) {
    if (!sim::find_eval_dataset(o->dataset, &ds, &err)) {
      return fail("--dataset: " + err + " (names: intel, fr079, aces, mit-killian, fr-clinic; data under MMLFW_DATA_DIR)");
    }
    o->log_path = ds.raw_log;
    if (o->rel_path.empty()) o->rel_path = ds_relations = ds.relations;
  }
  const std::string missing_dir = missing_output_dir(*o);
  if (!missing_dir.empty()) return fail(missing_dir);
  if (!sim::read_carmen_log(o->log_path, sim::CarmenReadOptions{}, log, &err)) return fail(err);
  if (!o->dataset.empty() && o->rel_path == ds_relations) {
    if (!sim::slam_dataset_relations(*log, ds, rel, &err)) return fail("--dataset: " + err);
  } else if (!o->rel_path.empty() && !sim::read_relations(o->rel_path, rel, &err)) {
    return fail("--relations: " + err);
  }
  if (log->scans.empty()) return fail(o->log_path + ": no laser scans in the log");
  if (!o->dataset.empty() && !ds.corrected_poses.empty() && !sim::reference_at_every_scan_of(*log, ds, reference, &err)) {
    return fail("--dataset: " + err);
  }
  return std::nullopt;
}

// The summary lines on stdout: loops, edge covariances, time, and with --verbose every closed loop.
void print_summary(const sim::CarmenLog& log, const sim::SlamConfig& cfg, const sim::SlamRun& run, bool verbose) {
  const double log_s = log.scans.size() > 1 ? log.scans[run.poses.size() - 1].ipc_timestamp - log.scans[0].ipc_timestamp : 0;
  std::printf("mml-slam: %zu scans, %zu fragments, %u loops closed, %u of them by a consistent pair (%u candidates: %u below "
              "quality, %u outside the gate, %u within it but not isolated; %u consistent pairs not isolated)\n",
              run.poses.size(), run.fragments.size(), run.stats.loops, run.stats.pair_loops, run.stats.candidates,
              run.stats.rejected_quality, run.stats.rejected_gate, run.stats.gated_not_isolated,
              run.stats.pairs_not_isolated);
  if (cfg.slam.edge_model == fw::antslam::EdgeModel::kSensorModel) {
    std::printf("mml-slam: edge covariances from the sensor model (Eq. 3.9): %u, fallback (too few points: Eq. 3.4, or closure-sigma for a closure): %u\n",
                run.stats.sensor_fits, run.stats.motion_fallbacks);
  }
  if (cfg.slam.traversal) {
    std::printf("mml-slam: %u borders cut (%u fragments left with no point on one side), %u entries into a TRAVERSAL fragment, %u scans traversed (not mapped; %u fitted on the fragment)\n",
                run.stats.borders, run.stats.no_border, run.stats.traversals, run.stats.traversal_scans, run.stats.traversal_fits);
  }
  std::printf("mml-slam: front end %.1f s + AntSLAM %.1f s (pRANSAM %.0f ms, %s %.0f ms) for %.0f s of log\n", run.frontend_s,
              run.backend_s, run.matcher_ms,
              cfg.slam.optimizer == fw::antslam::LoopOptimizer::kAntColony ? "ant colony" : "LM", run.optimizer_ms, log_s);
  if (cfg.slam.final_refinement) {
    std::printf("mml-slam: final refinement of the whole graph: W %.1f -> %.1f in %u Gauss-Newton steps (%u CG iterations), %.1f ms\n",
                run.stats.graph_initial_cost, run.stats.graph_final_cost, run.stats.graph_iterations,
                run.stats.graph_cg_iterations, 1e-6 * static_cast<double>(run.stats.graph_ns));
  }
  if (verbose) {
    for (const auto& c : run.closures) {
      std::printf("loop %u -> %u: %u edges, quality %.2f, chi2 %.1f, open %.3f m, W %.1f -> %.1f", c.from, c.to,
                  c.path_edges, c.quality, c.gate_chi2, c.shift_m, c.cost_before, c.cost_after);
      if (c.pair_with > 0) {
        std::printf(", beyond the gate: paired with fragment %u (cycle chi2 %.1f)", c.pair_with - 1, c.pair_chi2);
        if (cfg.slam.pair_isolation) std::printf(", isolated (z %.1f)", c.isolation_z);
      }
      std::printf("\n");
    }
  }
}

// The files asked for: 0, or the exit code of the failure reported.
int write_outputs(const SlamArgs& o, const sim::CarmenLog& log, const sim::SlamRun& run) {
  std::string err;
  if (!o.traj_path.empty() && !sim::write_trajectory(o.traj_path, sim::make_trajectory(log, run.poses), &err)) {
    return fail("--trajectory: " + err);
  }
  if (!o.rbsm_traj_path.empty() &&
      !sim::write_trajectory(o.rbsm_traj_path, sim::make_trajectory(log, run.frontend), &err)) {
    return fail("--rbsm-trajectory: " + err);
  }
  if (!o.map_path.empty() && !sim::write_slam_map(log, run.poses, o.resolution, o.max_range, o.map_path, &err)) {
    return fail("--map: " + err);
  }
  if (!o.svg_path.empty() && !sim::write_slam_svg(run, "AntSLAM: " + o.log_path, o.svg_path, &err)) {
    return fail("--svg: " + err);
  }
  return 0;
}

int run(int argc, char** argv) {
  SlamArgs o;
  if (const std::optional<int> exit_code = parse_args(argc, argv, &o)) return *exit_code;
  sim::CarmenLog log;
  std::vector<sim::Relation> rel;
  std::vector<fw::Se2d> reference;
  if (const std::optional<int> exit_code = load_inputs(&o, &log, &rel, &reference)) return *exit_code;
  const auto t0 = std::chrono::steady_clock::now();
  if (!o.quiet) {
    o.cfg.progress = [t0](std::size_t done, std::size_t total, const char* phase) {
      const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      std::fprintf(stderr, "\rmml-slam: %s %zu/%zu scans, %.0f s   ", phase, done, total, s);
      std::fflush(stderr);
    };
  }
  sim::SlamRun run;
  std::string err;
  if (!sim::run_slam(log, o.cfg, &run, &err)) {
    if (!o.quiet) std::fputc('\n', stderr);
    std::fprintf(stderr, "mml-slam: %s\n", err.c_str());
    return 1;
  }
  if (!o.quiet) std::fputc('\n', stderr);
  print_summary(log, o.cfg, run, o.verbose);
  if (!rel.empty()) {
    const auto mf = sim::evaluate_relations(rel, sim::make_trajectory(log, run.frontend));
    const auto ms = sim::evaluate_relations(rel, sim::make_trajectory(log, run.poses));
    std::printf("relations, front end alone: %s\nrelations, AntSLAM:          %s\n", sim::to_string(mf).c_str(),
                sim::to_string(ms).c_str());
    if (!run.alg3_poses.empty()) {
      const auto ma = sim::evaluate_relations(rel, sim::make_trajectory(log, run.alg3_poses));
      std::printf("relations, AntSLAM before the final refinement (Alg. 3 as published): %s\n", sim::to_string(ma).c_str());
    }
  }
  if (!reference.empty()) {
    // Whole trajectory (sim/slam/selfmap.h): a loop closed on a look-alike bends it all.
    sim::RigidAlignment2d af, as;
    if (!sim::align_rigid_2d(reference, run.frontend, &af, &err) || !sim::align_rigid_2d(reference, run.poses, &as, &err)) {
      std::fprintf(stderr, "mml-slam: whole-trajectory check: %s\n", err.c_str());
      return 1;
    }
    std::printf("whole trajectory against the corrected poses (rigid alignment, %zu scans): front end RMS %.3f m (max "
                "%.3f m), AntSLAM RMS %.3f m (max %.3f m)\n",
                as.pairs, af.rms_m, af.max_m, as.rms_m, as.max_m);
  }
  return write_outputs(o, log, run);
}

}  // namespace

int main(int argc, char** argv) {
  return sim::guarded_main("mml-slam", [&] { return run(argc, argv); });
}
