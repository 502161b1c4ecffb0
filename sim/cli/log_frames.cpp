#include "sim/cli/log_frames.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <utility>

#include "firmware/base/rng.h"
#include "sim/io/carmen_log.h"
#include "sim/io/log_replay.h"
#include "sim/io/reference_trajectory.h"
#include "sim/world/odometry_model.h"

namespace sim {

namespace {

// The source scan of every replayed step, and the step of the kidnapped frame (0 = no kidnapping).
struct ReplayOrder {
  std::vector<std::size_t> scans;
  std::size_t jump_step = 0;
};

// The whole log is read even with --steps: the reference is chained from corrected poses that may
// lie beyond the first N scans (aces: the first corrected pose is not at scan 0).
bool read_log_and_reference(const SimConfig& cfg, CarmenLog* log, std::vector<ReferencePose>* truth,
                            std::string* err) {
  CarmenReadOptions ro;
  ro.max_bytes = cfg.max_log_bytes;
  if (!read_carmen_log(cfg.log_path, ro, log, err)) return false;
  if (log->scans.empty()) {
    *err = "log '" + cfg.log_path + "' contains no laser scans";
    return false;
  }
  const std::size_t n = log->scans.size();
  if (cfg.log_start >= n) {
    *err = "--start " + std::to_string(cfg.log_start) + ": the log '" + cfg.log_path + "' has only " +
           std::to_string(n) + " scans (0.." + std::to_string(n - 1) + ")";
    return false;
  }
  if (!cfg.reference_path.empty()) {
    std::vector<CorrectedPose> corrected;
    if (!read_corrected_poses(cfg.reference_path, &corrected, err)) return false;
    *truth = reference_with_bounds(*log, corrected);
    if (truth->empty()) {
      *err = "reference '" + cfg.reference_path + "' has no pose matching a scan of '" + cfg.log_path + "'";
      return false;
    }
  }
  return true;
}

// --kidnap-at: the scans from --start up to the carry, then from a scan chosen by the seed among
// those ≥ kLogKidnapMinJumpM away with 50 scans (or a quarter of the log) to run on, to the end.
bool plan_kidnapped_order(const SimConfig& cfg, const CarmenLog& log, const std::vector<ReferencePose>& truth,
                          ReplayOrder* order, std::string* err) {
  const std::size_t n = log.scans.size();
  const std::size_t last_before = cfg.log_start + cfg.log_kidnap_at - 1;  // last scan before the carry
  if (last_before + 1 >= n) {
    *err = "--kidnap-at " + std::to_string(cfg.log_kidnap_at) + ": after the end of the log (" +
           std::to_string(n - cfg.log_start) + " scans from --start " + std::to_string(cfg.log_start) + ")";
    return false;
  }
  auto where = [&](std::size_t i) { return i < truth.size() ? truth[i].pose : log.scans[i].pose; };
  const fw::Se2d here = where(last_before);
  const std::size_t tail = std::min<std::size_t>(50, n / 4);
  std::vector<std::size_t> cand;
  for (std::size_t j = 1; j + tail < n; ++j) {
    const fw::Se2d p = where(j);
    if (std::hypot(p.x - here.x, p.y - here.y) >= kLogKidnapMinJumpM) cand.push_back(j);
  }
  if (cand.empty()) {
    *err = "--kidnap-at " + std::to_string(cfg.log_kidnap_at) + ": no scan of the log lies " +
           std::to_string(kLogKidnapMinJumpM).substr(0, 3) + " m or more from the pose at scan " +
           std::to_string(last_before);
    return false;
  }
  fw::RandomStream rng(cfg.seed, 5);  // stream 5: the kidnapping, as in synthetic worlds
  const std::size_t to = cand[rng.uniform_index(static_cast<std::uint32_t>(cand.size()))];
  for (std::size_t i = cfg.log_start; i <= last_before; ++i) order->scans.push_back(i);
  order->jump_step = order->scans.size();
  for (std::size_t i = to; i < n; ++i) order->scans.push_back(i);
  if (cfg.progress) {
    const fw::Se2d p = where(to);
    std::fprintf(stderr, "mml-sim: kidnapping at step %zu: the replay jumps from scan %zu to scan %zu (%.1f m away%s)\n",
                 order->jump_step, last_before, to, std::hypot(p.x - here.x, p.y - here.y),
                 truth.empty() ? ", by the log's own poses" : "");
  }
  return true;
}

bool plan_replay_order(const SimConfig& cfg, const CarmenLog& log, const std::vector<ReferencePose>& truth,
                       ReplayOrder* order, std::string* err) {
  if (cfg.log_kidnap_at > 0) {
    if (!plan_kidnapped_order(cfg, log, truth, order, err)) return false;
  } else {
    for (std::size_t i = cfg.log_start; i < log.scans.size(); ++i) order->scans.push_back(i);
  }
  if (cfg.steps > 0 && order->scans.size() > cfg.steps) order->scans.resize(cfg.steps);
  return true;
}

// Turns the replay order into frames, one scan at a time. The odometry of the replay is
// A ⊕ (the log's odometry); A changes at the kidnapping only.
class FrameBuilder {
 public:
  FrameBuilder(const CarmenLog& log, const std::vector<ReferencePose>& truth, const ReplayOrder& order)
      : log_(log), truth_(truth), order_(order) {
    t0_ = log.scans[order.scans.front()].ipc_timestamp;
    last_ts_ = t0_;
    next_odom_ = order.scans.front() > 0 ? first_odom_after(log.scans[order.scans.front() - 1].line) : 0;
  }

  Frame frame(std::size_t k, std::size_t* restamped) {
    const std::size_t i = order_.scans[k];
    const CarmenScan& s = log_.scans[i];
    const bool scan_has_odom = s.type.rfind("RAWLASER", 0) != 0;
    Frame f;
    f.index = static_cast<std::uint32_t>(k);
    if (k > 0 && k == order_.jump_step) {
      f.kidnapped = true;
      carry_to(i, scan_has_odom);
    }
    const double ts_scan = scan_time(k, s, restamped);
    f.t = ts_scan - t0_;
    add_odometry(s, scan_has_odom, ts_scan, &f);
    f.scan = to_laser_scan(s, to_ns(ts_scan));
    f.scan.scan_id = f.index;
    if (i < truth_.size()) {
      f.has_truth = true;
      f.truth = truth_[i].pose;
      f.truth_bound_m = truth_[i].bound;
      f.truth_bound_rad = truth_[i].bound_theta;
    }
    const fw::Se2d here = f.has_truth ? f.truth : s.odom;
    if (k > 0 && k != order_.jump_step) travelled_ += std::hypot(here.x - prev_.x, here.y - prev_.y);
    prev_ = here;
    f.travelled_m = travelled_;
    return f;
  }

 private:
  std::size_t first_odom_after(std::size_t line) const {
    return static_cast<std::size_t>(std::upper_bound(log_.odom.begin(), log_.odom.end(), line,
                                                     [](std::size_t l, const CarmenOdom& o) { return l < o.line; }) -
                                    log_.odom.begin());
  }

  std::uint64_t to_ns(double ts) const { return seconds_to_ns(ts - t0_ + 1.0); }

  hal::Odometry odometry_sample(const fw::Se2d& src, std::uint64_t t_ns, double v, double w) {
    const fw::Se2d o = A_.compose(src);
    const hal::Odometry h = odometry_message(o, v, w, t_ns);
    last_src_odom_ = src;
    last_out_odom_ = o;
    have_odom_ = true;
    return h;
  }

  // Carried away to scan i: time goes on by the log's own scan interval; the odometry chains on
  // from the last replayed sample with the increments of the new part.
  void carry_to(std::size_t i, bool scan_has_odom) {
    const CarmenScan& s = log_.scans[i];
    const double dt = s.ipc_timestamp - log_.scans[i - 1].ipc_timestamp;
    shift_ = last_ts_ + std::max(dt, 1e-3) - s.ipc_timestamp;
    next_odom_ = first_odom_after(log_.scans[i - 1].line);
    fw::Se2d q = log_.scans[i - 1].odom;
    if (!scan_has_odom) {
      q = last_src_odom_;
      if (next_odom_ > 0) q = log_.odom[next_odom_ - 1].pose;
    }
    if (have_odom_) A_ = last_out_odom_.compose(q.inverse());
  }

  // Some logs step back in time (intel: 631 scans whose ipc and logger stamps are earlier than the
  // previous scan's). The scan line carries its own odometry, so file order is the truth: such a
  // scan is re-stamped 1 ms after its predecessor (counted), keeping scan and odometry together.
  double scan_time(std::size_t k, const CarmenScan& s, std::size_t* restamped) {
    double ts_scan = s.ipc_timestamp + shift_;
    if (k > 0 && ts_scan <= last_ts_) {
      ts_scan = last_ts_ + 1e-3;
      if (k != order_.jump_step) ++*restamped;
    }
    last_ts_ = ts_scan;
    return ts_scan;
  }

  // Scans that carry the odometry at their own time stamp (FLASER, RLASER, ROBOTLASER1) are paired
  // with exactly that; separate ODOM records are used only for scans without it (RAWLASER). Mixing
  // both would feed the loop out-of-order samples: in intel, ODOM records are stamped up to 0.4 s
  // after the FLASER lines that follow them.
  void add_odometry(const CarmenScan& s, bool scan_has_odom, double ts_scan, Frame* f) {
    while (next_odom_ < log_.odom.size() && log_.odom[next_odom_].line < s.line) {
      const CarmenOdom& o = log_.odom[next_odom_++];
      if (scan_has_odom) continue;
      const double ts = o.ipc_timestamp + shift_;
      f->odometry.push_back(odometry_sample(o.pose, ts >= t0_ - 1.0 ? to_ns(ts) : 0, o.tv, o.rv));
    }
    if (scan_has_odom) f->odometry.push_back(odometry_sample(s.odom, to_ns(ts_scan), 0, 0));
  }

  const CarmenLog& log_;
  const std::vector<ReferencePose>& truth_;
  const ReplayOrder& order_;
  double t0_ = 0, last_ts_ = 0, shift_ = 0;
  std::size_t next_odom_ = 0;
  double travelled_ = 0;
  fw::Se2d prev_;
  fw::Se2d A_, last_src_odom_, last_out_odom_;
  bool have_odom_ = false;
};

// The log's odometry is taken as the true motion and perturbed as in synthetic worlds
// (sim/world/odometry_model.h: σ per scan step, split over the samples of a step).
void add_odometry_noise(const SimConfig& cfg, std::vector<Frame>* frames) {
  OdometryNoiseOptions no;
  no.sigma_trans = cfg.log_odom_sigma_m;
  no.sigma_rot_deg = cfg.log_odom_sigma_deg;
  for (const Frame& f : *frames) {
    if (f.odometry.empty()) continue;
    no.odom_origin = fw::Se2d(f.odometry.front().x, f.odometry.front().y, f.odometry.front().theta);
    break;
  }
  OdometrySimulator sim_odom(no, cfg.seed);
  bool started = false;
  for (Frame& f : *frames) {
    const double frac = f.odometry.empty() ? 1.0 : 1.0 / static_cast<double>(f.odometry.size());
    for (hal::Odometry& h : f.odometry) {
      const fw::Se2d src(h.x, h.y, h.theta);
      h = started ? sim_odom.next(src, h.timestamp_ns, frac) : sim_odom.start(src, h.timestamp_ns);
      started = true;
    }
  }
}

}  // namespace

bool load_log_frames(const SimConfig& cfg, std::vector<Frame>* frames, std::size_t* restamped, std::string* err) {
  CarmenLog log;
  std::vector<ReferencePose> truth;
  if (!read_log_and_reference(cfg, &log, &truth, err)) return false;
  ReplayOrder order;
  if (!plan_replay_order(cfg, log, truth, &order, err)) return false;
  FrameBuilder builder(log, truth, order);
  for (std::size_t k = 0; k < order.scans.size(); ++k) frames->push_back(builder.frame(k, restamped));
  if (cfg.log_odom_noise) add_odometry_noise(cfg, frames);
  return true;
}

}  // namespace sim
