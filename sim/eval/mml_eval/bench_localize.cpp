// bench_localize: the product figures of the localizer (mml-track) within ≤ 25 minutes on a
// 2-core machine (scripts/bench.sh localize → build/bench/localize.json). Budget, per dataset:
// 3 whole-log runs (kidnapped start over the first half of the path, to the end of the log; 1 on
// mit-killian and fr-campus, the long ones) + 10 kidnapped-start trials of 200 steps (5 on
// mit-killian/fr-clinic/fr-campus); MCL (30k particles) first-fix metres on intel and fr079 (the 10
// fix-trial starts, mml-track's figure on the same starts beside it); 3 kidnap runs on every dataset; unknown area on intel (3 runs); the built-in large office
// through mml-sim (5 seeds, large_office_*). (mml-track's tracking
// steps take 1–2 ms, `track_step_ms_p50`; MCL and the first-time map builds dominate the run time.) Then the vcan
// HIL (tests/hil/hil_vcan.sh: mmlfw inside user-mode Linux, scans over virtual CAN) for
// hil_vcan_availability — the same localizer, built by the same start-up code, behind the drivers.
// Full runs: mml-eval --localize (flags in mml_eval_main.cpp).
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "sim/eval/mml_eval/localize_eval.h"
#include "sim/common/cli_main.h"
#include "sim/common/flat_json_read.h"

namespace {

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}
double num(const std::string& text, const char* key) {
  std::string v;
  if (!sim::json_value(text, key, &v) || v == "null") return std::nan("");
  return std::strtod(v.c_str(), nullptr);
}

// The built-in large office (sim/world), switched on at 5 random places (seeds 1–5), driven along
// mml-sim's route to its end: the same localizer through the simulator's HAL backend. Pooled over
// the runs like the log figures (first fix within 200 steps, availability after it).
void large_office(const std::string& build, sim::BenchJson* json) {
  constexpr int kSeeds = 5;
  int fixed200 = 0, runs = 0;
  double avail_steps = 0, avail_loc = 0, failures = 0, pl_scored = 0, pl_exceeded = 0, p99 = 0;
  std::vector<double> m_fix, track_err, p50;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const std::string out = build + "/bench/localize/large_office_seed" + std::to_string(seed);
    std::printf("bench_localize: large office, seed %d (mml-sim, %s) ...\n", seed, out.c_str());
    std::fflush(stdout);
    const std::string cmd = build + "/sim/mml-sim --world large-office --seed " + std::to_string(seed) + " --out " + out +
                            " > " + out + ".log 2>&1";
    if (std::system(("mkdir -p " + out).c_str()) != 0 || std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "bench_localize: mml-sim failed for seed %d (see %s.log)\n", seed, out.c_str());
      continue;
    }
    const std::string s = sim::read_all(out + "/summary.json");
    ++runs;
    const double first = num(s, "first_localized_step");
    // As mml-eval's D_m_to_fix_median (mml_eval.h): a first fix after the window or an integrity
    // failure at it counts as never fixed.
    const bool fixed = first >= 0 && first < 200 && num(s, "first_integrity_failure_step") != first;
    if (fixed) ++fixed200;
    m_fix.push_back(fixed ? num(s, "first_localized_travelled_m") : std::numeric_limits<double>::infinity());
    avail_steps += num(s, "availability_steps");
    avail_loc += num(s, "availability_localized_steps");
    failures += num(s, "integrity_failures");
    pl_scored += num(s, "pl_scored_steps");
    pl_exceeded += num(s, "pl_exceeded_steps");
    if (std::isfinite(num(s, "tracking_err_m_p50"))) track_err.push_back(num(s, "tracking_err_m_p50"));
    p50.push_back(num(s, "step_ms_p50"));
    p99 = std::max(p99, num(s, "step_ms_p99"));
  }
  json->add_int("large_office_trials", runs);
  json->add("large_office_first_fix_success", runs ? static_cast<double>(fixed200) / runs : std::nan(""));
  json->add("large_office_m_to_fix_median", sim::mmleval::censored_median(m_fix));
  json->add("large_office_availability", avail_steps > 0 ? avail_loc / avail_steps : std::nan(""));
  json->add_int("large_office_integrity_failures", static_cast<long long>(failures));
  json->add("large_office_pl_exceed_rate", pl_scored > 0 ? pl_exceeded / pl_scored : std::nan(""));
  json->add("large_office_track_err_m_median", median(track_err));
  json->add("large_office_step_ms_p50", median(p50));
  json->add("large_office_step_ms_p99", runs ? p99 : std::nan(""));
  std::printf("large office: %d runs, first fix within 200 steps %d, availability %.3f, integrity failures %.0f\n", runs,
              fixed200, avail_steps > 0 ? avail_loc / avail_steps : std::nan(""), failures);
}

}  // namespace

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
  // The HIL script writes its figures under the build directory (the parent of bench/).
  const std::string exe = argv[0];
  const std::size_t slash = exe.find_last_of('/');
  const std::string build = (slash == std::string::npos ? std::string(".") : exe.substr(0, slash)) + "/..";
  large_office(build, &json);
  std::printf("bench_localize: vcan HIL inside user-mode Linux (log: %s/hil_vcan_localize.log) ...\n", build.c_str());
  std::fflush(stdout);
  const int status = std::system(("bash " MMLFW_SOURCE_DIR "/tests/hil/hil_vcan.sh " + build + " > " + build +
                                  "/hil_vcan_localize.log 2>&1").c_str());
  // The script's exit code (77 = skipped: no user-mode Linux on this host, no data), not the raw
  // wait status: a skip is reported as a skip, never as a pass or a failure.
  const int rc = status != -1 && WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  json.add_bool("hil_vcan_passed", rc == 0);
  json.add_bool("hil_vcan_skipped", rc == 77);
  const std::string hil = sim::read_all(build + "/hil/vcan/results.json");
  sim::copy_num(json, rc == 0 ? hil : std::string(), "hil_vcan_availability");  // NaN when the HIL did not run
  if (rc == 77) std::fprintf(stderr, "bench_localize: the vcan HIL was skipped (its log says why)\n");
  else if (rc != 0) std::fprintf(stderr, "bench_localize: the vcan HIL failed (exit %d); see the log above\n", rc);
  return json.write(argv[1]) ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_localize", [&] { return run_main(argc, argv); });
}
