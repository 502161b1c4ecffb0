// bench_localize: the product figures of the localizer (mml-track) within ≤ 25 minutes on a
// 2-core machine (scripts/bench.sh localize → build/bench/localize.json). Budget, per dataset:
// 3 whole-log runs (kidnapped start over the first half of the path, to the end of the log; 1 on
// mit-killian and fr-campus, the long ones) + 10 kidnapped-start trials of 200 steps (5 on
// mit-killian/fr-clinic/fr-campus); MCL (30k particles) first-fix metres on intel and fr079 (3
// trials); 3 kidnap runs on every dataset; unknown area on intel (3 runs). (mml-track tracks in
// well under 1 ms per step; MCL and the first-time map builds dominate the run time.)
// Full runs: mml-eval --localize (flags in mml_eval_main.cpp).
#include <cstdio>
#include <string>

#include "sim/eval/mml_eval/localize_eval.h"
#include "sim/common/cli_main.h"

static int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_localize OUTPUT.json\n");
    return 2;
  }
  sim::mmleval::LocalizePlan plan;
  plan.out_dir = "build/bench/localize";
  plan.whole_runs_override = {{"mit-killian", 1}, {"fr-campus", 1}};
  plan.fix_trials_override = {{"mit-killian", 5}, {"fr-clinic", 5}, {"fr-campus", 5}};
  sim::BenchJson json;
  std::string err;
  if (!sim::mmleval::run_localize_evaluation(plan, &json, &err)) {
    std::fprintf(stderr, "bench_localize: %s\n", err.c_str());
    return 1;
  }
  return json.write(argv[1]) ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_localize", [&] { return run_main(argc, argv); });
}
