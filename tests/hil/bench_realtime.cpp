// bench_realtime (scripts/bench.sh realtime → build/bench/realtime.json), issue 14. For D in intel,
// fr079, aces, mit-killian: the firmware stack as mmlfw runs it (fw::LocalizationSystem, mml-track,
// MML on the pinned `global` context thread, the sensor context on this thread pinned to its core;
// firmware/runtime/execution_contexts.h) fed ≥ 3000 scans of the real log at 75 Hz of the wall
// clock (tests/hil/replay_budget.h). Figures per D:
//   D_75hz_scans, D_75hz_deadline_misses   sensor-context steps and those longer than 13.3 ms
//   D_track_step_ms_max / _p99               sensor-context step (scan in → tracking → pose out)
//   D_global_step_ms_p50/_p99/_max           MML step on the global context; D_global_window_ms
//   D_global_overruns, D_global_jobs         global steps that missed their window, steps run
//   D_first_fix_success_deadline_mode        the live run localized (first fix) and no pose was wrong
//   D_first_fix_scan, D_localized, D_wrong_localized, D_static_memory_mib
// and budget_check_fails_when_broken (replay_budget_test BudgetCheckFailsWhenBroken, run by the
// script). Each dataset runs in its own process (the replay's firmware objects are static).
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>

#include "tests/hil/replay_budget.h"

namespace {

int run_one(const std::string& name, const std::string& out_path, size_t scans) {
  mmlfw_hil::ReplayOptions o;
  o.dataset = name;
  o.num_scans = scans;
  o.rate_hz = 75.0;
  o.deadline_ms = 1000.0 / 75.0;
  o.global_context = "thread";
  if (const char* v = std::getenv("MMLFW_REALTIME_GLOBAL")) o.global_context = v;
  // Experiments (not used by scripts/bench.sh): schedule and re-centre overrides, rate (0 = lockstep).
  if (const char* v = std::getenv("MMLFW_REALTIME_EVERY")) o.schedule_every = static_cast<unsigned>(std::atoi(v));
  if (const char* v = std::getenv("MMLFW_REALTIME_DELAY")) o.schedule_delay = std::atoi(v);
  if (const char* v = std::getenv("MMLFW_REALTIME_ANYTIME")) o.anytime_recentre = std::atoi(v);
  if (const char* v = std::getenv("MMLFW_REALTIME_RATE")) o.rate_hz = std::atof(v);
  // As mmlfw with realtime = true (SCHED_FIFO at the table's priorities) when the OS allows it;
  // else as realtime = false, and the JSON says so.
  o.realtime = std::getenv("MMLFW_REALTIME_NO_FIFO") == nullptr;
  mmlfw_hil::ReplayResult r;
  std::string err;
  bool ok = mmlfw_hil::run_replay(o, &r, &err);
  if (!ok && o.realtime) {
    std::fprintf(stderr, "bench_realtime %s: %s; running without SCHED_FIFO\n", name.c_str(), err.c_str());
    o.realtime = false;
    err.clear();
    ok = mmlfw_hil::run_replay(o, &r, &err);
  }
  if (!ok) {
    std::fprintf(stderr, "bench_realtime %s: %s\n", name.c_str(), err.c_str());
    return 1;
  }
  std::string key = name;
  for (char& c : key)
    if (c == '-') c = '_';
  std::ofstream f(out_path);
  f << "\"" << key << "_sched_fifo\": " << (r.realtime ? "true" : "false") << ",\n";
  f << "\"" << key << "_75hz_scans\": " << r.scans_processed << ",\n";
  f << "\"" << key << "_75hz_scans_fed\": " << r.scans_fed << ",\n";
  f << "\"" << key << "_75hz_deadline_misses\": " << r.deadline_misses << ",\n";
  f << "\"" << key << "_75hz_dropped\": " << r.scans_dropped << ",\n";
  f << "\"" << key << "_75hz_dropped_ring_overflow\": " << r.ring_overflows << ",\n";
  f << "\"" << key << "_75hz_dropped_unpaired\": " << r.scans_unpaired << ",\n";
  f << "\"" << key << "_75hz_dropped_out_of_order\": " << r.scans_out_of_order << ",\n";
  f << "\"" << key << "_track_step_ms_max\": " << r.step_max_ms << ",\n";
  f << "\"" << key << "_track_step_ms_p99\": " << r.step_p99_ms << ",\n";
  f << "\"" << key << "_global_step_ms_p50\": " << r.global_step_p50_ms << ",\n";
  f << "\"" << key << "_global_step_ms_p99\": " << r.global_step_p99_ms << ",\n";
  f << "\"" << key << "_global_step_ms_max\": " << r.global_step_max_ms << ",\n";
  f << "\"" << key << "_global_window_ms\": " << r.global_period_ms << ",\n";
  f << "\"" << key << "_global_jobs\": " << r.global_jobs << ",\n";
  f << "\"" << key << "_global_deadline_stops\": " << r.global_deadline_stops << ",\n";
  f << "\"" << key << "_global_overruns\": " << r.global_overruns << ",\n";
  // The global step's stages (MML's perf counters): where a long global step spent its time.
  f << "\"" << key << "_global_before_pransam_ms_p50\": " << r.global_front_end.p50_ms << ",\n";
  f << "\"" << key << "_global_before_pransam_ms_max\": " << r.global_front_end.max_ms << ",\n";
  f << "\"" << key << "_global_pransam_ms_p50\": " << r.global_match.p50_ms << ",\n";
  f << "\"" << key << "_global_pransam_ms_max\": " << r.global_match.max_ms << ",\n";
  f << "\"" << key << "_global_after_pransam_ms_p50\": " << r.global_after_match.p50_ms << ",\n";
  f << "\"" << key << "_global_after_pransam_ms_max\": " << r.global_after_match.max_ms << ",\n";
  f << "\"" << key << "_track_step_ms_p50\": " << r.step_p50_ms << ",\n";
  f << "\"" << key << "_first_fix_scan\": " << r.first_localized_scan << ",\n";
  f << "\"" << key << "_localized\": " << r.localized << ",\n";
  f << "\"" << key << "_wrong_localized\": " << r.wrong_localized << ",\n";
  f << "\"" << key << "_first_fix_success_deadline_mode\": "
    << ((r.first_localized_scan >= 0 && r.wrong_localized == 0) ? "true" : "false") << ",\n";
  f << "\"" << key << "_static_memory_mib\": " << r.static_memory_mib << ",\n";
  double load[3] = {0, 0, 0};
  if (getloadavg(load, 3) == 3) f << "\"" << key << "_loadavg_1min_after\": " << load[0] << ",\n";
  std::printf("%s: %zu scans at 75 Hz, %zu deadline misses, track step max %.2f ms p99 %.2f ms; global (%s) %zu jobs p50 "
              "%.2f p99 %.2f max %.2f ms (window %.1f ms; before pRANSAM p50 %.2f max %.2f, pRANSAM p50 %.2f max %.2f, "
              "after p50 %.2f max %.2f), %zu overruns; first fix at scan %ld, localized %zu, wrong %zu\n",
              name.c_str(), r.scans_processed, r.deadline_misses, r.step_max_ms, r.step_p99_ms, r.global_context.c_str(),
              r.global_jobs, r.global_step_p50_ms, r.global_step_p99_ms, r.global_step_max_ms, r.global_period_ms,
              r.global_front_end.p50_ms, r.global_front_end.max_ms, r.global_match.p50_ms, r.global_match.max_ms,
              r.global_after_match.p50_ms, r.global_after_match.max_ms, r.global_overruns, r.first_localized_scan,
              r.localized, r.wrong_localized);
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc == 5 && std::string(argv[1]) == "--one") return run_one(argv[2], argv[3], std::strtoull(argv[4], nullptr, 10));
  if (argc != 2 && argc != 3) {
    std::fprintf(stderr, "usage: bench_realtime OUT.json [BROKEN_CHECK_LOG]\n");
    return 2;
  }
  const std::string out = argv[1];
  size_t scans = 3000;
  if (const char* v = std::getenv("MMLFW_REALTIME_SCANS")) scans = std::strtoull(v, nullptr, 10);
  std::string body;
  for (const char* d : {"intel", "fr079", "aces", "mit-killian"}) {
    const std::string part = out + "." + d + ".part";
    const std::string cmd = std::string(argv[0]) + " --one " + d + " " + part + " " + std::to_string(scans);
    if (std::system(cmd.c_str()) != 0) {
      std::fprintf(stderr, "bench_realtime: %s failed\n", d);
      return 1;
    }
    std::ifstream in(part);
    std::stringstream ss;
    ss << in.rdbuf();
    body += ss.str();
    std::remove(part.c_str());
  }
  bool broken = false;
  if (argc == 3) {  // the output of replay_budget_test --gtest_filter=*BudgetCheckFailsWhenBroken*
    std::ifstream in(argv[2]);
    std::string line;
    while (std::getline(in, line))
      if (line.find("budget_check_fails_when_broken: true") != std::string::npos) broken = true;
  }
  std::ofstream f(out);
  f << "{\n" << body << "\"budget_check_fails_when_broken\": " << (broken ? "true" : "false") << "\n}\n";
  return 0;
}
