// bench_soak: the budget replay (tests/hil/replay_budget.h: mmlfw's stack, mml-track on aces, two
// pinned workers, scans due at 75 Hz of the wall clock) looped for MMLFW_SOAK_MINUTES (60) minutes.
// Every 10 s it samples the process RSS (/proc/self/statm) and the firmware's memory report. Figures
// (build/bench/soak.json, also merged into build/bench/faults.json):
//   soak_minutes            wall minutes actually run
//   soak_rss_growth_kib     largest RSS after the first full pass of the log minus the RSS then
//                           (the first pass touches the arena pages the localizer will ever use)
//   soak_memory_report_growth_bytes  memory report total at the end minus at the start
//   soak_unaccounted_scans  scans fed − processed − HEALTH dropped (ring overflows included) − pending
//   soak_wrong_localized    `localized` poses > 1 m from the reference
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <string>

#include "firmware/base/memory_report.h"
#include "sim/common/bench_json.h"
#include "tests/faults/flat_json_merge.h"
#include "tests/hil/replay_budget.h"

namespace {
long rss_kib() {
  long pages = 0, resident = 0;
  std::FILE* f = std::fopen("/proc/self/statm", "r");
  if (f == nullptr) return -1;
  if (std::fscanf(f, "%ld %ld", &pages, &resident) != 2) resident = -1;
  std::fclose(f);
  return resident * (sysconf(_SC_PAGESIZE) / 1024);
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: bench_soak OUT.json   (MMLFW_SOAK_MINUTES, default 60)\n");
    return 2;
  }
  const char* m = std::getenv("MMLFW_SOAK_MINUTES");
  const double minutes = m ? std::strtod(m, nullptr) : 60.0;
  mmlfw_hil::ReplayOptions o;
  o.num_scans = 1u << 30;  // the whole log, looped
  o.rate_hz = 75.0;
  o.duration_s = minutes * 60.0;
  o.sample_period_s = 10.0;
  long rss_base = -1, rss_max_after = -1;
  std::size_t mr_start = 0;
  bool have_mr_start = false;
  o.on_sample = [&](const mmlfw_hil::ReplaySample& s) {
    const long rss = rss_kib();
    const std::size_t mr = fw::MemoryReport::instance().total_bytes();
    if (!have_mr_start) { mr_start = mr; have_mr_start = true; }
    if (s.loops >= 1 && rss_base < 0) rss_base = rss;
    if (rss_base >= 0 && rss > rss_max_after) rss_max_after = rss;
    std::printf("soak %7.1f s  loops %zu  fed %zu  processed %zu  dropped %zu  ring %zu  localized %zu  wrong %zu  rss %ld KiB  report %zu B\n",
                s.elapsed_s, s.loops, s.scans_fed, s.scans_processed, s.health_dropped, s.ring_overflows, s.localized,
                s.wrong_localized, rss, mr);
    std::fflush(stdout);
  };
  mmlfw_hil::ReplayResult r;
  std::string err;
  const long t0 = static_cast<long>(time(nullptr));
  const bool ok = mmlfw_hil::run_replay(o, &r, &err);
  const double ran_min = static_cast<double>(time(nullptr) - t0) / 60.0;
  if (!ok) std::fprintf(stderr, "bench_soak: %s\n", err.c_str());
  const std::size_t mr_end = fw::MemoryReport::instance().total_bytes();
  sim::BenchJson j;
  j.add("soak_minutes", ok ? ran_min : 0.0);
  j.add_int("soak_loops", static_cast<long long>(r.loops));
  j.add_int("soak_scans_fed", static_cast<long long>(r.scans_fed));
  j.add_int("soak_scans_processed", static_cast<long long>(r.scans_processed));
  j.add_int("soak_health_dropped", static_cast<long long>(r.health_dropped));
  j.add_int("soak_ring_overflows", static_cast<long long>(r.ring_overflows));
  j.add_int("soak_rss_base_kib", rss_base);
  j.add_int("soak_rss_growth_kib", rss_base >= 0 ? rss_max_after - rss_base : -1);
  j.add_int("soak_memory_report_growth_bytes",
            static_cast<long long>(mr_end) - static_cast<long long>(have_mr_start ? mr_start : mr_end));
  // HEALTH dropped_scans includes the sensor ring's overflows (SimLaserSource::skipped_scans), as
  // mmlfw's CanNode counts its own: every scan fed is processed, dropped in HEALTH or still pending.
  const long long unaccounted = static_cast<long long>(r.scans_fed) - static_cast<long long>(r.scans_processed) -
                                static_cast<long long>(r.health_dropped) - static_cast<long long>(r.pending_at_end);
  j.add_int("soak_unaccounted_scans", unaccounted);
  j.add_int("soak_wrong_localized", static_cast<long long>(r.wrong_localized));
  j.add_int("soak_localized", static_cast<long long>(r.localized));
  j.add("soak_step_ms_p99", r.step_p99_ms);
  j.add_int("soak_deadline_misses", static_cast<long long>(r.deadline_misses));
  if (!j.write(argv[1])) return 1;
  // Also into faults.json when the fault campaign has written it (same folder).
  std::string out = argv[1];
  const std::string faults = out.substr(0, out.find_last_of('/') + 1) + "faults.json";
  auto kv = mmlfw_faults::read_flat_json(faults);
  if (!kv.empty()) {
    mmlfw_faults::merge_flat_json(&kv, mmlfw_faults::read_flat_json(argv[1]));
    mmlfw_faults::write_flat_json(faults, kv);
  }
  return ok ? 0 : 1;
}
