// bench_mml: the issue-6 figures within ~20 minutes on a 2-core machine (scripts/bench.sh mml).
// Budget (≈ 12 min measured): 10 kidnapped starts per dataset for MML and the hand-off, the first 3
// of them for MCL (the slow one; 1 at mit-killian with 120k particles), ≤ 200 steps per trial
// (mit-killian: ≤ 250), hand-off on intel and aces, unknown area on intel (3 runs).
// The full evaluation (≥ 10 trials, all configurations) is `mml-eval --trials 10 --all-configs`.
#include <cstdio>
#include <string>

#include "sim/eval/mml_eval/mml_eval_run.h"
#include "sim/common/cli_main.h"

static int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_mml OUTPUT.json\n");
    return 2;
  }
  sim::mmleval::EvalPlan plan;
  plan.trials = 10;
  plan.mcl_trials = 3;
  plan.mcl_trials_mit = 1;
  plan.trial.max_steps = 200;
  plan.trial_mit = plan.trial;
  plan.trial_mit.max_steps = 250;
  plan.unknown_trials = 3;
  plan.out_dir = "build/bench/mml";
  sim::BenchJson json;
  std::string err;
  if (!sim::mmleval::run_evaluation(plan, &json, &err)) {
    std::fprintf(stderr, "bench_mml: %s\n", err.c_str());
    return 1;
  }
  return json.write(argv[1]) ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_mml", [&] { return run_main(argc, argv); });
}
