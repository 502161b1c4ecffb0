// mml-eval: MML vs MCL vs hand-off on the real logs (issue 6 §5). Full runs with flags; the
// 20-minute benchmark is bench_mml (scripts/bench.sh mml).
//   mml-eval [--datasets intel,aces] [--trials 10] [--mcl-trials N] [--steps 200] [--mit-steps 300]
//            [--seed 1] [--threads 2] [--config 3] [--all-configs] [--mcl-particles 30000]
//            [--mcl-particles-mit 120000] [--no-handoff] [--no-mcl] [--no-unknown] [--out build/eval/mml]
//            [--correct] [--reduce] [--no-unique] [--compare-local-map-options]
//   --correct / --reduce: local map correction (Eq. 5.23–5.27) / reduction (Eq. 5.28–5.30) on in
//   every MML run (labels mml-C3+corr, +red); --compare-local-map-options: the main configuration
//   also with correction and with reduction, side by side (JSON keys <dataset>_mml_c3_corr_*, _red_*).
//
// Localizer product metrics (mml-track; sim/eval/mml_eval/localize_eval.h, README "Localizer product
// metrics"):
//   mml-eval --localize [--datasets intel,fr101] [--whole-runs 3] [--steps 0] [--fix-trials 10]
//            [--fix-steps 200] [--mcl-trials 10] [--mcl-datasets intel,fr079] [--kidnap-runs 2]
//            [--kidnap-datasets intel,fr079,aces] [--no-unknown] [--seed 1] [--threads 2] [--out DIR]
//            [--no-pool]   (MML best-cluster support not pooled over consistent steps: Eq. 5.17 per step)
//            [--no-unmapped-space]   (inner unknown regions count as misses: firmware/map/unmapped_space.h)
//            [--no-refit]   (a better alias rival within the prediction's PL is a fault: TrackOptions::refit_at_better_rival)
//   --help prints the usage.
//   --steps 0 = whole-log runs continue to the end of the log (else at most that many steps).
//   --global ref|live|live-deadline: mml-track's global search schedule (mml_systems.h; issue 14)
// The generated corpus (issue 55; sim/cli/corpus/README.md):
//   mml-eval --corpus N [--seed S] [--jobs 2] [--out build/eval/corpus] [--pictures 4] [--no-timing]
// Any building by path (implies --localize; only this building unless --datasets is given):
//   mml-eval --log LOG.clf[.gz] --map MAP.yaml|MAP.mmap --reference POSES.txt|CORRECTED.log[.gz]
//            [--relations R] [--name NAME] [--synthetic-odometry]
//   POSES.txt rows: "flaser_index ipc_timestamp logger_timestamp x y theta" (like
//   intel.corrected-poses.txt); a CARMEN reference log must have one scan per scan of LOG.
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "sim/eval/mml_eval/localize_eval.h"
#include "sim/eval/mml_eval/mml_eval_run.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/cli/corpus/corpus_cli.h"
#include "sim/common/cli_main.h"
#include "sim/io/datasets.h"

namespace {
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) if (!x.empty()) out.push_back(x);
  return out;
}
const char kUsage[] =
    "usage: mml-eval [--datasets intel,aces] [--trials 10] [--mcl-trials N] [--steps 200] [--mit-steps 300]\n"
    "                [--seed 1] [--threads 2] [--config 3] [--all-configs] [--mcl-particles 30000]\n"
    "                [--mcl-particles-mit 120000] [--no-handoff] [--no-mcl] [--no-unknown] [--out build/eval/mml]\n"
    "                [--correct] [--reduce] [--no-unique] [--compare-local-map-options]\n"
    "       mml-eval --localize [--datasets intel,fr101] [--whole-runs 3] [--steps 0] [--fix-trials 10]\n"
    "                [--fix-steps 200] [--mcl-trials 10] [--mcl-datasets intel,fr079] [--kidnap-runs 2]\n"
    "                [--kidnap-datasets intel,fr079,aces] [--no-unknown] [--seed 1] [--threads 2] [--out DIR]\n"
    "                [--no-pool] [--no-unmapped-space] [--no-refit] [--global ref|live|live-deadline] [--global-period 1..8]\n"
    "                [--odom-noise TT,TR,RR,RT]\n"
    "                [--odom-noise-per-step M,DEG] [--no-confirm-fix] [--no-confirm-on-past-scans]\n"
    "                [--no-steady-fit-trust] [--valley-one-mode] [--no-valley-one-mode] [--keep-valley-information]\n"
    "                [--no-cover-unfused] [--confidence-cap-pred-pl]\n"
    "       mml-eval --log LOG.clf[.gz] --map MAP.yaml|MAP.mmap --reference POSES.txt|CORRECTED.log[.gz]\n"
    "                [--relations R] [--name NAME] [--synthetic-odometry]   (any building by path)\n"
    "Datasets (--datasets, --mcl-datasets, --kidnap-datasets): intel, fr079, aces, mit-killian, fr-clinic,\n"
    "fr101, fr-campus, read from ../shared/data (MMLFW_DATA_DIR). --steps: localizer steps per kidnapped\n"
    "trial (default 200, as scripts/bench.sh mml); with --localize / --log the cap of a whole-log run\n"
    "(default 0 = to the end of the log). --threads: worker threads (default 2, as mml-sim).\n"
    "Your own building: --log RAW.clf --map MAP.yaml or MAP.mmap (a compiled image: its relation table is\n"
    "used) --reference REF (REF: 'mml-carmen reference' rows or a CARMEN log with one pose per scan of\n"
    "RAW). --odom-noise: the tracker's odometry noise model (mmlfw's config key odom_noise; default\n"
    "0.2,0.2,0.2,0.2). --odom-noise-per-step: σ per scan step that does not follow the motion, metres\n"
    "and degrees (odom_noise_per_step; default 0,0).\n"
    "--no-confirm-fix: MML's fix `localized` on its first consistent scan\n"
    "(TrackOptions::confirm_fix). --no-confirm-on-past-scans: MML's fix confirmed forward only, not on the\n"
    "scans before it first (TrackOptions::confirm_fix_on_past_scans, on by default). --no-steady-fit-trust:\n"
    "an alias rival beyond the prediction stays exempt when the fit fell at z 1.645\n"
    "(TrackOptions::alias_trust_needs_steady_fit). --valley-one-mode: on a trusted track a rival in the fix's own\n"
    "cost valley does not make the scan ambiguous (TrackOptions::alias_valley_is_one_mode, on by default;\n"
    "--no-valley-one-mode turns it off). --keep-valley-information: with it, such a scan's information along the\n"
    "valley is fused, not dropped (TrackOptions::alias_valley_drops_information). --no-cover-unfused: the PL of a\n"
    "scan not fused (standing robot) leaves out the update the scan would make\n"
    "(TrackOptions::cover_unfused_update). --confidence-cap-pred-pl: the scan's confidence extent capped at\n"
    "the prediction's PL alone (TrackOptions::confidence_cap_with_update). --cap-unpinned-scans: that cap\n"
    "also for a scan open to the alert limit along both axes (TrackOptions::confidence_cap_needs_a_pinned_axis).\n"
    "--outside-map-any-pose: after a lost track, `outside-map` from the scan at any dead-reckoned pose, also\n"
    "after a kidnap or divergence (TrackOptions::outside_map_needs_clean_exit, on by default).\n"
    "Definitions of every figure: sim/eval/mml_eval/README.md.\n";
int usage(const char* msg) {
  std::fprintf(stderr, "mml-eval: %s\n%s", msg, kUsage);
  return 2;
}
// Errors of the evaluation library may already carry the tool's name: print it once.
void print_error(const std::string& err) {
  std::fprintf(stderr, "%s%s\n", err.rfind("mml-eval:", 0) == 0 ? "" : "mml-eval: ", err.c_str());
}
std::string known_dataset_names() {
  std::string names;
  for (const sim::Dataset& d : sim::datasets()) {
    if (d.raw_log.empty() && d.corrected_log.empty()) continue;
    names += (names.empty() ? "" : ", ") + d.name;
  }
  return names;
}
// Every dataset name given on the command line, checked before anything runs (a bad name used to
// fail only when its turn came, after the figures of the datasets before it had been printed).
bool check_dataset_names(const std::string& option, const std::vector<std::string>& names, const std::string& custom) {
  for (const std::string& n : names) {
    if (!custom.empty() && n == custom) continue;
    const sim::Dataset* d = sim::find_dataset(n);
    if (d == nullptr || (d->raw_log.empty() && d->corrected_log.empty())) {
      std::fprintf(stderr,
                   "mml-eval: %s: unknown dataset '%s' (known: %s; your own building: --log LOG --map MAP.yaml "
                   "--reference REF, see --help)\n",
                   option.c_str(), n.c_str(), known_dataset_names().c_str());
      return false;
    }
  }
  return true;
}
}  // namespace

static int run_main(int argc, char** argv) {
  sim::mmleval::EvalPlan plan;
  plan.out_dir = "build/eval/mml";
  plan.trial.max_steps = 200;  // as scripts/bench.sh mml and the README (≤ 200 steps per trial)
  plan.trial_mit = plan.trial;
  plan.trial_mit.max_steps = 300;
  sim::mmleval::LocalizePlan lp;
  lp.out_dir = "build/eval/localize";
  bool localize = false, datasets_given = false, mcl_datasets_given = false, kidnap_datasets_given = false;
  sim::mmleval::DatasetFiles files;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--help" || a == "-h") {
      std::fputs(kUsage, stdout);
      return 0;
    }
    auto next = [&](long lo, long hi) -> long {
      if (i + 1 >= argc) { std::exit(usage(("missing value for " + a).c_str())); }
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < lo || v > hi) std::exit(usage(("bad value for " + a + ": '" + argv[i] + "'").c_str()));
      return v;
    };
    auto str = [&]() -> std::string {
      if (i + 1 >= argc) std::exit(usage(("missing value for " + a).c_str()));
      return argv[++i];
    };
    if (a == "--localize") localize = true;
    else if (a == "--log") { files.log = str(); localize = true; }
    else if (a == "--map") { files.map_yaml = str(); localize = true; }
    else if (a == "--reference") { files.reference = str(); localize = true; }
    else if (a == "--relations") files.relations = str();
    else if (a == "--name") files.name = str();
    else if (a == "--synthetic-odometry") files.synthetic_odometry = true;
    else if (a == "--pool") lp.pool_cluster_support = true;
    else if (a == "--no-pool") lp.pool_cluster_support = false;
    else if (a == "--no-unmapped-space") lp.unmapped_space = false;
    else if (a == "--no-refit") lp.track.refit_at_better_rival = false;
    else if (a == "--keep-support") lp.keep_support_across_empty_steps = true;
    else if (a == "--no-keep-support") lp.keep_support_across_empty_steps = false;
    else if (a == "--keep-contested") lp.keep_support_across_contested_steps = true;
    else if (a == "--no-keep-contested") lp.keep_support_across_contested_steps = false;
    else if (a == "--no-confirm-fix") { lp.track.confirm_fix = false; localize = true; }
    else if (a == "--no-confirm-on-past-scans") { lp.track.confirm_fix_on_past_scans = false; localize = true; }
    else if (a == "--no-steady-fit-trust") { lp.track.alias_trust_needs_steady_fit = false; localize = true; }
    else if (a == "--valley-one-mode") { lp.track.alias_valley_is_one_mode = true; localize = true; }
    else if (a == "--no-valley-one-mode") { lp.track.alias_valley_is_one_mode = false; localize = true; }
    else if (a == "--keep-valley-information") { lp.track.alias_valley_drops_information = false; localize = true; }
    else if (a == "--no-cover-unfused") { lp.track.cover_unfused_update = false; localize = true; }
    else if (a == "--confidence-cap-pred-pl") { lp.track.confidence_cap_with_update = false; localize = true; }
    else if (a == "--cap-unpinned-scans") { lp.track.confidence_cap_needs_a_pinned_axis = false; localize = true; }
    else if (a == "--outside-map-any-pose") { lp.track.outside_map_needs_clean_exit = false; localize = true; }
    else if (a == "--odom-noise") {
      const std::string v = str();
      if (!sim::mmleval::set_odom_noise(v, &lp.track)) {
        return usage(("--odom-noise: '" + v + "' is not four numbers TT,TR,RR,RT in 0..10").c_str());
      }
      localize = true;
    }
    else if (a == "--odom-noise-per-step") {
      const std::string v = str();
      if (!sim::mmleval::set_odom_noise_per_step(v, &lp.track)) {
        return usage(("--odom-noise-per-step: '" + v + "' is not M,DEG (metres in 0..1, degrees in 0..28)").c_str());
      }
      localize = true;
    }
    else if (a == "--global") {
      const std::string m = str();
      if (m == "ref") sim::mmleval::set_eval_global_mode(sim::mmleval::EvalGlobalMode::kReference);
      else if (m == "live") sim::mmleval::set_eval_global_mode(sim::mmleval::EvalGlobalMode::kLive);
      else if (m == "live-deadline") sim::mmleval::set_eval_global_mode(sim::mmleval::EvalGlobalMode::kLiveDeadline);
      else std::exit(usage(("bad value for --global: '" + m + "' (ref, live, live-deadline)").c_str()));
    }
    else if (a == "--global-period") sim::mmleval::set_eval_global_period(static_cast<std::uint32_t>(next(1, 8)));
    else if (a == "--whole-runs") lp.whole_runs = next(0, 1000);
    else if (a == "--fix-trials") lp.fix_trials = next(0, 1000);
    else if (a == "--fix-steps") lp.fix_steps = next(1, 100000);
    else if (a == "--mcl-datasets") { lp.mcl_datasets = split(str()); mcl_datasets_given = true; }
    else if (a == "--kidnap-runs") lp.kidnap_runs = next(0, 1000);
    else if (a == "--kidnap-datasets") { lp.kidnap_datasets = split(str()); kidnap_datasets_given = true; }
    else if (a == "--datasets") {
      plan.datasets = split(str());
      if (plan.datasets.empty()) return usage("--datasets: empty list");
      datasets_given = true;
    }
    else if (a == "--trials") plan.trials = next(1, 1000);
    else if (a == "--mcl-trials") lp.mcl_trials = plan.mcl_trials = next(0, 1000);
    else if (a == "--steps") lp.whole_max_steps = plan.trial.max_steps = next(0, 100000);
    else if (a == "--mit-steps") plan.trial_mit.max_steps = next(1, 100000);
    else if (a == "--seed") lp.seed = plan.seed = next(0, 1L << 40);
    else if (a == "--threads") lp.threads = plan.threads = static_cast<int>(next(1, 16));
    else if (a == "--config") plan.mml_config = static_cast<int>(next(1, 4));
    else if (a == "--all-configs") plan.extra_mml_configs = {1, 2, 3, 4};
    else if (a == "--mcl-particles") plan.mcl_particles = next(100, 131072);
    else if (a == "--mcl-particles-mit") plan.mcl_particles_mit = next(100, 131072);
    else if (a == "--no-handoff") plan.run_handoff = false;
    else if (a == "--no-mcl") plan.run_mcl = false;
    else if (a == "--no-unknown") lp.run_unknown = plan.run_unknown = false;
    else if (a == "--correct") plan.mml_correct = true;
    else if (a == "--reduce") plan.mml_reduce = true;
    else if (a == "--no-unique") plan.mml_unique = false;
    else if (a == "--compare-local-map-options") plan.compare_local_map_options = true;
    else if (a == "--out") lp.out_dir = plan.out_dir = str();
    else return usage(("unknown argument '" + a + "'").c_str());
  }
  if ((datasets_given && !check_dataset_names("--datasets", plan.datasets, "")) ||
      (mcl_datasets_given && !check_dataset_names("--mcl-datasets", lp.mcl_datasets, "")) ||
      (kidnap_datasets_given && !check_dataset_names("--kidnap-datasets", lp.kidnap_datasets, files.name))) {
    return 2;
  }
  sim::BenchJson json;
  std::string err;
  if (localize) {
    const bool custom = !files.log.empty() || !files.map_yaml.empty() || !files.reference.empty();
    if (custom) {
      if (files.log.empty() || files.map_yaml.empty() || files.reference.empty())
        return usage("--log, --map and --reference go together");
      lp.custom.push_back(files);
      lp.datasets = datasets_given ? plan.datasets : std::vector<std::string>{};
      lp.kidnap_datasets.push_back(files.name);
      if (!datasets_given) lp.run_unknown = false;
    } else if (datasets_given) {
      lp.datasets = plan.datasets;
    }
    if (!sim::mmleval::run_localize_evaluation(lp, &json, &err)) {
      print_error(err);
      return 1;
    }
    json.write(lp.out_dir + "/localize.json");
    std::printf("wrote %s/{localize.json,localize.md,*.svg,*.png}\n", lp.out_dir.c_str());
    return 0;
  }
  if (!sim::mmleval::run_evaluation(plan, &json, &err)) {
    print_error(err);
    return 1;
  }
  json.write(plan.out_dir + "/mml_eval.json");
  std::printf("wrote %s/{mml_eval.json,summary.md,*.svg,*.png}\n", plan.out_dir.c_str());
  return 0;
}

int main(int argc, char** argv) {
  return sim::guarded_main("mml-eval", [&] {
    return sim::corpus::wants_corpus(argc, argv) ? sim::corpus::corpus_main(argc, argv) : run_main(argc, argv);
  });
}
