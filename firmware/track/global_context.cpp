#include "firmware/track/global_context.h"

#include "firmware/base/se2.h"

namespace fw {
namespace track {

Status GlobalScheduleOptions::validate(bool threaded) const {
  if (every_n_scans == 0 || every_n_scans > 1000) {
    return Status::error(Errc::kInvalidArgument, "global schedule: every_n_scans %u outside [1, 1000]", every_n_scans);
  }
  if (result_delay_scans > every_n_scans) {
    return Status::error(Errc::kInvalidArgument,
                         "global schedule: result_delay_scans %u > every_n_scans %u (one job in flight at most)",
                         result_delay_scans, every_n_scans);
  }
  if (threaded && result_delay_scans == 0) {
    return Status::error(Errc::kInvalidArgument,
                         "global schedule: a threaded global context needs result_delay_scans >= 1 (the sensor "
                         "context never waits for it)");
  }
  return Status::ok();
}

Status GlobalContext::init(mml::MmlLocalizer* mml, const GlobalScheduleOptions& schedule) {
  if (mml == nullptr) return Status::error(Errc::kInvalidArgument, "global context: null MML localizer");
  if (threaded_) return Status::error(Errc::kInvalidArgument, "global context: init() while the thread runs");
  FW_RETURN_IF_ERROR(schedule.validate(false));
  mml_ = mml;
  schedule_ = schedule;
  index_ = 0;
  generation_ = 0;
  jobs_ = overruns_ = skipped_offers_ = 0;
  reset_pending_ = false;
  replaying_ = false;
  slot_.store(Slot::kIdle);
  return Status::ok();
}

Status GlobalContext::attach_thread(GlobalThread* thread, const ExecutionContext& context, const hal::Clock* clock) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "global context: thread attached before init()");
  if (threaded_) return Status::error(Errc::kInvalidArgument, "global context: thread already started");
  if (replaying_) return Status::error(Errc::kInvalidArgument, "global context: a replay runs inline");
  if (thread == nullptr || !thread->running()) {
    return Status::error(Errc::kInvalidArgument, "global context: the attached thread is not running");
  }
  FW_RETURN_IF_ERROR(schedule_.validate(true));
  clock_ = clock;
  // Anytime global search: pRANSAM's iterations are cut so the step fits the context's window.
  // Each job's window is measured by the sensor context (scan_window.h); the context's deadline is
  // its floor.
  if (clock != nullptr) mml_->set_deadline_mode(clock, context.deadline_ns);
  configured_window_ns_ = context.deadline_ns;
  scan_window_.reset();
  thread_ = thread;
  threaded_ = true;
  return Status::ok();
}

Status GlobalContext::start_thread(const ExecutionContext& context, bool realtime, const hal::Clock* clock) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "global context: start_thread() before init()");
  if (threaded_) return Status::error(Errc::kInvalidArgument, "global context: thread already started");
  FW_RETURN_IF_ERROR(schedule_.validate(true));
  FW_RETURN_IF_ERROR(own_thread_.start(context, realtime));
  own_thread_.serve(this);
  const Status s = attach_thread(&own_thread_, context, clock);
  if (!s) own_thread_.stop();
  return s;
}

void GlobalContext::stop_thread() {
  if (!threaded_) return;
  if (thread_ == &own_thread_) own_thread_.stop();
  thread_ = nullptr;
  threaded_ = false;
  // A job queued but never run is dropped; a finished one stays for the next step() (inline now).
  Slot s = slot_.load();
  if (s == Slot::kQueued || s == Slot::kRunning) slot_.store(Slot::kIdle);
}

void GlobalContext::run_queued_job() {
  slot_.store(Slot::kRunning, std::memory_order_release);
  run_job();
}

void GlobalContext::run_job() {
  // The reset is timed with the step: the job's result is due within the same window (it was left
  // out once, and hid 14-17 ms resets of RBSM's grid behind a 10 ms step p99).
  const std::uint64_t t0 = clock_ != nullptr ? clock_->now_ns() : 0;
  if (job_reset_) mml_->reset();
  if (job_window_ns_ != 0) mml_->set_deadline_budget(job_window_ns_);
  mml_->set_unmapped_hypothesis(job_unmapped_);
  job_status_ = mml_->step(job_scan_, job_odom_, &job_out_);
  job_deadline_rounds_ = mml_->last_deadline_rounds();
  if (clock_ != nullptr) {
    const std::uint64_t dt = clock_->now_ns() - t0;
    pthread_mutex_lock(&stats_mutex_);
    perf_step_.add_ns(dt);
    pthread_mutex_unlock(&stats_mutex_);
  }
  slot_.store(Slot::kDone, std::memory_order_release);
}

PerfStats GlobalContext::step_stats() const {
  pthread_mutex_lock(&stats_mutex_);
  const PerfStats s = perf_step_.stats();
  pthread_mutex_unlock(&stats_mutex_);
  return s;
}

void GlobalContext::tick() {
  ++index_;
  if (!threaded_) return;
  if (clock_ != nullptr) scan_window_.step(clock_->now_ns());
  const Slot s = slot_.load(std::memory_order_acquire);
  // The job's window closes at index job_index_ + delay: still not done then is an overrun.
  if ((s == Slot::kQueued || s == Slot::kRunning) && index_ - 1 == job_index_ + schedule_.result_delay_scans) {
    ++overruns_;
  }
}

void GlobalContext::reset() {
  ++generation_;
  if (!threaded_ && !replaying_) {
    mml_->reset();  // at once: the tracker as it always was
    reset_pending_ = false;
  } else {
    reset_pending_ = true;  // MML belongs to the global thread: it resets before its next job
  }
}

void GlobalContext::restart() {
  if (mml_ == nullptr) return;
  reset();
  index_ = 0;
}

void GlobalContext::take_result(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  *out = job_out_;
  const std::uint64_t cur = index_ - 1;
  if (cur != job_index_) {
    // MML's estimate is for the scan it consumed: move it to this scan by the wheel odometry.
    const Se2f before(job_odom_.x, job_odom_.y, job_odom_.theta);
    const Se2f now(odom.x, odom.y, odom.theta);
    const Se2f p = Se2f(job_out_.x, job_out_.y, job_out_.theta).compose(before.between(now));
    out->x = p.x;
    out->y = p.y;
    out->theta = p.theta;
  }
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  slot_.store(Slot::kIdle, std::memory_order_release);
}

Status GlobalContext::step(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const Status collected = collect(scan, odom, out);
  const Status offered = offer(scan, odom, out);
  return results_delayed() ? collected : offered;
}

Status GlobalContext::collect(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "global context: step() before init()");
  *out = hal::PoseEstimate();
  out->timestamp_ns = scan.timestamp_ns;
  out->scan_id = scan.scan_id;
  out->status = hal::LocalizationStatus::kSearching;
  // A finished result whose window has come.
  if (slot_.load(std::memory_order_acquire) != Slot::kDone) return Status::ok();
  return replaying_ ? collect_replayed(scan, odom, out) : collect_done(scan, odom, out);
}

Status GlobalContext::collect_done(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  const std::uint64_t cur = index_ > 0 ? index_ - 1 : 0;
  if (job_generation_ != generation_) {
    record(scan, true);
    slot_.store(Slot::kIdle, std::memory_order_release);  // asked before a reset: stale
    return Status::ok();
  }
  if (cur < job_index_ + schedule_.result_delay_scans) return Status::ok();
  record(scan, false);
  const Status result_status = job_status_;
  take_result(scan, odom, out);
  return result_status;
}

void GlobalContext::record(const hal::LaserScan& scan, bool dropped) {
  if (!threaded_ || record_sink_ == nullptr) return;
  hal::GlobalRecord r;
  r.scan_ns = scan.timestamp_ns;
  r.job_scan_ns = job_scan_.timestamp_ns;
  r.deadline_rounds = job_deadline_rounds_;
  r.dropped = dropped;
  record_sink_->record_global(r);
}

Status GlobalContext::offer(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "global context: step() before init()");
  const std::uint64_t cur = index_ > 0 ? index_ - 1 : 0;
  Status result_status;
  if (cur % schedule_.every_n_scans != 0) return result_status;
  if (slot_.load(std::memory_order_acquire) != Slot::kIdle) {
    ++skipped_offers_;
    return result_status;
  }
  job_scan_ = scan;
  job_odom_ = odom;
  job_index_ = cur;
  job_generation_ = generation_;
  job_reset_ = reset_pending_;
  job_unmapped_ = unmapped_hypothesis_;
  reset_pending_ = false;
  ++jobs_;
  job_window_ns_ = threaded_ && clock_ != nullptr && configured_window_ns_ != 0
                      ? scan_window_.window_ns(schedule_.result_delay_scans, configured_window_ns_)
                      : 0;
  if (threaded_) {
    slot_.store(Slot::kQueued, std::memory_order_release);
    thread_->notify();
    return result_status;
  }
  if (replaying_) match_replay_job(scan);
  run_job();
  if (schedule_.result_delay_scans == 0) {
    result_status = job_status_;
    take_result(scan, odom, out);
  }
  return result_status;
}

}  // namespace track
}  // namespace fw
