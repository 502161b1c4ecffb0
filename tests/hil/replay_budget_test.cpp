// Budget check (CTest label budget, RUN_SERIAL): replays aces at 75 Hz (a timing limit broken once is repeated once) on the host with pinned
// worker threads and compares memory, step latency and deadline misses with firmware/app/budget.txt.
// The localizer is built as mmlfw builds it (fw::LocalizationSystem), by default mmlfw's default
// (mml-track); MMLFW_REPLAY_LOCALIZER=mml (or handoff, mcl, odom) and MMLFW_REPLAY_PRESET=1..4
// select another, as the config keys `localizer` and `mml_preset` would.
#include <gtest/gtest.h>

#include <cstdio>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include <spawn.h>
#include <unistd.h>
#include <sys/wait.h>

#include "sim/io/datasets.h"
#include "tests/hil/replay_budget.h"

namespace {
void apply_localizer_env(mmlfw_hil::ReplayOptions* o) {
  if (const char* v = std::getenv("MMLFW_REPLAY_LOCALIZER")) o->localizer = v;
  if (const char* v = std::getenv("MMLFW_REPLAY_PRESET")) o->mml_preset = std::atoi(v);
}
}  // namespace

#ifndef MMLFW_BUDGET_FILE
#error MMLFW_BUDGET_FILE must name firmware/app/budget.txt
#endif

namespace {
// Timing limits measure the host as well as the firmware: one stall of a shared CI machine (a
// vCPU taken away for 20 ms) breaks a p99 over ~20 global jobs by itself. Memory limits do not.
bool is_timing_limit(const std::string& violation) {
  for (const char* key : {"deadline_misses", "step_max_ms", "step_p99_ms", "cycle_p99_ms", "dropped_scans", "processed_rate_hz_min",
                          "global_step_p99_ms", "global_overruns"}) {
    const std::string k = std::string(key) + ":";
    if (violation.rfind(k, 0) == 0) return true;
  }
  return false;
}

// One replay at the budget's rate, printed; returns the limits it broke.
std::vector<std::string> replay_and_check(const std::map<std::string, double>& budget) {
  mmlfw_hil::ReplayOptions o;
  o.num_scans = static_cast<size_t>(budget.count("replay_scans") ? budget.at("replay_scans") : 600);
  o.rate_hz = budget.count("scan_rate_hz") ? budget.at("scan_rate_hz") : 75.0;
  o.deadline_ms = 1000.0 / o.rate_hz;
  apply_localizer_env(&o);
  // As mmlfw with realtime = true (SCHED_FIFO at the execution-context table's priorities, memory locked) where the
  // OS permits it; otherwise as realtime = false (then the limits hold only on a quiet machine).
  o.realtime = std::getenv("MMLFW_REPLAY_NO_FIFO") == nullptr;
  mmlfw_hil::ReplayResult r;
  std::string err;
  if (!mmlfw_hil::run_replay(o, &r, &err) && o.realtime) {
    std::printf("real-time refused (%s): replay without SCHED_FIFO and locked memory\n", err.c_str());
    o.realtime = false;
    err.clear();
    if (!mmlfw_hil::run_replay(o, &r, &err)) return {"replay: " + err};
  }
  if (!err.empty()) return {"replay: " + err};
  std::printf("replay aces (%s, %s) %zu scans at %.0f Hz: processed %zu (%.1f Hz), dropped %zu, localized %zu, "
              "step p50 %.2f ms p99 %.2f ms max %.2f ms, cycle p99 %.2f ms, deadline misses %zu, "
              "static memory %.1f MiB, map %zux%zu @ %.2f m, pin warnings %d\n",
              r.localizer.c_str(), r.realtime ? "SCHED_FIFO" : "no SCHED_FIFO", r.scans_fed, o.rate_hz, r.scans_processed, r.achieved_rate_hz, r.scans_dropped, r.localized,
              r.step_p50_ms, r.step_p99_ms, r.step_max_ms, r.cycle_p99_ms, r.deadline_misses, r.static_memory_mib,
              r.map_width, r.map_height, r.map_resolution, r.pin_warnings);
  for (const auto& [m, mib] : r.module_mib) std::printf("  memory %-12s %8.2f MiB\n", m.c_str(), mib);
  std::printf("global context %s: %zu jobs, step p50 %.2f ms p99 %.2f ms max %.2f ms (window %.2f ms), overruns %zu, "
              "skipped offers %zu\n",
              r.global_context.c_str(), r.global_jobs, r.global_step_p50_ms, r.global_step_p99_ms, r.global_step_max_ms,
              r.global_period_ms, r.global_overruns, r.global_skipped_offers);
  std::printf("  stages: before pRANSAM p50 %.2f max %.2f ms, pRANSAM p50 %.2f max %.2f ms (%zu cut by the deadline), "
              "after it p50 %.2f max %.2f ms\n",
              r.global_front_end.p50_ms, r.global_front_end.max_ms, r.global_match.p50_ms, r.global_match.max_ms,
              r.global_deadline_stops, r.global_after_match.p50_ms, r.global_after_match.max_ms);
  std::printf("localized %zu (first at scan %ld, availability after it %.1f %%), wrong (> %.1f m) %zu, mean error while "
              "localized %.3f m\n",
              r.localized, r.first_localized_scan, 100.0 * r.availability, o.localized_bound_m, r.wrong_localized,
              r.mean_err_localized_m);
  if (r.wrong_localized) {
    // Not a budget item; reported for the localizer owners (the HIL test asserts it).
    std::printf("NOTE: wrong localized poses at log scans:");
    for (size_t i : r.wrong_localized_scans) std::printf(" %zu", i);
    std::printf("\n");
  }
  if (r.scans_processed == 0) return {"replay: no scan processed"};
  return mmlfw_hil::check_budget(budget, r);
}
}  // namespace

// A memory limit broken once fails. A timing limit broken once is repeated once, and fails when
// the repeat breaks a limit too: a firmware that is really too slow breaks it in both replays,
// while a single host stall (seen on the 2-core CI machine: one global job of 22 ms among 23, the
// rest 4-6 ms) does not fail the suite. Both replays are printed.
TEST(ReplayBudget, Aces75HzWithinBudget) {
  std::map<std::string, double> budget;
  std::string err;
  ASSERT_TRUE(mmlfw_hil::read_budget(MMLFW_BUDGET_FILE, &budget, &err)) << err;
  const sim::Dataset* ds = sim::find_dataset("aces");
  if (!ds || std::fopen(sim::data_path(ds->raw_log).c_str(), "rb") == nullptr) {
    GTEST_SKIP() << "aces log not found under " << sim::data_dir() << " (set MMLFW_DATA_DIR)";
  }
  std::vector<std::string> broken = replay_and_check(budget);
  bool timing_only = !broken.empty();
  for (const std::string& v : broken) timing_only = timing_only && is_timing_limit(v);
  if (timing_only && std::getenv("MMLFW_REPLAY_REPEAT") == nullptr) {
    // The firmware's start-up arena is initialised once per process, so the repeat is this test
    // in a fresh process (as mmlfw restarted), which prints its own replay and judges it alone.
    for (const std::string& v : broken) std::printf("replay 1 broke a timing limit: %s; repeating once\n", v.c_str());
    std::fflush(stdout);
    ASSERT_EQ(setenv("MMLFW_REPLAY_REPEAT", "1", 1), 0);
    char exe[] = "/proc/self/exe";
    char filter[] = "--gtest_filter=ReplayBudget.Aces75HzWithinBudget";
    char* argv[] = {exe, filter, nullptr};
    pid_t pid = 0;
    ASSERT_EQ(posix_spawn(&pid, exe, nullptr, nullptr, argv, environ), 0) << "cannot start the repeat";
    int status = 0;
    ASSERT_EQ(waitpid(pid, &status, 0), pid);
    EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "the repeated replay broke the budget too (above)";
    return;
  }
  for (const std::string& v : broken) ADD_FAILURE() << "budget exceeded: " << v;
}

// The budget check must be able to fail (issue 14): a real replay with a tiny sensor deadline must
// break `deadline_misses`, and every limit of budget.txt, set just out of reach of the measured
// value, must be reported by name; an unknown key is reported too (it would never be checked).
// Prints "budget_check_fails_when_broken: true|false" for scripts/bench.sh realtime.
TEST(ReplayBudget, BudgetCheckFailsWhenBroken) {
  std::map<std::string, double> budget;
  std::string err;
  ASSERT_TRUE(mmlfw_hil::read_budget(MMLFW_BUDGET_FILE, &budget, &err)) << err;
  const sim::Dataset* ds = sim::find_dataset("aces");
  if (!ds || std::fopen(sim::data_path(ds->raw_log).c_str(), "rb") == nullptr) {
    GTEST_SKIP() << "aces log not found under " << sim::data_dir() << " (set MMLFW_DATA_DIR)";
  }
  bool all_fail = true;
  mmlfw_hil::ReplayOptions o;
  o.num_scans = 150;
  o.rate_hz = budget.count("scan_rate_hz") ? budget["scan_rate_hz"] : 75.0;
  o.deadline_ms = 0.001;  // 1 µs: every sensor step misses it
  apply_localizer_env(&o);
  mmlfw_hil::ReplayResult r;
  ASSERT_TRUE(mmlfw_hil::run_replay(o, &r, &err)) << err;
  ASSERT_GT(r.scans_processed, 0u);
  // (A step with nothing to do — no global work, no scan points — can take < 1 us.)
  EXPECT_GT(r.deadline_misses, r.scans_processed / 2) << "a 1 us deadline must be missed by most steps";
  auto names = [](const std::vector<std::string>& v, const std::string& key) {
    for (const std::string& s : v)
      if (s.rfind(key + ":", 0) == 0) return true;
    return false;
  };
  const bool deadline_caught = names(mmlfw_hil::check_budget(budget, r), "deadline_misses");
  EXPECT_TRUE(deadline_caught) << "budget.txt deadline_misses did not catch " << r.deadline_misses << " misses";
  all_fail = all_fail && deadline_caught && budget.count("deadline_misses");
  for (const auto& [key, limit] : budget) {
    if (key == "replay_scans" || key == "scan_rate_hz") continue;  // replay parameters, not limits
    std::map<std::string, double> broken{{key, key.size() > 4 && key.compare(key.size() - 4, 4, "_min") == 0 ? 1e12 : -1.0}};
    const bool caught = names(mmlfw_hil::check_budget(broken, r), key);
    EXPECT_TRUE(caught) << "limit " << key << " broken on purpose was not reported";
    all_fail = all_fail && caught;
  }
  std::map<std::string, double> unknown{{"step_p99_msec", 1.0}};  // a typo: never checked
  const bool unknown_caught = names(mmlfw_hil::check_budget(unknown, r), "step_p99_msec");
  EXPECT_TRUE(unknown_caught);
  all_fail = all_fail && unknown_caught;
  std::printf("budget_check_fails_when_broken: %s (tiny deadline: %zu misses of %zu steps)\n",
              all_fail ? "true" : "false", r.deadline_misses, r.scans_processed);
}

// Deterministic check of the firmware's localizer as mmlfw builds it (not part of the budget): aces
// scans 0..249 in lockstep (no scan skipped, so timing cannot matter); it must localize and never
// be confidently wrong. Prints every wrong `localized` pose. For diagnosis (the asserted bounds are
// for the default run), environment variables replay another run: MMLFW_REPLAY_SEED, _FIRST,
// _COUNT; scans lost on the way: _LOSE_EVERY (every n-th), _LOSE_PROB with _LOSE_SEED (at random,
// as a real-time firmware skipping to the newest scan), _LOSE_LIST (comma-separated log indices);
// _JITTER_MS (scan/odometry pairing jitter, drawn from _LOSE_SEED); _TRACE=1 prints every step.
TEST(ReplayBudget, LockstepAcesLocalizesNeverWrong) {
  const sim::Dataset* ds = sim::find_dataset("aces");
  if (!ds || std::fopen(sim::data_path(ds->raw_log).c_str(), "rb") == nullptr) {
    GTEST_SKIP() << "aces log not found under " << sim::data_dir() << " (set MMLFW_DATA_DIR)";
  }
  mmlfw_hil::ReplayOptions o;
  o.num_scans = 250;
  o.rate_hz = 0;
  apply_localizer_env(&o);
  if (const char* seed = std::getenv("MMLFW_REPLAY_SEED")) o.seed = std::strtoull(seed, nullptr, 10);
  if (const char* v = std::getenv("MMLFW_REPLAY_FIRST")) o.first_scan = std::strtoull(v, nullptr, 10);
  if (const char* v = std::getenv("MMLFW_REPLAY_COUNT")) o.num_scans = std::strtoull(v, nullptr, 10);
  if (const char* v = std::getenv("MMLFW_REPLAY_LOSE_EVERY")) o.lose_every = std::strtoull(v, nullptr, 10);
  if (const char* v = std::getenv("MMLFW_REPLAY_LOSE_PROB")) o.lose_prob = std::strtod(v, nullptr);
  if (const char* v = std::getenv("MMLFW_REPLAY_LOSE_SEED")) o.lose_seed = std::strtoull(v, nullptr, 10);
  o.trace = std::getenv("MMLFW_REPLAY_TRACE") != nullptr;
  if (const char* v = std::getenv("MMLFW_REPLAY_JITTER_MS")) o.scan_time_jitter_ms = std::strtod(v, nullptr);
  if (const char* v = std::getenv("MMLFW_REPLAY_LOSE_LIST")) {  // comma-separated log indices
    for (const char* q = v; *q;) {
      char* end = nullptr;
      const unsigned long long i = std::strtoull(q, &end, 10);
      if (end == q) break;
      o.lose_list.push_back(static_cast<size_t>(i));
      q = *end == ',' ? end + 1 : end;
    }
  }
  mmlfw_hil::ReplayResult r;
  std::string err;
  ASSERT_TRUE(mmlfw_hil::run_replay(o, &r, &err)) << err;
  std::printf("lockstep (%s): fed %zu, processed %zu, dropped %zu, localized %zu (first at scan %ld, availability after "
              "it %.1f %%), wrong %zu, mean error while localized %.3f m; wrong at:",
              r.localizer.c_str(), r.scans_fed, r.scans_processed, r.scans_dropped, r.localized, r.first_localized_scan,
              100.0 * r.availability, r.wrong_localized, r.mean_err_localized_m);
  for (size_t i : r.wrong_localized_scans) std::printf(" %zu", i);
  std::printf("\n");
  EXPECT_EQ(r.wrong_localized, 0u);
  // mml-track, seed 1 (2026-11-24): localized on 121 of the 250 scans, first fix at scan 10, 0.078 m
  // mean error. The robot stands still until scan 130; when it starts turning, the odometry sample
  // attached to a scan is out of step with the laser and the scan fix is 6° from the prediction in
  // heading (a large fault: tracked_localizer.h then waits for MML, which does not isolate the pose
  // again before scan 250). The 231-234 scans noted here before were measured at d57ed19, before the
  // confirmation after a large fault and the later tracker guards. mml alone (MMLFW_REPLAY_LOCALIZER=mml), seed 1: 194 scans, 0.126 m.
  EXPECT_GE(r.localized, 100u);
}
