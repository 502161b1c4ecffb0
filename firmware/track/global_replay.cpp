// GlobalContext's replay of a threaded robot's global records (issue 60; global_context.h): the
// jobs run inline on the offers the schedule makes, pRANSAM stopped after the rounds its deadline
// allowed on the robot, and each result is held until the scan the robot took (or dropped) it at.
// MML is a function of its inputs and those rounds, so the replay's tracker sees what the robot's
// saw. The first record the replay does not meet ends the replay of records (replay_status()).
#include "firmware/track/global_context.h"

namespace fw {
namespace track {
namespace {
// Scans are named by their time stamps, kept to the µs in the black box.
std::uint64_t us(std::uint64_t ns) { return ns / 1000; }
}  // namespace

Status GlobalContext::replay(const hal::GlobalRecord* records, std::size_t n) {
  if (mml_ == nullptr) return Status::error(Errc::kNotInitialized, "global context: replay() before init()");
  if (threaded_) return Status::error(Errc::kInvalidArgument, "global context: replay() while the thread runs");
  if (n > 0 && records == nullptr) return Status::error(Errc::kInvalidArgument, "global context: null records");
  FW_RETURN_IF_ERROR(schedule_.validate(true));
  mml_->set_deadline_mode(nullptr, 0);  // the recorded rounds stand in for the clock
  replay_records_ = records;
  replay_count_ = n;
  replay_next_ = 0;
  job_record_ = kNoRecord;
  replay_failed_ = 0;
  replay_status_ = Status::ok();
  replaying_ = true;
  return Status::ok();
}

void GlobalContext::fail_replay(std::size_t record, const char* what, std::uint64_t replay_ns) {
  if (replay_status_.is_ok()) {
    const hal::GlobalRecord& r = replay_records_[record];
    const unsigned long long at = us(r.scan_ns), job = us(r.job_scan_ns), now = us(replay_ns);
    replay_status_ = Status::error(
        Errc::kInvalidArgument,
        "global record %zu (%s at scan %llu.%06llu, job of scan %llu.%06llu): %s (replay at scan %llu.%06llu)", record,
        r.dropped ? "drop" : "take", at / 1000000, at % 1000000, job / 1000000, job % 1000000, what, now / 1000000,
        now % 1000000);
    replay_failed_ = record;
  }
  replay_next_ = replay_count_;  // records after a mismatch mean nothing: the runs have parted
  job_record_ = kNoRecord;
}

// A job offered now: the next record must be its own (the robot offered at the same scan).
void GlobalContext::match_replay_job(const hal::LaserScan& scan) {
  job_record_ = kNoRecord;
  std::uint32_t rounds = 0;
  if (replay_next_ < replay_count_) {
    const hal::GlobalRecord& r = replay_records_[replay_next_];
    if (us(r.job_scan_ns) == us(scan.timestamp_ns)) {
      job_record_ = replay_next_++;
      rounds = r.deadline_rounds;
    } else {
      fail_replay(replay_next_, "the robot's job was of another scan than the replay's", scan.timestamp_ns);
    }
  }
  // No record (the robot's job was still running when the box was written): its result is held.
  mml_->force_deadline_rounds(rounds);
}

Status GlobalContext::collect_replayed(const hal::LaserScan& scan, const hal::Odometry& odom, hal::PoseEstimate* out) {
  if (job_record_ == kNoRecord) return Status::ok();
  const hal::GlobalRecord& r = replay_records_[job_record_];
  if (us(scan.timestamp_ns) < us(r.scan_ns)) return Status::ok();  // held until its scan
  if (us(scan.timestamp_ns) > us(r.scan_ns)) {
    fail_replay(job_record_, "its scan passed without the replay taking (or dropping) the result there",
                scan.timestamp_ns);
    return Status::ok();
  }
  const bool stale = job_generation_ != generation_;
  if (stale != r.dropped) {
    fail_replay(job_record_, stale ? "the replay's result is stale (a reset came between)"
                                   : "the replay's result is not stale", scan.timestamp_ns);
    return Status::ok();
  }
  const std::uint64_t cur = index_ > 0 ? index_ - 1 : 0;
  if (!stale && cur < job_index_ + schedule_.result_delay_scans) {
    fail_replay(job_record_, "taken before its window (result_delay_scans) closed", scan.timestamp_ns);
    return Status::ok();
  }
  job_record_ = kNoRecord;
  if (stale) {
    slot_.store(Slot::kIdle, std::memory_order_release);
    return Status::ok();
  }
  const Status result_status = job_status_;
  take_result(scan, odom, out);
  return result_status;
}

}  // namespace track
}  // namespace fw
