#include "tests/hil/replay_budget.h"

#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>
#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <random>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>

#include "firmware/app/system.h"
#include "firmware/base/arena.h"
#include "firmware/base/memory_report.h"
#include "firmware/base/worker_pool.h"
#include "firmware/map/global_map.h"
#include "firmware/map/map_image.h"
#include "firmware/map/map_image_file.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/runtime/execution_contexts.h"
#include "firmware/runtime/localization_loop.h"
#include "firmware/runtime/rt_thread.h"
#include "hal/hal.h"
#include "hal_linux/linux_clock.h"
#include "hal_sim/sim_sensor_io.h"
#include "hal_sim/stepped_clock.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/reference_trajectory.h"
#include "sim/map/global_maps.h"

namespace mmlfw_hil {
namespace {

std::uint64_t mono_ns() {
  timespec t{};
  clock_gettime(CLOCK_MONOTONIC, &t);
  return static_cast<std::uint64_t>(t.tv_sec) * 1000000000ull + static_cast<std::uint64_t>(t.tv_nsec);
}

// Static storage as in mmlfw (firmware/app/mmlfw_main.cpp: `fw::LocalizationSystem g_system`; the
// localizer objects themselves are placed in the start-up arena by the builder). Re-created per
// run so that its objects are destroyed before the arena they live in is set up again.
// The arena is declared first so that it is destroyed last: the localizer objects g_system owns
// live in it. (As a function-local static it was destroyed before g_system at exit, and ASan found
// ~TrackedLocalizer running on unmapped arena memory — the order mmlfw_main.cpp already keeps.)
fw::StartupArena g_arena;
std::optional<fw::LocalizationSystem> g_system;

}  // namespace

namespace {

// The log (with the scans' odometry as the odometry stream when it has no ODOM records) and the
// reference pose at every scan (empty when the dataset has none).
bool load_replay_inputs(const ReplayOptions& o, const sim::Dataset& ds, sim::CarmenLog* log,
                        std::vector<fw::Se2d>* reference, ReplayResult* r, std::string* error) {
  sim::CarmenReadOptions ro;
  ro.max_scans = o.first_scan + o.num_scans;
  if (!sim::read_carmen_log(sim::data_path(ds.raw_log), ro, log, error)) return false;
  if (log->odom.empty()) {
    // A log without ODOM records (mit-killian's reconstructed log): FLASER carries the odometry pose
    // of every scan; feed it as the odometry stream (one sample per scan, at the scan's time).
    r->odometry_from_scans = true;
    for (const sim::CarmenScan& sc : log->scans) {
      sim::CarmenOdom od;
      od.line = sc.line;
      od.pose = sc.odom;
      od.ipc_timestamp = sc.ipc_timestamp;
      log->odom.push_back(od);
    }
  }
  if (log->scans.size() <= o.first_scan) {
    *error = "log has no scans after " + std::to_string(o.first_scan);
    return false;
  }
  if (!ds.corrected_poses.empty()) {
    sim::CarmenLog full;
    std::vector<sim::CorrectedPose> corrected;
    if (sim::read_carmen_log(sim::data_path(ds.raw_log), sim::CarmenReadOptions{}, &full, error) &&
        sim::read_corrected_poses(sim::data_path(ds.corrected_poses), &corrected, error)) {
      *reference = sim::reference_at_every_scan(full, corrected);
    }
    error->clear();
  }
  return true;
}

// The firmware side of the replay, in static storage as mmlfw keeps it.
struct ReplayRig {
  fw::GlobalMap map{};
  fw::MapImageFile image;
  const std::uint8_t* table = nullptr;
  std::size_t table_len = 0;
  std::string gmode;
  bool lockstep = false;
  bool rt = false;
  fw::WorkerPool* pool = nullptr;
  fw::LocalizationSystem* sys = nullptr;
  fw::LocalizationLoop* loop = nullptr;
  hal::Hal hal;
  hal_linux::LinuxClock* clock = nullptr;
  hal_sim::SteppedClock* stepped = nullptr;
  hal_sim::SimLaserSource* laser = nullptr;
  hal_sim::SimOdometrySource* odom = nullptr;
  hal_sim::SimPoseSink* sink = nullptr;
};

// Arena, map image and relation table (as mmlfw loads them).
bool load_replay_map(const std::string& image_path, ReplayRig* rig, ReplayResult* r, std::string* error) {
  g_system.reset();  // before its arena is set up again
  fw::MemoryReport::instance().clear();
  fw::Status st = g_arena.init_mapped(256u << 20, false, "arena");
  if (!st) { *error = st.message(); return false; }
  st = rig->image.open(image_path.c_str());
  if (st) st = fw::load_map_image(rig->image.data(), rig->image.size(), g_arena, &rig->map, image_path.c_str());
  if (!st) { *error = st.message(); return false; }
  rig->table = fw::find_section(rig->image.data(), rig->image.size(), fw::MapSectionType::kRelationTable2D,
                                &rig->table_len);
  r->map_width = rig->map.geometry.width;
  r->map_height = rig->map.geometry.height;
  r->map_resolution = rig->map.geometry.resolution;
  return true;
}

// The worker pool (pinned beside the global context when MML runs on its thread, as in mmlfw).
bool start_replay_pool(const ReplayOptions& o, ReplayRig* rig, ReplayResult* r, std::string* error) {
  static fw::WorkerPool pool;
  rig->pool = &pool;
  fw::WorkerPoolOptions po;
  po.num_workers = o.workers;
  po.realtime = rig->rt;
  po.require_realtime = rig->rt;
  po.priority = fw::kWorkerContext.priority;
  if (rig->gmode == "thread") {  // as mmlfw: the workers beside the global context (execution_contexts.h)
    const long online = sysconf(_SC_NPROCESSORS_ONLN) > 0 ? sysconf(_SC_NPROCESSORS_ONLN) : 1;
    for (int i = 0; i < o.workers && i < fw::WorkerPoolOptions::kMaxWorkers; ++i)
      po.cores[i] = static_cast<int>((fw::kWorkerContext.core + i) % online);
  }
  const fw::Status st = pool.start(po);
  if (!st) { *error = st.message(); return false; }
  r->pin_warnings = pool.warning_count();
  return true;
}

// The localizer exactly as mmlfw builds it (firmware/app/mmlfw_main.cpp): the one start-up builder
// with the config's localizer name, MML preset and seed; the relation table is the image's section
// or filled at start-up. Then the HAL of simulated devices and the localization loop.
bool build_replay_localizer(const ReplayOptions& o, ReplayRig* rig, ReplayResult* r, std::string* error) {
  g_system.emplace();
  fw::LocalizationSystem& sys = *g_system;
  rig->sys = &sys;
  fw::SystemSpec spec;
  spec.localizer = o.localizer.c_str();
  spec.mml_preset = o.mml_preset;
  spec.seed = o.seed;
  fw::track::GlobalScheduleOptions live = fw::track::live_global_schedule();
  if (rig->gmode != "inline-ref") {
    spec.global_schedule = &live;
    spec.anytime_global = true;
  }
  if (o.schedule_every > 0 || o.schedule_delay >= 0) {
    if (rig->gmode == "inline-ref") live = fw::track::GlobalScheduleOptions();
    if (o.schedule_every > 0) live.every_n_scans = o.schedule_every;
    if (o.schedule_delay >= 0) live.result_delay_scans = static_cast<std::uint32_t>(o.schedule_delay);
    spec.global_schedule = &live;
  }
  if (o.anytime_recentre >= 0) spec.anytime_global = o.anytime_recentre != 0;
  fw::Status st = sys.build(spec, rig->map, rig->table, rig->table_len, g_arena, rig->pool);
  if (!st) { *error = std::string("localizer: ") + st.message(); return false; }
  static hal_linux::LinuxClock perf_clock;
  if (sys.tracked() != nullptr) {
    r->global_context = rig->gmode;
    r->global_period_ms = static_cast<double>(sys.tracked()->global_context().schedule().every_n_scans) * 1000.0 /
                          (o.rate_hz > 0 ? o.rate_hz : 75.0);
    if (rig->gmode == "thread") {
      st = sys.start_global_context(rig->rt, &perf_clock, fw::track::global_context_for(live.every_n_scans));
      if (!st) { *error = std::string("global context: ") + st.message(); return false; }
    } else {
      sys.tracked()->global_context().set_clock(&perf_clock);
    }
  }
  r->localizer = sys.name();
  // A table section in use is read in place from the image copy: keep only its pages (as mmlfw does).
  if (rig->table != nullptr && sys.table_in_use()) {
    st = rig->image.retain(rig->table, rig->table_len);
    if (!st) { *error = st.message(); return false; }
  } else {
    rig->image.close();
  }

  static hal_linux::LinuxClock clock;
  static hal_sim::SteppedClock stepped;  // lockstep: HAL time = time of the newest scan fed
  static hal_sim::SimLaserSource laser;
  static hal_sim::SimOdometrySource odom;
  static hal_sim::SimPoseSink sink;
  rig->clock = &clock;
  rig->stepped = &stepped;
  rig->laser = &laser;
  rig->odom = &odom;
  rig->sink = &sink;
  rig->hal.clock = rig->lockstep ? static_cast<hal::Clock*>(&stepped) : static_cast<hal::Clock*>(&clock);
  rig->hal.laser = &laser;
  rig->hal.odometry = &odom;
  rig->hal.pose_sink = &sink;
  static fw::LocalizationLoop loop;
  rig->loop = &loop;
  fw::LocalizationLoopOptions lo;
  lo.step_deadline_ns = static_cast<std::uint64_t>(o.deadline_ms * 1e6);
  lo.perf_clock = &clock;
  st = loop.init(rig->hal, sys.localizer(), lo);
  if (!st) { *error = st.message(); return false; }
  g_arena.seal();
  return true;
}

// Memory: arena used (its peak: the map loader's distance check is start-up scratch, issue 14) +
// the static objects of the firmware binary. The localizer objects are in the arena, as in mmlfw.
void record_memory(const ReplayRig& rig, ReplayResult* r) {
  const double mib = 1.0 / (1024.0 * 1024.0);
  const auto& mr = fw::MemoryReport::instance();
  for (std::size_t i = 0; i < mr.region_count(); ++i) {
    const fw::MemoryRegion& reg = mr.region(i);
    if (std::string(reg.module) == "arena") continue;
    r->module_mib[reg.module] += static_cast<double>(reg.bytes) * mib;
  }
  const double statics = static_cast<double>(sizeof(fw::LocalizationSystem) + sizeof(*rig.loop) + sizeof(*rig.pool) +
                                             sizeof(*rig.laser) + sizeof(*rig.odom) + sizeof(*rig.sink)) * mib;
  r->module_mib["statics"] = statics;
  const std::size_t arena_need = g_arena.peak_used() > g_arena.used() ? g_arena.peak_used() : g_arena.used();
  r->module_mib["arena_used"] = static_cast<double>(arena_need) * mib;
  r->static_memory_mib = static_cast<double>(arena_need) * mib + statics;
}

// One published pose: the trace line, availability and the error against the reference.
void account_pose(const ReplayOptions& o, const fw::LocalizationSystem& sys, const std::vector<fw::Se2d>& reference,
                  const hal::PoseEstimate& e, ReplayResult* r) {
  ++r->scans_processed;
  const fw::mml::MmlLocalizer* mml = sys.mml();
  if (o.trace && mml != nullptr && e.scan_id < reference.size()) {
    const fw::mml::InterpretResult& ir = mml->last();
    const fw::Se2d& ref = reference[e.scan_id];
    std::printf("trace %u %-10s %s err %6.3f pose %8.3f %8.3f %6.3f ref %8.3f %8.3f pl %.3f hyps %4u cl %3u r %.3f d2 %8.2f smed %6.2f c %d%d%d soft %d inl %.2f uq %d %.3f/%.3f\n",
                e.scan_id, hal::status_name(e.status), e.mode == hal::LocalizationMode::kTracking ? "trk" : "glb",
                std::hypot(e.x - ref.x, e.y - ref.y), e.x, e.y, e.theta, ref.x, ref.y, e.protection_xy_m,
                ir.hypotheses_valid, ir.cluster_count, ir.best_rating, ir.d2, ir.sigma_med, ir.c_rating,
                ir.c_mahalanobis, ir.c_median, ir.soft, mml->last_refine().inlier_ratio, mml->last_uniqueness().unique,
                mml->last_uniqueness().cost, mml->last_uniqueness().rival_cost);
  }
  // Availability: share of the poses after the first fix that are `localized` (as mml-sim).
  if (r->first_localized_scan >= 0) {
    ++r->after_first_fix;
    if (e.status == hal::LocalizationStatus::kLocalized) ++r->localized_after_first_fix;
  }
  if (e.status != hal::LocalizationStatus::kLocalized) return;
  if (r->first_localized_scan < 0) r->first_localized_scan = static_cast<long>(e.scan_id);
  r->last_localized_scan = static_cast<long>(e.scan_id);
  ++r->localized;
  const size_t idx = e.scan_id;  // to_laser_scan: scan_id = log index
  if (idx < reference.size()) {
    const double err = std::hypot(e.x - reference[idx].x, e.y - reference[idx].y);
    r->mean_err_localized_m += err;
    if (err > o.localized_bound_m) {
      ++r->wrong_localized;
      if (r->wrong_localized_scans.size() < 20) r->wrong_localized_scans.push_back(idx);
    }
  }
}

// Feeds the log's scans (at rate_hz of the wall clock, or in lockstep) with the odometry records
// between them interleaved by their log time, and runs the loop until every scan is processed (or
// the soak's duration is over). Sensor time is compressed the same way (per-scan motion unchanged).
class ReplayFeeder {
 public:
  ReplayFeeder(const ReplayOptions& o, const sim::CarmenLog& log, ReplayRig& rig, ReplayResult* r)
      : o_(o), log_(log), rig_(rig), r_(r), lose_rng_(o.lose_seed) {
    last_ = std::min(log.scans.size(), o.first_scan + o.num_scans);
    period_ = 1.0 / (o.rate_hz > 0 ? o.rate_hz : 75.0);
    for (size_t i = o.first_scan; i < last_; ++i) scan_t_.push_back(log.scans[i].ipc_timestamp);
    // Scan times in the HAL clock domain (hal/msg/laser_scan.h): scan k is due at t0 + k * period.
    t0_ = mono_ns() + 10'000'000;
    const double log_t0 = log.scans[o.first_scan].ipc_timestamp;
    while (oi_ < log.odom.size() && log.odom[oi_].ipc_timestamp < log_t0 - 0.5) ++oi_;
    oi_start_ = oi_;
    soak_ = o.duration_s > 0 && !rig.lockstep;
    next_sample_ns_ = t0_ + static_cast<std::uint64_t>(o.sample_period_s * 1e9);
    end_ns_ = soak_ ? t0_ + static_cast<std::uint64_t>(o.duration_s * 1e9)
                    : t0_ + (rig.lockstep ? 600'000'000'000ull
                                          : static_cast<std::uint64_t>((last_ - o.first_scan) * period_ * 1e9) +
                                                3'000'000'000ull);
  }
  std::uint64_t t0() const { return t0_; }

  void run(const std::vector<fw::Se2d>& reference) {
    while (true) {
      const std::uint64_t now = mono_ns();
      if (soak_ && k_ >= scan_t_.size() && now < end_ns_) {
        // Soak: one pass of the log lasts n * period; pass L runs L * n * period later in sensor time.
        k_ = 0;
        oi_ = oi_start_;
        ++r_->loops;
        loop_offset_ns_ = static_cast<std::uint64_t>(static_cast<double>(r_->loops * scan_t_.size()) * period_ * 1e9);
      }
      while (due(now)) feed_next();
      if (o_.on_sample && now >= next_sample_ns_) sample(now);
      rig_.loop->spin_once();
      // Lockstep: a scan waiting for odometry that will never come must see time pass (timeout).
      if (rig_.lockstep && !rig_.loop->stepped() && rig_.loop->scan_pending()) rig_.stepped->advance_ns(50'000'000);
      hal::PoseEstimate e;
      while (rig_.sink->pop(&e)) account_pose(o_, *rig_.sys, reference, e, r_);
      const bool idle = rig_.laser->pending() == 0 && !rig_.loop->scan_pending();
      if ((!soak_ || mono_ns() >= end_ns_) && k_ >= scan_t_.size() && idle) break;
      if (soak_ && mono_ns() >= end_ns_ && idle) break;
      if (mono_ns() > end_ns_ + (soak_ ? 3'000'000'000ull : 0)) break;
      if (!rig_.loop->stepped()) {
        timespec ts{0, 200'000};  // 0.2 ms: idle until the next scan is due
        nanosleep(&ts, nullptr);
      }
    }
  }

 private:
  // Piecewise-linear time warp of a log time: scan k of the log is at t0 + k * period.
  std::uint64_t warp(double ipc) const {
    auto it = std::upper_bound(scan_t_.begin(), scan_t_.end(), ipc);
    const size_t k = static_cast<size_t>(it - scan_t_.begin());
    double t;
    if (k == 0) t = 0;
    else if (k >= scan_t_.size()) t = (scan_t_.size() - 1) * period_;
    else {
      const double a = scan_t_[k - 1], b = scan_t_[k];
      t = ((k - 1) + (b > a ? (ipc - a) / (b - a) : 0)) * period_;
    }
    return t0_ + static_cast<std::uint64_t>(t * 1e9);
  }

  // The next scan is due: in lockstep when the loop has taken every scan fed so far, at rate when
  // its wall time has come.
  bool due(std::uint64_t now) const {
    if (k_ >= scan_t_.size() || (soak_ && now >= end_ns_)) return false;
    if (rig_.lockstep) {
      const hal::Health& h = rig_.loop->health();
      return rig_.laser->pending() == 0 && !rig_.loop->scan_pending() &&
             h.scans_processed + h.dropped_scans + r_->scans_dropped + r_->scans_lost >= k_;
    }
    return now >= t0_ + static_cast<std::uint64_t>(static_cast<double>(g_) * period_ * 1e9);
  }

  void feed_next() {
    const double tk = scan_t_[k_];
    while (oi_ < log_.odom.size() &&
           log_.odom[oi_].ipc_timestamp <= tk + 0.5 * (k_ + 1 < scan_t_.size() ? scan_t_[k_ + 1] - tk : 0)) {
      const sim::CarmenOdom& c = log_.odom[oi_++];
      hal::Odometry od;
      od.timestamp_ns = warp(c.ipc_timestamp) + loop_offset_ns_;
      od.x = static_cast<float>(c.pose.x);
      od.y = static_cast<float>(c.pose.y);
      od.theta = static_cast<float>(c.pose.theta);
      if (o_.mutate_odometry) o_.mutate_odometry(c.ipc_timestamp, &od);
      rig_.odom->push(od);
    }
    std::int64_t jitter_ns = 0;
    if (o_.scan_time_jitter_ms > 0)
      jitter_ns = static_cast<std::int64_t>((2.0 * lose_draw_(lose_rng_) - 1.0) * o_.scan_time_jitter_ms * 1e6);
    // Scan k at t0 + k·period exactly (= warp(tk) for distinct log times; logs with two scans at
    // one ipc time, as intel has, would otherwise feed the second at the same time: out of order).
    const std::uint64_t scan_ns = t0_ + static_cast<std::uint64_t>(static_cast<double>(k_) * period_ * 1e9);
    hal::LaserScan s = sim::to_laser_scan(log_.scans[o_.first_scan + k_], scan_ns + loop_offset_ns_ + jitter_ns);
    if (o_.mutate_scan) o_.mutate_scan(o_.first_scan + k_, &s);
    if (rig_.lockstep) rig_.stepped->set_ns(warp(k_ + 1 < scan_t_.size() ? scan_t_[k_ + 1] : tk));
    const bool lost_random =
        (o_.lose_prob > 0 && lose_draw_(lose_rng_) < o_.lose_prob) ||
        std::find(o_.lose_list.begin(), o_.lose_list.end(), o_.first_scan + k_) != o_.lose_list.end();
    if ((o_.lose_every > 0 && k_ % o_.lose_every == o_.lose_every - 1) || lost_random) {
      ++r_->scans_lost;
    } else if (!rig_.laser->push(s)) {
      ++r_->scans_dropped;
      ++r_->ring_overflows;
    }
    ++r_->scans_fed;
    ++k_;
    ++g_;
  }

  void sample(std::uint64_t now) {
    next_sample_ns_ += static_cast<std::uint64_t>(o_.sample_period_s * 1e9);
    ReplaySample smp;
    smp.elapsed_s = static_cast<double>(now - t0_) * 1e-9;
    smp.scans_fed = r_->scans_fed;
    smp.scans_processed = r_->scans_processed;
    smp.health_dropped = rig_.loop->health().dropped_scans;
    smp.ring_overflows = r_->ring_overflows;
    smp.localized = r_->localized;
    smp.wrong_localized = r_->wrong_localized;
    smp.loops = r_->loops;
    o_.on_sample(smp);
  }

  const ReplayOptions& o_;
  const sim::CarmenLog& log_;
  ReplayRig& rig_;
  ReplayResult* r_;
  std::vector<double> scan_t_;  // log times of the scans fed
  size_t last_ = 0;
  double period_ = 0;
  std::uint64_t t0_ = 0, end_ns_ = 0, next_sample_ns_ = 0, loop_offset_ns_ = 0;
  size_t oi_ = 0, oi_start_ = 0;
  size_t k_ = 0;  // index into scan_t_ of the next scan to feed
  size_t g_ = 0;  // scans fed over all loops (soak): scan g is due at t0 + g * period
  bool soak_ = false;
  std::mt19937_64 lose_rng_;
  std::uniform_real_distribution<double> lose_draw_{0.0, 1.0};
};

// Timing, the global context's figures and the loop's counters after the run.
void collect_results(ReplayRig& rig, double wall_s, ReplayResult* r) {
  fw::LocalizationSystem& sys = *rig.sys;
  sys.stop_global_context();  // before the pool it drives
  if (sys.tracked() != nullptr) {
    const fw::track::GlobalContext& gc = sys.tracked()->global_context();
    const fw::PerfStats gs = gc.step_stats();
    r->global_step_p50_ms = gs.p50_ms;
    r->global_step_p99_ms = gs.p99_ms;
    r->global_step_max_ms = gs.max_ms;
    r->global_jobs = gc.jobs();
    r->global_overruns = gc.overruns();
    r->global_skipped_offers = gc.skipped_offers();
    r->global_deadline_stops = sys.mml() != nullptr ? sys.mml()->deadline_stops() : 0;
    if (sys.mml() != nullptr) {
      r->global_front_end = sys.mml()->front_end_perf().stats();
      r->global_match = sys.mml()->match_perf().stats();
      r->global_after_match = sys.mml()->after_match_perf().stats();
    }
  }
  if (r->localized) r->mean_err_localized_m /= static_cast<double>(r->localized);
  if (r->after_first_fix) {
    r->availability = static_cast<double>(r->localized_after_first_fix) / static_cast<double>(r->after_first_fix);
  }
  rig.pool->stop();
  const fw::LocalizationLoop& loop = *rig.loop;
  const fw::PerfStats step = loop.perf_step().stats();
  r->step_p50_ms = step.p50_ms;
  r->step_p99_ms = step.p99_ms;
  r->step_max_ms = step.max_ms;
  r->cycle_p99_ms = loop.perf_total().stats().p99_ms;
  r->deadline_misses = loop.health().deadline_misses;
  // HEALTH dropped_scans includes the ring overflows counted above (SimLaserSource::skipped_scans).
  r->scans_dropped = loop.health().dropped_scans;
  r->health_dropped = loop.health().dropped_scans;
  r->pending_at_end = rig.laser->pending() + (loop.scan_pending() ? 1 : 0);
  r->scans_unpaired = loop.counters().scans_unpaired;
  r->scans_out_of_order = loop.counters().scans_out_of_order;
  r->scans_malformed = loop.counters().scans_malformed;
  r->achieved_rate_hz = wall_s > 0 ? static_cast<double>(r->scans_processed) / wall_s : 0;
}

}  // namespace

bool run_replay(const ReplayOptions& o, ReplayResult* r, std::string* error) {
  *r = ReplayResult{};
  const sim::Dataset* ds = sim::find_dataset(o.dataset);
  if (!ds || ds->raw_log.empty()) {
    *error = "dataset '" + o.dataset + "' unknown or without a raw log";
    return false;
  }
  sim::CarmenLog log;
  std::vector<fw::Se2d> reference;
  if (!load_replay_inputs(o, *ds, &log, &reference, r, error)) return false;
  const std::string dir = o.map_dir.empty() ? sim::map_cache_dir() : o.map_dir;
  sim::RosMap ros;
  if (!sim::ensure_global_map(o.dataset, 0, dir, &ros, error)) return false;
  ReplayRig rig;
  rig.lockstep = o.rate_hz <= 0;
  rig.gmode = o.global_context == "auto" ? (rig.lockstep ? "inline-ref" : "thread") : o.global_context;
  if (rig.gmode != "thread" && rig.gmode != "inline-live" && rig.gmode != "inline-ref") {
    *error = "global_context '" + rig.gmode + "': expected auto, thread, inline-live or inline-ref";
    return false;
  }
  rig.rt = o.realtime && !rig.lockstep;
  // As mmlfw with realtime = true (prepare_memory_and_sensor_context): every page locked and faulted
  // in before the arena is mapped, so no first touch of arena or stack during the replay waits for
  // the kernel to zero a page (the replay ran without it: it measured page faults mmlfw never takes).
  // The process goes on after the replay (tests): unlocked again on the way out.
  if (rig.rt && mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    *error = std::string("mlockall refused (") + std::strerror(errno) + ")";
    return false;
  }
  struct UnlockOnExit {
    bool on;
    ~UnlockOnExit() {
      if (on) munlockall();
    }
  } unlock{rig.rt};
  if (!load_replay_map(sim::global_map_image_path(o.dataset, dir), &rig, r, error)) return false;
  int old_policy = SCHED_OTHER;
  sched_param old_param{};
  pthread_getschedparam(pthread_self(), &old_policy, &old_param);
  struct RestoreSched {  // the process goes on (tests): this thread back to its old policy
    bool on;
    int policy;
    sched_param param;
    ~RestoreSched() {
      if (on) pthread_setschedparam(pthread_self(), policy, &param);
    }
  } restore{rig.rt, old_policy, old_param};
  if (!rig.lockstep && (o.pin_sensor_thread || rig.rt)) {
    char warning[160];
    const fw::Status st = fw::apply_execution_context_here(fw::kSensorContext, rig.rt, warning);
    if (!st) { *error = st.message(); return false; }
  }
  r->realtime = rig.rt;
  if (!start_replay_pool(o, &rig, r, error)) return false;
  if (!build_replay_localizer(o, &rig, r, error)) {
    rig.pool->stop();
    return false;
  }
  record_memory(rig, r);
  ReplayFeeder feeder(o, log, rig, r);
  feeder.run(reference);
  collect_results(rig, static_cast<double>(mono_ns() - feeder.t0()) * 1e-9, r);
  return true;
}

bool read_budget(const std::string& path, std::map<std::string, double>* out, std::string* error) {
  std::ifstream in(path);
  if (!in) { *error = path + ": cannot open"; return false; }
  std::string line;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    const auto hash = line.find('#');
    if (hash != std::string::npos) line.resize(hash);
    std::istringstream ls(line);
    std::string key, eq, value;
    if (!(ls >> key)) continue;
    if (!(ls >> eq >> value) || eq != "=") {
      *error = path + ":" + std::to_string(n) + ": expected 'key = value'";
      return false;
    }
    char* end = nullptr;
    const double v = std::strtod(value.c_str(), &end);
    if (*end || !std::isfinite(v)) {
      if (key == "dataset" || key == "localizer") continue;  // text keys
      *error = path + ":" + std::to_string(n) + ": key '" + key + "': '" + value + "' is not a number";
      return false;
    }
    (*out)[key] = v;
  }
  return true;
}

std::vector<std::string> check_budget(const std::map<std::string, double>& b, const ReplayResult& r) {
  std::vector<std::string> v;
  std::map<std::string, bool> known = {{"replay_scans", true}, {"scan_rate_hz", true}};
  auto lim = [&](const std::string& key, double value, bool max = true) {
    known[key] = true;
    auto it = b.find(key);
    if (it == b.end()) return;
    if (max ? value > it->second : value < it->second) {
      v.push_back(key + ": measured " + std::to_string(value) + (max ? " > " : " < ") + std::to_string(it->second));
    }
  };
  lim("static_memory_total_mib", r.static_memory_mib);
  for (const auto& [module, mib] : r.module_mib) lim("static_memory_mib." + module, mib);
  // The sensor-rate path (scan in → tracking → pose out): every step within the scan period.
  lim("deadline_misses", static_cast<double>(r.deadline_misses));
  lim("step_max_ms", r.step_max_ms);
  lim("step_p99_ms", r.step_p99_ms);
  lim("cycle_p99_ms", r.cycle_p99_ms);
  lim("dropped_scans", static_cast<double>(r.scans_dropped));
  lim("processed_rate_hz_min", r.achieved_rate_hz, false);
  // The global context (MML): p99 within its own period; overruns of its window counted.
  lim("global_step_p99_ms", r.global_step_p99_ms);
  lim("global_overruns", static_cast<double>(r.global_overruns));
  for (const auto& [key, value] : b) {
    if (!known.count(key) && key.rfind("static_memory_mib.", 0) != 0) v.push_back(key + ": not a limit the checker knows (it could never fail)");
  }
  return v;
}

}  // namespace mmlfw_hil
