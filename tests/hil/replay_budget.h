// Real-time replay on the host for the budget check: a CARMEN log is fed to the same firmware
// stack as mmlfw (LocalizationLoop + the localizer built by fw::LocalizationSystem from the same
// SystemSpec fields as mmlfw's config — localizer, MML preset, seed — with pinned WorkerPool
// threads, map image and localizer objects in a StartupArena) through the hal/sim rings, scans due
// at the sensor rate (75 Hz) of the wall clock.
// A step slower than the period delays later scans (they queue in the ring, overflow is counted);
// a step longer than the deadline is a deadline miss.
#pragma once

#include <cstddef>
#include <functional>
#include <map>
#include <cstdint>
#include <string>
#include <vector>

#include "firmware/base/perf_counter.h"
#include "hal/msg/laser_scan.h"
#include "hal/msg/odometry.h"

namespace mmlfw_hil {

// Progress of a running replay (soak samples).
struct ReplaySample {
  double elapsed_s = 0;
  size_t scans_fed = 0, scans_processed = 0, health_dropped = 0, ring_overflows = 0, localized = 0,
         wrong_localized = 0, loops = 0;
};

struct ReplayOptions {
  std::string dataset = "aces";
  std::string map_dir;          // map cache; empty = sim::map_cache_dir()
  // As mmlfw's config keys (firmware/app/app_config.h) and their defaults: localizer (mml-track,
  // mml, handoff, mcl, odom), mml_preset (C1..C4), seed (below).
  std::string localizer = "mml-track";
  int mml_preset = 3;
  size_t first_scan = 0, num_scans = 600;
  double rate_hz = 75.0;         // <= 0: lockstep (each scan processed before the next; deterministic)
  double localized_bound_m = 1.0;  // a `localized` pose farther from the reference is wrong
  double deadline_ms = 1000.0 / 75.0;
  int workers = 2;
  std::uint64_t seed = 1;
  size_t lose_every = 0;          // > 0: every n-th scan is lost on the way (never reaches the firmware)
  double lose_prob = 0;           // > 0: each scan is also lost with this probability (drawn from lose_seed),
  std::uint64_t lose_seed = 1;    // as a real-time firmware that skips to the newest scan would see them
  std::vector<size_t> lose_list;  // log indices of scans lost on the way (e.g. read off a HIL trace)
  // > 0: each scan's timestamp is shifted by a uniform draw in ±this (ms, from lose_seed) against the
  // odometry, the pairing jitter of a CAN link whose sender clock is mapped by a min-delay offset
  // (HIL runs of one log differ by 1-2 cm in the paired odometry).
  double scan_time_jitter_ms = 0;
  bool trace = false;             // one line per processed scan on stdout (interpreter state, error)
  // mml-track's global search (firmware/track/global_context.h, execution_contexts.h):
  //   "auto"        thread in rate mode (as mmlfw runs), inline-ref in lockstep
  //   "thread"      MML on the pinned `global` thread, live schedule (execution_contexts.h)
  //   "inline-live" the live schedule executed inline (deterministic: what "thread" computes when
  //                 every global step meets its window)
  //   "inline-ref"  inline, every scan, result on the same scan (the reference schedule of the tools)
  std::string global_context = "auto";
  bool pin_sensor_thread = true;  // rate mode: pin this (the sensor) thread as the table says
  // Rate mode: SCHED_FIFO at the table's priorities for the sensor (this thread, restored after),
  // global and worker threads, and every page locked (mlockall), as mmlfw with realtime = true. An
  // error when the OS refuses either.
  bool realtime = false;
  // Overrides of the schedule for experiments (0 / -1 = as global_context says).
  unsigned schedule_every = 0;
  int schedule_delay = -1;
  int anytime_recentre = -1;      // 0 / 1: RBSM window re-centre at once / spread (SystemSpec.anytime_global)
  // Fault campaign: called with each scan (log index) before it is fed; may corrupt it (NaN, inf,
  // zero readings, ...). The reference for scoring stays the log's.
  std::function<void(size_t log_index, hal::LaserScan* scan)> mutate_scan;
  // Likewise for each odometry sample (its log time in seconds).
  std::function<void(double log_time_s, hal::Odometry* odom)> mutate_odometry;
  // Soak (rate mode only): > 0 loops the scans [first_scan, first_scan + num_scans) until this much
  // wall time has passed; sensor time runs on across the wraps (the robot is carried back to the
  // start: a kidnapping the odometry sees as a jump). on_sample is called every sample_period_s.
  double duration_s = 0;
  double sample_period_s = 10;
  std::function<void(const ReplaySample&)> on_sample;
};


struct ReplayResult {
  std::string localizer;          // name of the localizer built (LocalizationSystem::name())
  size_t scans_fed = 0, scans_processed = 0, scans_dropped = 0, scans_lost = 0, localized = 0;
  long first_localized_scan = -1;  // log index of the first `localized` pose
  long last_localized_scan = -1;   // log index of the last `localized` pose
  size_t after_first_fix = 0, localized_after_first_fix = 0;  // poses after the first `localized` one
  double availability = 0;         // localized_after_first_fix / after_first_fix
  size_t deadline_misses = 0;
  size_t wrong_localized = 0;     // localized poses farther than localized_bound_m from the reference
  double mean_err_localized_m = 0;
  std::vector<size_t> wrong_localized_scans;  // log indices (first 20)
  double step_p50_ms = 0, step_p99_ms = 0, step_max_ms = 0, cycle_p99_ms = 0;
  double achieved_rate_hz = 0;    // processed scans per second of wall time
  double static_memory_mib = 0;   // arena used + static objects
  std::map<std::string, double> module_mib;  // memory report by module (arena regions, statics)
  size_t map_width = 0, map_height = 0;
  double map_resolution = 0;
  int pin_warnings = 0;
  size_t ring_overflows = 0;      // scans the simulated sensor could not hand over (ring full)
  size_t health_dropped = 0;      // HEALTH dropped_scans at the end
  size_t loops = 0;               // completed passes over the scans (soak)
  size_t pending_at_end = 0;      // scans still queued or waiting when the replay stopped
  std::string global_context;     // schedule used (thread, inline-live, inline-ref; empty: no MML)
  double global_step_p50_ms = 0, global_step_p99_ms = 0, global_step_max_ms = 0;
  size_t global_jobs = 0, global_overruns = 0, global_skipped_offers = 0;
  double global_period_ms = 0;    // the global context's window (its deadline)
  size_t global_deadline_stops = 0;  // pRANSAM runs cut by the deadline (anytime mode)
  // The global step's stages (MML's perf counters): before pRANSAM, pRANSAM, after it.
  fw::PerfStats global_front_end, global_match, global_after_match;
  size_t scans_unpaired = 0, scans_out_of_order = 0, scans_malformed = 0;  // loop counters (dropped scans)
  bool odometry_from_scans = false;
  bool realtime = false;             // ran with SCHED_FIFO  // the log has no ODOM records: the scans' odometry triple was used
};

bool run_replay(const ReplayOptions& options, ReplayResult* out, std::string* error);

// Budget file: "key = value" lines, '#' comments (firmware/app/budget.txt).
bool read_budget(const std::string& path, std::map<std::string, double>* out, std::string* error);
// Compares; returns human-readable violations (empty = within budget). A key the checker does not
// know is itself a violation (a limit that is never checked cannot fail).
std::vector<std::string> check_budget(const std::map<std::string, double>& budget, const ReplayResult& r);

}  // namespace mmlfw_hil
