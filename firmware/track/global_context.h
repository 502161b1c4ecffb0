// GlobalContext: how the tracker (sensor context) reaches the global search (MML) — issue 14.
// The tracker calls step() on each scan it wants a global step for; the context decides by the
// schedule, not by timing, which scans MML consumes and when their results come back:
//   - scan index i counts the tracker's steps since reset (tick() on every step);
//   - MML consumes the scan offered at index i when i % every_n_scans == 0 (and no job is in
//     flight: with result_delay_scans ≤ every_n_scans, one on time never is);
//   - its result is handed back at the first step() at index ≥ i + result_delay_scans, its pose
//     moved from scan i to the current scan by the wheel odometry between them (Se2 ⊕, Eq. 5.1);
//     at other scans step() reports `searching` without a pose.
// Two executions of the same schedule:
//   inline   MML runs synchronously inside step() (lockstep tools: sim, mml-eval, bench). With
//            every_n_scans = 1 and result_delay_scans = 0 this is the tracker as it always was.
//   threaded MML runs on its own pinned thread (execution_contexts.h, `global`); step() only
//            copies the scan into a one-slot mailbox and takes a finished result. Same function of
//            the inputs as inline as long as every global step finishes within its window
//            (result_delay_scans scan periods); a late step is counted (overruns()), its result is
//            taken at the first step() after it finished, and the offers it overlapped are
//            skipped (skipped_offers()) — from then on the run differs from the inline one.
// reset() forgets MML's state (fresh local map) before the next job; results of jobs handed over
// before a reset are dropped. Nothing is allocated after init()/start_thread().
// Black box (issue 60): threaded, each result taken (or dropped after a reset) is reported to the
// record sink (set_record_sink) with the scan it was taken at, the scan of its job and pRANSAM's
// deadline rounds (hal/msg/global_record.h). replay() executes such records: MML runs inline on
// the same offers, stops pRANSAM after the recorded rounds, and its result is held until the
// recorded scan — so a replay reproduces the threaded robot's poses (global_replay.cpp).
#pragma once

#include <pthread.h>

#include <atomic>
#include <cstdint>

#include "firmware/base/perf_counter.h"
#include "firmware/base/status.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/execution_contexts.h"
#include "firmware/track/global_thread.h"
#include "firmware/track/scan_window.h"
#include "hal/clock.h"
#include "hal/global_record_sink.h"

namespace fw {
namespace track {

struct GlobalScheduleOptions {
  std::uint32_t every_n_scans = 1;
  std::uint32_t result_delay_scans = 0;  // ≤ every_n_scans; ≥ 1 when threaded
  Status validate(bool threaded) const;
};

// The shipped live schedule: the `global` entry of the execution-context table (period_scans 0), or
// every n-th scan with the result n scans later.
inline GlobalScheduleOptions live_global_schedule(std::uint32_t period_scans = 0) {
  GlobalScheduleOptions s;
  s.every_n_scans = period_scans > 0 ? period_scans : kGlobalContext.period_scans;
  s.result_delay_scans = s.every_n_scans;
  return s;
}
// The `global` context for that schedule: deadline = period_scans scan periods.
inline ExecutionContext global_context_for(std::uint32_t period_scans) {
  ExecutionContext c = kGlobalContext;
  if (period_scans > 0) {
    c.period_scans = period_scans;
    c.deadline_ns = period_scans * kSensorPeriodNs;
  }
  return c;
}

class GlobalContext {
 public:
  GlobalContext() = default;
  GlobalContext(const GlobalContext&) = delete;
  GlobalContext& operator=(const GlobalContext&) = delete;
  ~GlobalContext() { stop_thread(); }

  Status init(mml::MmlLocalizer* mml, const GlobalScheduleOptions& schedule);
  // Start-up only: creates the global thread (pinned, SCHED_FIFO when realtime). `clock` times the
  // global steps (perf_step()) and puts MML in deadline mode (pRANSAM's iterations set by the time
  // left in the context's deadline, Sec. 4.4.3); null = neither.
  Status start_thread(const ExecutionContext& context, bool realtime, const hal::Clock* clock);
  // The same on a thread created elsewhere at start-up and shared (GlobalThread::serve picks the
  // context it runs: several maps, firmware/app/map_set.h). Creates no thread, so it may be called
  // after start-up (a map rebuilt by a reload). `thread` must outlive the attachment.
  Status attach_thread(GlobalThread* thread, const ExecutionContext& context, const hal::Clock* clock);
  // Own thread: stopped and joined. Attached: detached (the thread stays).
  void stop_thread();
  bool threaded() const { return threaded_; }
  // Inline: the clock that times global steps (perf_step()); null = not timed.
  void set_clock(const hal::Clock* clock) { clock_ = clock; }
  // Threaded: every result taken or dropped is recorded here (the black box); null = none.
  // Sensor context, like step().
  void set_record_sink(hal::GlobalRecordSink* sink) { record_sink_ = sink; }
  // Replay of a threaded robot's records (in the order recorded; `records` must outlive the replay):
  // not threaded, a schedule with result_delay_scans ≥ 1 (the robot's), pRANSAM's deadline mode off.
  // A record the replay does not meet (another job scan, a take where the replay drops, a scan
  // passed) stops the replay of records: replay_status() names the record's index and what differs.
  Status replay(const hal::GlobalRecord* records, std::size_t n);
  bool replaying() const { return replaying_; }
  const Status& replay_status() const { return replay_status_; }
  std::size_t replay_records_used() const { return replay_next_; }
  // The index of the record replay_status() is about (valid when it is an error).
  std::size_t replay_failed_record() const { return replay_failed_; }

  // Once per tracker step, before any step()/reset() of that scan.
  void tick();
  void reset();   // MML forgets everything before its next job
  // MML's unmapped-space hypothesis (MmlLocalizer::set_unmapped_hypothesis) for the jobs offered
  // from now on: it travels with each job, so a threaded MML sees it at the same scan as inline.
  void set_unmapped_hypothesis(bool on) { unmapped_hypothesis_ = on; }
  void restart(); // reset() and the scan index back to 0 (TrackedLocalizer::reset)
  // See the header comment. `out` is always written. step() = collect() then offer().
  Status step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  // The two halves of step(), for a caller that decides after seeing the result whether this scan
  // is still wanted (results_delayed() only: with result_delay_scans = 0 a scan's result exists only
  // once it is offered). collect(): a finished result whose window has come, else `searching`
  // without a pose (`out` always written). offer(): this scan for MML if the schedule says so and
  // the mailbox is free (run inline when not threaded; with no delay its result goes to `out`).
  bool results_delayed() const { return schedule_.result_delay_scans > 0; }
  Status collect(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  Status offer(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);

  const GlobalScheduleOptions& schedule() const { return schedule_; }
  // A job handed to the global thread and not finished yet.
  bool job_in_flight() const {
    const Slot s = slot_.load(std::memory_order_acquire);
    return s == Slot::kQueued || s == Slot::kRunning;
  }
  std::uint64_t jobs() const { return jobs_; }
  std::uint64_t overruns() const { return overruns_; }
  std::uint64_t skipped_offers() const { return skipped_offers_; }
  const PerfCounter& perf_step() const { return perf_step_; }
  // Thread-safe copy of the global step's stats (threaded: written by the global thread).
  PerfStats step_stats() const;
  // Threaded with a clock: the window the last job was given (its pRANSAM deadline budget,
  // scan_window.h) and the median scan interval it came from; 0 = none yet.
  std::uint64_t last_window_ns() const { return job_window_ns_; }
  std::uint64_t median_scan_interval_ns() const { return scan_window_.median_interval_ns(); }

 private:
  friend class GlobalThread;
  bool job_queued() const { return slot_.load(std::memory_order_acquire) == Slot::kQueued; }
  void run_queued_job();  // GlobalThread: the queued job, on that thread
  void run_job();  // on whichever thread executes MML
  void take_result(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  // The finished job's result at this scan: taken (its window has come) or dropped (stale); recorded
  // when threaded. Replay: as its record says (global_replay.cpp).
  Status collect_done(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  void record(const hal::LaserScan& scan, bool dropped);
  void match_replay_job(const hal::LaserScan& scan);
  Status collect_replayed(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out);
  void fail_replay(std::size_t record, const char* what, std::uint64_t replay_ns);
  static constexpr std::size_t kNoRecord = static_cast<std::size_t>(-1);

  mml::MmlLocalizer* mml_ = nullptr;
  GlobalScheduleOptions schedule_;
  const hal::Clock* clock_ = nullptr;
  std::uint64_t index_ = 0;         // tracker steps since restart (index of the current scan + 1)
  std::uint64_t generation_ = 0;    // bumped by reset(); jobs carry the generation they were taken in
  std::uint64_t jobs_ = 0, overruns_ = 0, skipped_offers_ = 0;

  // Mailbox (one slot each way). States: idle → queued (sensor) → running (global) → done → idle.
  enum class Slot : std::uint8_t { kIdle, kQueued, kRunning, kDone };
  hal::LaserScan job_scan_;
  hal::Odometry job_odom_;
  std::uint64_t job_index_ = 0, job_generation_ = 0;
  bool job_reset_ = false;   // MML resets before this job
  bool job_unmapped_ = false;  // MML's unmapped-space hypothesis for this job
  bool unmapped_hypothesis_ = false;
  bool reset_pending_ = false;
  Status job_status_;
  hal::PoseEstimate job_out_;
  std::uint32_t job_deadline_rounds_ = 0;  // pRANSAM's rounds when its deadline stopped the job
  std::uint64_t job_window_ns_ = 0;  // the job's deadline budget (threaded with a clock), else 0
  ScanWindow scan_window_;           // the sensor context's step intervals (tick())
  std::uint64_t configured_window_ns_ = 0;  // the context's deadline: the window's floor
  std::atomic<Slot> slot_{Slot::kIdle};

  bool threaded_ = false;
  GlobalThread own_thread_;            // start_thread()
  GlobalThread* thread_ = nullptr;     // the thread running the jobs (own or attached)
  hal::GlobalRecordSink* record_sink_ = nullptr;
  // replay(): the records, the next one to meet, the one of the job held (kNoRecord: none).
  const hal::GlobalRecord* replay_records_ = nullptr;
  std::size_t replay_count_ = 0, replay_next_ = 0, job_record_ = kNoRecord, replay_failed_ = 0;
  bool replaying_ = false;
  Status replay_status_;
  mutable pthread_mutex_t stats_mutex_ = PTHREAD_MUTEX_INITIALIZER;
  PerfCounter perf_step_{"global.step"};
};

}  // namespace track
}  // namespace fw
