// The firmware's execution contexts, declared as data in one place (PX4's work-queue table,
// platforms/common/px4_work_queue/WorkQueueManager: name, priority, stack; here also the core and
// the period/deadline). mmlfw creates every thread from this table once at start-up and pins it;
// nothing spawns a thread later. With `realtime = true` the threads run SCHED_FIFO at these
// priorities (higher number = more urgent) and mlockall keeps their memory resident.
//
//  sensor  scan in → pairing → tracking (PoseTracker) → pose out, on every scan. Hard deadline: one
//          scan period of the SICK LMS (13.3 ms at 75 Hz); a step longer than that is a deadline
//          miss (HEALTH deadline_misses, budget limit 0).
//  global  the MML step (RBSM + pRANSAM + interpretation, Ch. 5), lower priority. The sensor
//          context hands it the scan + odometry of every `period_scans`-th scan through a one-slot
//          mailbox and takes its result (a fix hypothesis, moved to the current scan by odometry)
//          `period_scans` scans later; the global step's deadline is that window, measured from the
//          sensor context's scan intervals with deadline_ns as its floor (track/scan_window.h). It never blocks
//          the sensor context (the mailbox copy is the only shared section); a step still running
//          when the next scan is due makes the sensor context skip that offer (counted).
//  workers pRANSAM / RBSM worker pool threads (firmware/base/worker_pool.h), run by the global
//          context only; same core as it, lower priority than the sensor context.
// On a 2-core machine: sensor context on core 0 (shared only with the second worker, at lower
// priority), the global context and the first worker on core 1.
#pragma once

#include <cstdint>

namespace fw {

struct ExecutionContext {
  const char* name;
  int core;                  // CPU the thread is pinned to (mod online CPUs, with a warning)
  int priority;              // SCHED_FIFO priority when realtime = true
  std::uint32_t period_scans;  // runs on every n-th scan
  std::uint64_t deadline_ns;   // longest allowed step (0 = none)
};

inline constexpr std::uint64_t kSensorPeriodNs = 13'333'333;  // 75 Hz SICK LMS

inline constexpr ExecutionContext kSensorContext{"sensor", 0, 80, 1, kSensorPeriodNs};
// Global: every scan, result one scan later (deadline one scan period). Measured (issue 14, mml-eval
// --localize intel+fr079, 13 fix trials each): the one-scan delay costs 0.2-0.7 m to the first fix;
// every 2nd scan with the result 2 scans later halved the MML steps per metre and doubled the
// distance to the first fix (intel 3.4 → 7.5 m, first-fix success 0.77 → 0.54). On a slower CPU
// where the MML step p99 exceeds one scan period, set period_scans = 2 (config
// global_period_scans) and accept that cost. README "Real time".
inline constexpr ExecutionContext kGlobalContext{"global", 1, 40, 1, kSensorPeriodNs};
inline constexpr ExecutionContext kWorkerContext{"workers", 1, 30, 0, 0};

inline constexpr ExecutionContext kExecutionContexts[] = {kSensorContext, kGlobalContext, kWorkerContext};

}  // namespace fw
