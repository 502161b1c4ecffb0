// mml-eval: MML vs MCL vs hand-off on the real logs (issue 6 §5). Full runs with flags; the
// 20-minute benchmark is bench_mml (scripts/bench.sh mml).
//   mml-eval [--datasets intel,aces] [--trials 10] [--mcl-trials N] [--steps 150] [--mit-steps 300]
//            [--seed 1] [--threads 2] [--config 3] [--all-configs] [--mcl-particles 30000]
//            [--mcl-particles-mit 120000] [--no-handoff] [--no-mcl] [--no-unknown] [--out build/eval/mml]
//            [--correct] [--reduce] [--no-unique] [--compare-local-map-options]
//   --correct / --reduce: local map correction (Eq. 5.23–5.27) / reduction (Eq. 5.28–5.30) on in
//   every MML run (labels mml-C3+corr, +red); --compare-local-map-options: the main configuration
//   also with correction and with reduction, side by side (JSON keys <dataset>_mml_c3_corr_*, _red_*).
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>

#include "sim/eval/mml_eval/mml_eval_run.h"

namespace {
std::vector<std::string> split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  std::string x;
  while (std::getline(ss, x, ',')) if (!x.empty()) out.push_back(x);
  return out;
}
int usage(const char* msg) {
  std::fprintf(stderr, "mml-eval: %s\n(see the header of sim/eval/mml_eval/mml_eval_main.cpp for the flags)\n", msg);
  return 2;
}
}  // namespace

int main(int argc, char** argv) {
  sim::mmleval::EvalPlan plan;
  plan.out_dir = "build/eval/mml";
  plan.trial_mit = plan.trial;
  plan.trial_mit.max_steps = 300;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&](long lo, long hi) -> long {
      if (i + 1 >= argc) { std::exit(usage(("missing value for " + a).c_str())); }
      char* end = nullptr;
      const long v = std::strtol(argv[++i], &end, 10);
      if (*end != '\0' || v < lo || v > hi) std::exit(usage(("bad value for " + a + ": '" + argv[i] + "'").c_str()));
      return v;
    };
    if (a == "--datasets" && i + 1 < argc) plan.datasets = split(argv[++i]);
    else if (a == "--trials") plan.trials = next(1, 1000);
    else if (a == "--mcl-trials") plan.mcl_trials = next(1, 1000);
    else if (a == "--steps") plan.trial.max_steps = next(1, 100000);
    else if (a == "--mit-steps") plan.trial_mit.max_steps = next(1, 100000);
    else if (a == "--seed") plan.seed = next(0, 1L << 40);
    else if (a == "--threads") plan.threads = static_cast<int>(next(1, 16));
    else if (a == "--config") plan.mml_config = static_cast<int>(next(1, 4));
    else if (a == "--all-configs") plan.extra_mml_configs = {1, 2, 3, 4};
    else if (a == "--mcl-particles") plan.mcl_particles = next(100, 131072);
    else if (a == "--mcl-particles-mit") plan.mcl_particles_mit = next(100, 131072);
    else if (a == "--no-handoff") plan.run_handoff = false;
    else if (a == "--no-mcl") plan.run_mcl = false;
    else if (a == "--no-unknown") plan.run_unknown = false;
    else if (a == "--correct") plan.mml_correct = true;
    else if (a == "--reduce") plan.mml_reduce = true;
    else if (a == "--no-unique") plan.mml_unique = false;
    else if (a == "--compare-local-map-options") plan.compare_local_map_options = true;
    else if (a == "--out" && i + 1 < argc) plan.out_dir = argv[++i];
    else return usage(("unknown argument '" + a + "'").c_str());
  }
  sim::BenchJson json;
  std::string err;
  if (!sim::mmleval::run_evaluation(plan, &json, &err)) {
    std::fprintf(stderr, "mml-eval: %s\n", err.c_str());
    return 1;
  }
  json.write(plan.out_dir + "/mml_eval.json");
  std::printf("wrote %s/{mml_eval.json,summary.md,*.svg,*.png}\n", plan.out_dir.c_str());
  return 0;
}
