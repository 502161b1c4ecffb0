// bench_global (scripts/bench.sh global → build/bench/global.json), issue 58 item 2: the global step
// bounded on any map, and what the bound costs. The global search (MML) runs inline on the scan in
// three schedules of mml-eval --global (sim/eval/mml_eval/mml_systems.h):
//   ref        every scan, result on the same scan, pRANSAM to I_max (the figures of record);
//   deadline   live-deadline: mmlfw's live schedule (result one scan later) with pRANSAM's deadline
//              mode (Sec. 4.4.3): its rounds stop at 60 % of the global context's window
//              (firmware/runtime/execution_contexts.h, 13.3 ms) — the anytime structure mmlfw runs;
//   deadline6  the same with global_period_scans = 6: MML on every 6th scan, an 80 ms window.
// Per bench log D (fix trials from kidnapped starts, MMLFW_GLOBAL_FIX_TRIALS, default 5, 200 steps,
// one thread): D_global_step_ms_p50/_p99/_max_{ref,deadline,deadline6} (MML's steps, GlobalContext's timer),
// D_m_to_fix_median_MODE, D_first_fix_success_MODE, D_integrity_failures_*.
// Then the largest generated buildings of the corpus (seed 505's three largest, 138–141 × 96–98 m:
// draws 238, 76, 50 of build/bench/corpus_505/runs.csv) run to the end of their routes with
// mml-eval --corpus --draw K --opt global=MODE: large_Kdraw_global_step_ms_p99_MODE, _metres_to_fix_MODE,
// _fixed_MODE, _wrong_MODE; and the worst over all (global_step_ms_p99_max_MODE).
// Deadline mode depends on the time: its figures vary with the machine and its load.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include "sim/common/cli_main.h"
#include "sim/common/flat_json_read.h"

namespace {

double num(const std::string& text, const std::string& key) {
  std::string v;
  if (!sim::json_value(text, key, &v) || v == "null") return std::nan("");
  return std::strtod(v.c_str(), nullptr);
}

struct Mode {
  const char* name;    // key suffix
  const char* global;  // mml-eval --global / --opt global=
  int period;          // mml-eval --global-period / --opt global_period= (mmlfw's global_period_scans)
};
constexpr Mode kModes[] = {{"ref", "ref", 1}, {"deadline", "live-deadline", 1}, {"deadline6", "live-deadline", 6}};
constexpr int kModeCount = sizeof(kModes) / sizeof(kModes[0]);

bool run(const std::string& cmd, const std::string& log) {
  std::printf("bench_global: %s\n", cmd.c_str());
  std::fflush(stdout);
  return std::system((cmd + " > " + log + " 2>&1").c_str()) == 0;
}

// The bench logs: fix trials in each mode.
void bench_logs(const std::string& eval, const std::string& out, int trials, double* worst, sim::BenchJson* json) {
  const char* logs[] = {"intel", "fr079", "aces", "mit-killian", "fr-clinic", "fr101", "fr-campus"};
  for (const Mode& m : kModes) {
    for (const char* d : logs) {
      const std::string dir = out + "/" + d + "_" + m.name;
      const std::string cmd = eval + " --localize --datasets " + d + " --whole-runs 0 --fix-trials " +
                              std::to_string(trials) + " --mcl-trials 0 --kidnap-runs 0 --no-unknown --threads 1" +
                              " --global " + m.global + " --global-period " + std::to_string(m.period) + " --out " + dir;
      std::string key = d;
      std::replace(key.begin(), key.end(), '-', '_');
      const std::string sfx = std::string("_") + m.name;
      if (!run(cmd, dir + ".log")) {
        std::fprintf(stderr, "bench_global: mml-eval failed for %s (%s.log)\n", d, dir.c_str());
        json->add(key + "_global_step_ms_p99" + sfx, std::nan(""));
        continue;
      }
      const std::string s = sim::read_all(dir + "/localize.json");
      for (const char* f : {"global_step_ms_p50", "global_step_ms_p99", "global_step_ms_max", "m_to_fix_median",
                            "first_fix_success", "availability"})
        json->add(key + "_" + f + sfx, num(s, key + "_" + f));
      json->add_int(key + "_integrity_failures" + sfx, static_cast<long long>(num(s, key + "_integrity_failures")));
      const double p99 = num(s, key + "_global_step_ms_p99");
      if (std::isfinite(p99)) worst[&m - kModes] = std::max(worst[&m - kModes], p99);
    }
  }
}

// The largest generated buildings, each run to the end of its route in each mode.
void large_buildings(const std::string& eval, const std::string& out, double* worst, sim::BenchJson* json) {
  const int draws[] = {238, 76, 50};
  for (const Mode& m : kModes) {
    for (const int k : draws) {
      const std::string dir = out + "/corpus505_draw" + std::to_string(k) + "_" + m.name;
      const std::string cmd = eval + " --corpus 1 --seed 505 --draw " + std::to_string(k) + " --opt global=" +
                              m.global + " --opt global_period=" + std::to_string(m.period) + " --out " + dir;
      const std::string p = "large_" + std::to_string(k) + "draw_";
      const std::string sfx = std::string("_") + m.name;
      if (!run(cmd, dir + ".log")) {
        std::fprintf(stderr, "bench_global: corpus draw %d failed (%s.log)\n", k, dir.c_str());
        json->add(p + "global_step_ms_p99" + sfx, std::nan(""));
        continue;
      }
      const std::string s = sim::read_all(dir + "/corpus.json");
      json->add(p + "global_step_ms_p50" + sfx, num(s, "corpus_global_step_ms_p50"));
      json->add(p + "global_step_ms_p99" + sfx, num(s, "corpus_global_step_ms_p99"));
      json->add(p + "global_step_ms_max" + sfx, num(s, "corpus_global_step_ms_max"));
      json->add(p + "metres_to_fix" + sfx, num(s, "corpus_metres_to_fix_median"));
      json->add(p + "fixed" + sfx, num(s, "corpus_first_fix_success"));
      json->add_int(p + "wrong" + sfx, static_cast<long long>(num(s, "corpus_integrity_failures")));
      const double p99 = num(s, "corpus_global_step_ms_p99");
      if (std::isfinite(p99)) worst[&m - kModes] = std::max(worst[&m - kModes], p99);
    }
  }
}

}  // namespace

static int run_main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_global OUTPUT.json\n");
    return 2;
  }
  const std::string exe = argv[0];
  const std::size_t slash = exe.find_last_of('/');
  const std::string build = (slash == std::string::npos ? std::string(".") : exe.substr(0, slash)) + "/..";
  const std::string eval = build + "/sim/eval/mml_eval/mml-eval";
  const std::string out = build + "/bench/global";
  if (std::system(("mkdir -p " + out).c_str()) != 0) return 1;
  const char* t = std::getenv("MMLFW_GLOBAL_FIX_TRIALS");
  const int trials = t != nullptr ? std::max(1, std::atoi(t)) : 5;
  sim::BenchJson json;
  json.add_int("fix_trials_per_log", trials);
  double worst[kModeCount] = {};
  if (std::getenv("MMLFW_GLOBAL_SKIP_LOGS") == nullptr) bench_logs(eval, out, trials, worst, &json);
  large_buildings(eval, out, worst, &json);
  for (int i = 0; i < kModeCount; ++i) json.add(std::string("global_step_ms_p99_max_") + kModes[i].name, worst[i]);
  return json.write(argv[1]) ? 0 : 1;
}

int main(int argc, char** argv) {
  return sim::guarded_main("bench_global", [&] { return run_main(argc, argv); });
}
