#include "sim/cli/sim_runner.h"

#include "firmware/app/localizer_names.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <memory>
#include <thread>

#include "firmware/base/arena.h"
#include "firmware/map/map_image.h"
#include "firmware/runtime/localization_loop.h"
#include "hal/hal.h"
#include "hal_linux/linux_clock.h"
#include "hal_sim/sim_hal.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/log_replay.h"
#include "sim/io/reference_trajectory.h"
#include "sim/map/global_maps.h"
#include "sim/map/map_image_writer.h"
#include "sim/viz/picture.h"
#include "sim/world/builtin_worlds.h"
#include "sim/world/odometry_model.h"
#include "firmware/base/rng.h"

namespace sim {

namespace {

constexpr double kRadToDeg = 180.0 / M_PI;
// Success bounds of the dissertation (Sec. 5.7): a localized estimate farther off is a failure.
constexpr double kWrongM = 0.5, kWrongDeg = 20.0;

struct Frame {
  std::uint32_t index = 0;
  double t = 0;
  bool kidnapped = false;
  bool has_truth = false;
  fw::Se2d truth;
  double travelled_m = 0;
  std::vector<hal::Odometry> odometry;
  hal::LaserScan scan;
};

struct FrameInfo {
  double t = 0;
  bool has_truth = false;
  fw::Se2d truth;
  double travelled_m = 0;
  bool kidnapped = false;
  bool in_unknown = false;
};

// A CARMEN log prepared as frames: odometry records in file order before each scan, plus the
// scan's own odometry triple (FLASER/RLASER/ROBOTLASER1) at the scan time. --start skips the first
// scans; --kidnap-at jumps to another part of the log (the odometry continues with that part's
// increments, so it sees nothing); --odom-noise perturbs every odometry increment.
bool load_log_frames(const SimConfig& cfg, std::vector<Frame>* frames, std::size_t* restamped, std::string* err) {
  CarmenLog log;
  // The whole log is read even with --steps: the reference is chained from corrected poses that
  // may lie beyond the first N scans (aces: the first corrected pose is not at scan 0).
  CarmenReadOptions ro;
  ro.max_bytes = cfg.max_log_bytes;
  if (!read_carmen_log(cfg.log_path, ro, &log, err)) return false;
  if (log.scans.empty()) {
    *err = "log '" + cfg.log_path + "' contains no laser scans";
    return false;
  }
  const size_t n = log.scans.size();
  if (cfg.log_start >= n) {
    *err = "--start " + std::to_string(cfg.log_start) + ": the log '" + cfg.log_path + "' has only " +
           std::to_string(n) + " scans (0.." + std::to_string(n - 1) + ")";
    return false;
  }
  std::vector<fw::Se2d> truth;
  if (!cfg.reference_path.empty()) {
    std::vector<CorrectedPose> corrected;
    if (!read_corrected_poses(cfg.reference_path, &corrected, err)) return false;
    truth = reference_at_every_scan(log, corrected);
    if (truth.empty()) {
      *err = "reference '" + cfg.reference_path + "' has no pose matching a scan of '" + cfg.log_path + "'";
      return false;
    }
  }
  // Source scan of every replayed step.
  std::vector<size_t> order;
  size_t jump_step = 0;  // step of the kidnapped frame (0 = no kidnapping)
  if (cfg.log_kidnap_at > 0) {
    const size_t last_before = cfg.log_start + cfg.log_kidnap_at - 1;  // last scan before the carry
    if (last_before + 1 >= n) {
      *err = "--kidnap-at " + std::to_string(cfg.log_kidnap_at) + ": after the end of the log (" +
             std::to_string(n - cfg.log_start) + " scans from --start " + std::to_string(cfg.log_start) + ")";
      return false;
    }
    auto where = [&](size_t i) { return i < truth.size() ? truth[i] : log.scans[i].pose; };
    const fw::Se2d here = where(last_before);
    // Candidates: ≥ kLogKidnapMinJumpM away, with 50 scans (or a quarter of the log) to run on.
    const size_t tail = std::min<size_t>(50, n / 4);
    std::vector<size_t> cand;
    for (size_t j = 1; j + tail < n; ++j) {
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
    const size_t to = cand[rng.uniform_index(static_cast<std::uint32_t>(cand.size()))];
    for (size_t i = cfg.log_start; i <= last_before; ++i) order.push_back(i);
    jump_step = order.size();
    for (size_t i = to; i < n; ++i) order.push_back(i);
    if (cfg.progress) {
      const fw::Se2d p = where(to);
      std::fprintf(stderr, "mml-sim: kidnapping at step %zu: the replay jumps from scan %zu to scan %zu (%.1f m away%s)\n",
                   jump_step, last_before, to, std::hypot(p.x - here.x, p.y - here.y),
                   truth.empty() ? ", by the log's own poses" : "");
    }
  } else {
    for (size_t i = cfg.log_start; i < n; ++i) order.push_back(i);
  }
  if (cfg.steps > 0 && order.size() > cfg.steps) order.resize(cfg.steps);

  const double t0 = log.scans[order.front()].ipc_timestamp;
  double last_ts = t0, shift = 0;
  auto first_odom_after = [&](size_t line) {
    return static_cast<size_t>(std::upper_bound(log.odom.begin(), log.odom.end(), line,
                                                [](size_t l, const CarmenOdom& o) { return l < o.line; }) -
                               log.odom.begin());
  };
  size_t next_odom = order.front() > 0 ? first_odom_after(log.scans[order.front() - 1].line) : 0;
  double travelled = 0;
  fw::Se2d prev;
  // Odometry of the replay = A ⊕ (the log's odometry); A changes at the kidnapping only.
  fw::Se2d A, last_src_odom, last_out_odom;
  bool have_odom = false;
  auto emit = [&](const fw::Se2d& src, std::uint64_t t_ns, double v, double w) {
    const fw::Se2d o = A.compose(src);
    hal::Odometry h;
    h.timestamp_ns = t_ns;
    h.x = static_cast<float>(o.x);
    h.y = static_cast<float>(o.y);
    h.theta = static_cast<float>(o.theta);
    h.v = static_cast<float>(v);
    h.omega = static_cast<float>(w);
    last_src_odom = src;
    last_out_odom = o;
    have_odom = true;
    return h;
  };
  for (size_t k = 0; k < order.size(); ++k) {
    const size_t i = order[k];
    const CarmenScan& s = log.scans[i];
    const bool scan_has_odom = s.type.rfind("RAWLASER", 0) != 0;
    Frame f;
    f.index = static_cast<std::uint32_t>(k);
    if (k > 0 && k == jump_step) {
      // Carried away: time goes on by the log's own scan interval; the odometry chains on from the
      // last replayed sample with the increments of the new part.
      f.kidnapped = true;
      const double dt = s.ipc_timestamp - log.scans[i - 1].ipc_timestamp;
      shift = last_ts + std::max(dt, 1e-3) - s.ipc_timestamp;
      next_odom = first_odom_after(log.scans[i - 1].line);
      fw::Se2d q = log.scans[i - 1].odom;
      if (!scan_has_odom) {
        q = last_src_odom;
        if (next_odom > 0) q = log.odom[next_odom - 1].pose;
      }
      if (have_odom) A = last_out_odom.compose(q.inverse());
    }
    // Some logs step back in time (intel: 631 scans whose ipc and logger stamps are earlier than the
    // previous scan's). The scan line carries its own odometry, so file order is the truth: such a
    // scan is re-stamped 1 ms after its predecessor (counted), keeping scan and odometry together.
    double ts_scan = s.ipc_timestamp + shift;
    if (k > 0 && ts_scan <= last_ts) {
      ts_scan = last_ts + 1e-3;
      if (k != jump_step) ++*restamped;
    }
    last_ts = ts_scan;
    f.t = ts_scan - t0;
    auto to_ns = [&](double ts) { return seconds_to_ns(ts - t0 + 1.0); };
    // Scans that carry the odometry at their own time stamp (FLASER, RLASER, ROBOTLASER1) are paired
    // with exactly that; separate ODOM records are used only for scans without it (RAWLASER). Mixing
    // both would feed the loop out-of-order samples: in intel, ODOM records are stamped up to 0.4 s
    // after the FLASER lines that follow them.
    while (next_odom < log.odom.size() && log.odom[next_odom].line < s.line) {
      const CarmenOdom& o = log.odom[next_odom++];
      if (scan_has_odom) continue;
      const double ts = o.ipc_timestamp + shift;
      f.odometry.push_back(emit(o.pose, ts >= t0 - 1.0 ? to_ns(ts) : 0, o.tv, o.rv));
    }
    if (scan_has_odom) f.odometry.push_back(emit(s.odom, to_ns(ts_scan), 0, 0));
    f.scan = to_laser_scan(s, to_ns(ts_scan));
    f.scan.scan_id = f.index;
    if (i < truth.size()) {
      f.has_truth = true;
      f.truth = truth[i];
    }
    const fw::Se2d here = f.has_truth ? f.truth : s.odom;
    if (k > 0 && k != jump_step) travelled += std::hypot(here.x - prev.x, here.y - prev.y);
    prev = here;
    f.travelled_m = travelled;
    frames->push_back(std::move(f));
  }
  if (cfg.log_odom_noise) {
    // The log's odometry is taken as the true motion and perturbed as in synthetic worlds
    // (sim/world/odometry_model.h: σ per scan step, split over the samples of a step).
    OdometryNoiseOptions no;
    no.sigma_trans = cfg.log_odom_sigma_m;
    no.sigma_rot_deg = cfg.log_odom_sigma_deg;
    bool started = false;
    for (Frame& f : *frames) {
      if (!started && !f.odometry.empty()) {
        no.odom_origin = fw::Se2d(f.odometry.front().x, f.odometry.front().y, f.odometry.front().theta);
      }
      if (!f.odometry.empty()) break;
    }
    OdometrySimulator sim_odom(no, cfg.seed);
    for (Frame& f : *frames) {
      const double frac = f.odometry.empty() ? 1.0 : 1.0 / static_cast<double>(f.odometry.size());
      for (hal::Odometry& h : f.odometry) {
        const fw::Se2d src(h.x, h.y, h.theta);
        h = started ? sim_odom.next(src, h.timestamp_ns, frac) : sim_odom.start(src, h.timestamp_ns);
        started = true;
      }
    }
  }
  return true;
}

// A compiled map image starts with the magic "MMLFWMAP" (firmware/map/map_image.h).
bool is_map_image_file(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) return false;  // errors: left to the YAML reader
  std::FILE* f = std::fopen(path.c_str(), "rb");
  if (f == nullptr) return false;
  char magic[8] = {};
  const bool ok = std::fread(magic, 1, sizeof(magic), f) == sizeof(magic) && std::memcmp(magic, "MMLFWMAP", 8) == 0;
  std::fclose(f);
  return ok;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t idx = static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(idx, v.size() - 1)];
}

std::string fmt(const char* f, ...) __attribute__((format(printf, 1, 2)));
std::string fmt(const char* f, ...) {
  char b[512];
  va_list ap;
  va_start(ap, f);
  std::vsnprintf(b, sizeof(b), f, ap);
  va_end(ap);
  return b;
}

std::string final_error_text(const SimSummary& s) {
  if (s.final_pose_step < 0) return "final error: none (no step with a pose)";
  if (!std::isfinite(s.final_err_m)) {
    return fmt("final pose: step %ld (%s), no ground truth", s.final_pose_step, s.final_pose_status.c_str());
  }
  return fmt("final error %.2f m / %.1f deg (step %ld, %s)", s.final_err_m, s.final_err_deg, s.final_pose_step,
             s.final_pose_status.c_str());
}

std::string availability_text(const SimSummary& s) {
  if (!std::isfinite(s.availability)) return "availability n/a";
  std::string t = fmt("availability %.1f %% (%zu/%zu steps after the fix", 100.0 * s.availability,
                      s.availability_localized, s.availability_steps);
  if (s.unknown_area_steps > 0) t += fmt(", %zu in unknown area left out", s.unknown_area_steps);
  return t + ")";
}

std::string pl_text(const SimSummary& s) {
  if (s.pl_steps == 0) return "protection level: none published";
  std::string t = fmt("protection level median %.2f m / %.1f deg, max %.2f m / %.1f deg", s.pl_xy_m_p50,
                      s.pl_theta_deg_p50, s.pl_xy_m_max, s.pl_theta_deg_max);
  if (s.pl_scored > 0) {
    t += fmt(", exceeded %zu/%zu (%.2f %%)", s.pl_exceeded, s.pl_scored, 100.0 * s.pl_exceedance_rate);
  }
  return t;
}

std::string kidnap_text(const SimSummary& s) {
  std::string t = fmt("kidnap at step %ld", s.kidnap_step);
  if (s.kidnap_detected_step < 0) return t + ": never detected (localized to the end)";
  t += fmt(": detected after %ld steps", s.kidnap_detection_delay_steps);
  if (s.relocalized_step < 0) return t + ", no re-fix before the end";
  return t + fmt(", re-fixed after %.1f m / %.1f s", s.refix_travelled_m, s.refix_s);
}

Rgb status_colour(hal::LocalizationStatus s) {
  switch (s) {
    case hal::LocalizationStatus::kSearching: return {150, 150, 150};
    case hal::LocalizationStatus::kAmbiguous: return {240, 150, 0};
    case hal::LocalizationStatus::kLocalized: return {20, 90, 230};
    case hal::LocalizationStatus::kOutsideMap: return {150, 60, 200};
    case hal::LocalizationStatus::kFault: return {220, 0, 0};
  }
  return {0, 0, 0};
}

bool write_pictures(const SimConfig& cfg, const SimResult& r, const World* world, const OccupancyGrid* grid,
                    std::string* err) {
  Picture pic;
  const SimSummary& s = r.summary;
  pic.title = "mml-sim: " + s.source + ", localizer " + s.localizer + ", seed " + std::to_string(cfg.seed);
  // Notes short enough for the PNG font (12 px a character over ~1600 px).
  char buf[320];
  if (s.first_localized_step >= 0) {
    std::snprintf(buf, sizeof(buf), "first fix at step %ld after %.1f s / %.1f m (error %.2f m); %s",
                  s.first_localized_step, s.first_localized_t, s.first_localized_travelled_m, s.first_localized_err_m,
                  availability_text(s).c_str());
  } else {
    std::snprintf(buf, sizeof(buf), "never localized in %zu steps (%.1f m driven)", s.steps, s.path_length_m);
  }
  pic.notes.push_back(buf);
  std::snprintf(buf, sizeof(buf), "integrity failures %zu (localized, error > %.1f m or > %.0f deg)",
                s.integrity_failures, kIntegrityLimitM, kIntegrityLimitDeg);
  pic.notes.push_back(buf);
  pic.notes.push_back(pl_text(s));
  if (s.kidnap_step >= 0) pic.notes.push_back(kidnap_text(s));
  std::snprintf(buf, sizeof(buf), "step time p50 %.2f ms, p99 %.2f ms; %s", s.step_ms_p50, s.step_ms_p99,
                final_error_text(s).c_str());
  pic.notes.push_back(buf);
  pic.map = grid;
  if (world != nullptr) {
    for (const Box& b : world->unknown_areas) {
      pic.boxes.push_back({b.min.x(), b.min.y(), b.max.x(), b.max.y(), {200, 40, 160}, "unknown area (not in map)"});
    }
  }
  Polyline truth{{}, {0, 160, 60}, 3.0, "ground truth"};
  // The estimate is drawn as a line only while localized (a global localizer's best guess jumps
  // around while it searches: those steps are dots coloured by status).
  Polyline est{{}, {20, 90, 230}, 2.0, "estimate while localized"};
  std::vector<Polyline> est_runs;
  PointSet by_status[5];
  const char* names[5] = {"searching", "ambiguous", "localized", "outside-map", "fault"};
  for (int i = 0; i < 5; ++i) {
    by_status[i].color = status_colour(static_cast<hal::LocalizationStatus>(i));
    by_status[i].radius_px = 2.0;
    by_status[i].label = std::string("estimate: ") + names[i];
  }
  // Protection level as a circle around the estimate at every n-th `localized` step (about 100
  // circles at most), and every integrity failure as a cross.
  std::size_t with_pl = 0;
  for (const StepRecord& st : r.steps) {
    with_pl += st.estimate.status == hal::LocalizationStatus::kLocalized && st.estimate.protection_xy_m > 0;
  }
  const std::size_t pl_every = std::max<std::size_t>(10, (with_pl + 99) / 100);
  CircleSet pl_circles{{}, {0, 170, 190}, 1.2,
                       "protection level (1 in " + std::to_string(pl_every) + " localized)"};
  PointSet failures{{}, {255, 0, 40}, 7.0,
                    "integrity failure (" + std::to_string(s.integrity_failures) + ")",
                    PointShape::kCross};
  std::size_t pl_seen = 0;
  std::vector<Polyline> truth_before;
  for (const StepRecord& st : r.steps) {
    const bool loc = st.estimate.status == hal::LocalizationStatus::kLocalized;
    if (loc && st.estimate.protection_xy_m > 0 && pl_seen++ % pl_every == 0) {
      pl_circles.circles.push_back({st.estimate.x, st.estimate.y, st.estimate.protection_xy_m});
    }
    if (loc && std::isfinite(st.err_m) && (st.err_m > kIntegrityLimitM || st.err_deg > kIntegrityLimitDeg)) {
      failures.points.push_back({st.estimate.x, st.estimate.y});
    }
    if (st.kidnapped && !truth.points.empty()) {  // no line across the carry
      truth_before.push_back(truth);
      truth_before.back().label.clear();
      truth.points.clear();
    }
    if (st.has_truth) truth.points.push_back({st.truth.x, st.truth.y});
    if (st.estimate.status == hal::LocalizationStatus::kLocalized && !st.kidnapped) {
      est.points.push_back({st.estimate.x, st.estimate.y});
    } else if (!est.points.empty()) {
      est_runs.push_back(est);
      est.points.clear();
    }
    // A dot for every pose the localizer gave (a dead-reckoning pose while `searching` too), never
    // for the (0, 0, 0) placeholder of a step without one.
    const hal::PoseEstimate& e = st.estimate;
    const int k = static_cast<int>(e.status);
    if (k >= 0 && k < 5 && !is_placeholder_pose(e) && e.status != hal::LocalizationStatus::kFault) {
      by_status[k].points.push_back({e.x, e.y});
    }
  }
  if (!pl_circles.circles.empty()) pic.circle_sets.push_back(pl_circles);
  for (const auto& l : truth_before) pic.lines.push_back(l);
  pic.lines.push_back(truth);
  if (!est.points.empty()) est_runs.push_back(est);
  for (size_t i = 0; i < est_runs.size(); ++i) {
    if (i > 0) est_runs[i].label.clear();
    pic.lines.push_back(est_runs[i]);
  }
  for (auto& ps : by_status) {
    if (!ps.points.empty()) pic.point_sets.push_back(ps);
  }
  // Shown (with its count) whenever there is a fix, so a clean run says "0" in the legend.
  if (s.first_localized_step >= 0) pic.point_sets.push_back(failures);
  if (!r.last_hypotheses.empty()) {
    PointSet h{{}, {230, 30, 30}, 3.0, "hypotheses (step " + std::to_string(r.last_hypotheses_step) + ")"};
    for (const auto& p : r.last_hypotheses) h.points.push_back({p.x, p.y});
    pic.point_sets.push_back(h);
  }
  if (!r.steps.empty() && r.steps.front().has_truth) {
    const auto& f = r.steps.front().truth;
    pic.markers.push_back({f.x, f.y, f.theta, {0, 160, 60}, 7.0, "start"});
    const auto& l = r.steps.back().truth;
    pic.markers.push_back({l.x, l.y, l.theta, {0, 110, 40}, 5.0, "end"});
  }
  if (s.kidnap_step >= 0) {
    const auto& k = r.steps[static_cast<size_t>(s.kidnap_step)].truth;
    pic.markers.push_back({k.x, k.y, k.theta, {200, 0, 0}, 7.0, "kidnapped to"});
  }
  if (s.first_localized_step >= 0) {
    const auto& e = r.steps[static_cast<size_t>(s.first_localized_step)].estimate;
    pic.markers.push_back({e.x, e.y, e.theta, {20, 90, 230}, 9.0, "localized"});
  }
  // Without a map, frame the picture on the ground truth only (a dead-reckoning estimate from the
  // origin may be far away).
  if (grid == nullptr && world != nullptr) {
    pic.x_min = world->bounds.min.x() - 1;
    pic.y_min = world->bounds.min.y() - 1;
    pic.x_max = world->bounds.max.x() + 1;
    pic.y_max = world->bounds.max.y() + 1;
  }
  const std::string base = cfg.out_dir + "/run";
  return write_svg(pic, base + ".svg", err) && write_png(pic, base + ".png", err);
}

}  // namespace

bool write_steps_csv(const std::string& path, const std::vector<StepRecord>& steps, std::string* err) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *err = "cannot write '" + path + "'";
    return false;
  }
  std::fprintf(f,
               "step,t_s,scan_id,status,mode,x,y,theta,truth_x,truth_y,truth_theta,err_m,err_deg,travelled_m,"
               "hypotheses,clusters,rating,odom_x,odom_y,odom_theta,cov_xx,cov_yy,cov_tt,step_ms,kidnapped,"
               "pl_xy_m,pl_theta_deg,unsupported_steps,in_unknown\n");
  for (const StepRecord& s : steps) {
    const hal::PoseEstimate& e = s.estimate;
    std::fprintf(f, "%u,%.3f,%u,%s,%s,%.4f,%.4f,%.5f,", s.step, s.t, e.scan_id, hal::status_name(e.status),
                 e.mode == hal::LocalizationMode::kTracking ? "tracking" : "global", e.x, e.y, e.theta);
    if (s.has_truth) {
      std::fprintf(f, "%.4f,%.4f,%.5f,", s.truth.x, s.truth.y, s.truth.theta);
    } else {
      std::fprintf(f, ",,,");
    }
    // The error only where there is a pose to score (never from a placeholder).
    if (std::isfinite(s.err_m) && std::isfinite(s.err_deg)) {
      std::fprintf(f, "%.4f,%.3f,", s.err_m, s.err_deg);
    } else {
      std::fprintf(f, ",,");
    }
    std::fprintf(f, "%.3f,%u,%u,%.4f,%.4f,%.4f,%.5f,%.6g,%.6g,%.6g,%.4f,%d,", s.travelled_m, e.hypothesis_count,
                 e.cluster_count, e.rating, s.odom.x, s.odom.y, s.odom.theta, e.cov[0], e.cov[4], e.cov[8], s.step_ms,
                 s.kidnapped ? 1 : 0);
    // Protection level: empty when none was published (0).
    if (e.protection_xy_m > 0 || e.protection_theta_rad > 0) {
      std::fprintf(f, "%.4f,%.3f,", e.protection_xy_m, e.protection_theta_rad * kRadToDeg);
    } else {
      std::fprintf(f, ",,");
    }
    std::fprintf(f, "%u,%d\n", e.unsupported_steps, s.in_unknown ? 1 : 0);
  }
  const bool ok = std::fclose(f) == 0;
  if (!ok) *err = "error writing '" + path + "'";
  return ok;
}

// --transport: what went over the simulated bus and what the firmware's decoder made of it.
static void write_transport_json(std::FILE* f, const SimSummary& s) {
  const TransportStats& t = s.transport_stats;
  const hal_can::DecoderStats& d = t.decoder;
  auto u = [](std::uint64_t v) { return static_cast<unsigned long long>(v); };
  std::fprintf(f, "  \"transport\": \"%s\",\n", s.transport.c_str());
  std::fprintf(f, "  \"transport_scans_sent\": %llu,\n  \"transport_odometry_sent\": %llu,\n  \"transport_frames_sent\": %llu,\n",
               u(t.scans_sent), u(t.odometry_sent), u(t.frames_sent));
  std::fprintf(f, "  \"transport_encode_failed\": %llu,\n  \"transport_bus_full\": %llu,\n", u(t.encode_failed),
               u(t.bus_full));
  std::fprintf(f, "  \"transport_faults_frames_dropped\": %llu,\n  \"transport_faults_frames_corrupted\": %llu,\n",
               u(t.frames_dropped), u(t.frames_corrupted));
  std::fprintf(f, "  \"decoder_frames\": %llu,\n  \"decoder_scans_ok\": %llu,\n  \"decoder_scans_dropped\": %llu,\n",
               u(d.frames), u(d.scans_ok), u(d.scans_dropped));
  std::fprintf(f, "  \"decoder_crc_errors\": %llu,\n  \"decoder_lost_segments\": %llu,\n  \"decoder_malformed\": %llu,\n",
               u(d.crc_errors), u(d.lost_segments), u(d.malformed));
  std::fprintf(f, "  \"decoder_orphan_segments\": %llu,\n  \"decoder_unknown_ids\": %llu,\n  \"decoder_invalid_scans\": %llu,\n",
               u(d.orphan_segments), u(d.unknown_ids), u(d.invalid_scans));
  std::fprintf(f, "  \"decoder_odometry_ok\": %llu,\n  \"decoder_broken_records\": %llu,\n", u(d.odometry_ok),
               u(d.broken_records));
  std::fprintf(f, "  \"sick_telegrams_sent\": %llu,\n  \"sick_parser_telegrams\": %llu,\n  \"sick_crc_errors\": %llu,\n",
               u(t.telegrams_sent), u(t.sick_telegrams), u(t.sick_crc_errors));
  std::fprintf(f, "  \"sick_bad_length\": %llu,\n  \"sick_garbage_bytes\": %llu,\n  \"sick_scans_ok\": %llu,\n",
               u(t.sick_bad_length), u(t.sick_garbage_bytes), u(t.sick_scans));
  std::fprintf(f, "  \"sick_bad_measurements\": %llu,\n  \"sick_scans_dropped\": %llu\n", u(t.sick_bad_measurements),
               u(t.scans_sent > t.sick_scans ? t.scans_sent - t.sick_scans : 0));
}

// One clause of the summary line for a run through a transport with bytes (empty for none).
static std::string transport_text(const SimSummary& s) {
  if (s.transport == "none") return {};
  const TransportStats& t = s.transport_stats;
  if (s.transport == "sick") {
    const std::uint64_t lost = t.scans_sent > t.sick_scans ? t.scans_sent - t.sick_scans : 0;
    return fmt("transport sick: %llu telegrams, %llu dropped + %llu corrupted by fault injection; driver: %u scans ok, "
               "%llu dropped (CRC %u, bad length %u, garbage bytes %u, bad measurements %u)",
               static_cast<unsigned long long>(t.telegrams_sent), static_cast<unsigned long long>(t.frames_dropped),
               static_cast<unsigned long long>(t.frames_corrupted), t.sick_scans, static_cast<unsigned long long>(lost),
               t.sick_crc_errors, t.sick_bad_length, t.sick_garbage_bytes, t.sick_bad_measurements);
  }
  std::string x = fmt("transport %s: %llu frames, %llu dropped + %llu corrupted by fault injection; decoder: %u scans ok, "
                      "%u dropped (CRC %u, lost segments %u, malformed %u), %u odometry ok, %u broken records",
                      s.transport.c_str(), static_cast<unsigned long long>(t.frames_sent),
                      static_cast<unsigned long long>(t.frames_dropped), static_cast<unsigned long long>(t.frames_corrupted),
                      t.decoder.scans_ok, t.decoder.scans_dropped, t.decoder.crc_errors, t.decoder.lost_segments,
                      t.decoder.malformed, t.decoder.odometry_ok, t.decoder.broken_records);
  if (t.encode_failed > 0) x += fmt(", %llu not encodable", static_cast<unsigned long long>(t.encode_failed));
  if (t.bus_full > 0) x += fmt(", %llu refused by a full bus", static_cast<unsigned long long>(t.bus_full));
  return x;
}

bool write_summary_json(const std::string& path, const SimSummary& s, std::string* err) {
  std::FILE* f = std::fopen(path.c_str(), "w");
  if (!f) {
    *err = "cannot write '" + path + "'";
    return false;
  }
  auto num = [](double v) {
    char b[48];
    if (!std::isfinite(v)) return std::string("null");
    std::snprintf(b, sizeof(b), "%.6g", v);
    return std::string(b);
  };
  std::fprintf(f, "{\n  \"source\": \"%s\",\n  \"localizer\": \"%s\",\n  \"steps\": %zu,\n", s.source.c_str(),
               s.localizer.c_str(), s.steps);
  std::fprintf(f, "  \"first_localized_step\": %ld,\n  \"first_localized_t_s\": %s,\n", s.first_localized_step,
               s.first_localized_step >= 0 ? num(s.first_localized_t).c_str() : "null");
  std::fprintf(f, "  \"first_localized_travelled_m\": %s,\n  \"first_localized_err_m\": %s,\n",
               s.first_localized_step >= 0 ? num(s.first_localized_travelled_m).c_str() : "null",
               s.first_localized_step >= 0 ? num(s.first_localized_err_m).c_str() : "null");
  std::fprintf(f, "  \"first_localized_pl_xy_m\": %s,\n", num(s.first_localized_pl_xy_m).c_str());
  std::fprintf(f, "  \"availability\": %s,\n  \"availability_steps\": %zu,\n  \"availability_localized_steps\": %zu,\n",
               num(s.availability).c_str(), s.availability_steps, s.availability_localized);
  std::fprintf(f, "  \"unknown_area_steps_excluded\": %zu,\n", s.unknown_area_steps);
  std::fprintf(f, "  \"integrity_failures\": %zu,\n  \"integrity_failures_before_kidnap_detection\": %zu,\n",
               s.integrity_failures, s.integrity_failures_kidnap);
  std::fprintf(f, "  \"first_integrity_failure_step\": %ld,\n  \"integrity_limit_m\": %s,\n  \"integrity_limit_deg\": %s,\n",
               s.first_integrity_failure_step, num(kIntegrityLimitM).c_str(), num(kIntegrityLimitDeg).c_str());
  std::fprintf(f, "  \"pl_steps\": %zu,\n  \"pl_scored_steps\": %zu,\n  \"pl_exceeded_steps\": %zu,\n  \"pl_exceedance_rate\": %s,\n",
               s.pl_steps, s.pl_scored, s.pl_exceeded, num(s.pl_exceedance_rate).c_str());
  std::fprintf(f, "  \"pl_xy_m_p50\": %s,\n  \"pl_xy_m_max\": %s,\n  \"pl_theta_deg_p50\": %s,\n  \"pl_theta_deg_max\": %s,\n",
               num(s.pl_xy_m_p50).c_str(), num(s.pl_xy_m_max).c_str(), num(s.pl_theta_deg_p50).c_str(),
               num(s.pl_theta_deg_max).c_str());
  std::fprintf(f, "  \"tracking_steps\": %zu,\n  \"tracking_err_m_p50\": %s,\n  \"tracking_err_m_p95\": %s,\n",
               s.tracking_steps, num(s.tracking_err_m_p50).c_str(), num(s.tracking_err_m_p95).c_str());
  std::fprintf(f, "  \"tracking_err_deg_p50\": %s,\n  \"tracking_err_deg_p95\": %s,\n", num(s.tracking_err_deg_p50).c_str(),
               num(s.tracking_err_deg_p95).c_str());
  std::fprintf(f, "  \"kidnap_step\": %ld,\n  \"kidnap_jump_m\": %s,\n  \"kidnap_detected_step\": %ld,\n", s.kidnap_step,
               num(s.kidnap_jump_m).c_str(), s.kidnap_detected_step);
  std::fprintf(f, "  \"kidnap_detection_delay_steps\": %ld,\n  \"relocalized_step\": %ld,\n",
               s.kidnap_detection_delay_steps, s.relocalized_step);
  std::fprintf(f, "  \"refix_travelled_m\": %s,\n  \"refix_s\": %s,\n  \"refix_err_m\": %s,\n", num(s.refix_travelled_m).c_str(),
               num(s.refix_s).c_str(), num(s.refix_err_m).c_str());
  std::fprintf(f, "  \"localized_steps\": %zu,\n  \"wrong_localized_steps\": %zu,\n", s.localized_steps,
               s.wrong_localized_steps);
  std::fprintf(f, "  \"mean_err_localized_m\": %s,\n  \"max_err_localized_m\": %s,\n", num(s.mean_err_localized_m).c_str(),
               num(s.max_err_localized_m).c_str());
  std::fprintf(f, "  \"final_err_m\": %s,\n  \"final_err_deg\": %s,\n  \"final_pose_step\": %ld,\n  \"final_pose_status\": %s,\n",
               num(s.final_err_m).c_str(), num(s.final_err_deg).c_str(), s.final_pose_step,
               s.final_pose_step >= 0 ? ("\"" + s.final_pose_status + "\"").c_str() : "null");
  const char* names[5] = {"searching", "ambiguous", "localized", "outside_map", "fault"};
  for (int i = 0; i < 5; ++i) std::fprintf(f, "  \"steps_%s\": %zu,\n", names[i], s.status_counts[i]);
  std::fprintf(f, "  \"step_ms_mean\": %s,\n  \"step_ms_p50\": %s,\n  \"step_ms_p99\": %s,\n  \"step_ms_max\": %s,\n",
               num(s.step_ms_mean).c_str(), num(s.step_ms_p50).c_str(), num(s.step_ms_p99).c_str(),
               num(s.step_ms_max).c_str());
  std::fprintf(f, "  \"path_length_m\": %s,\n  \"load_s\": %s,\n  \"wall_s\": %s,\n  \"scans_per_s\": %s,\n",
               num(s.path_length_m).c_str(), num(s.load_s).c_str(), num(s.wall_s).c_str(), num(s.scans_per_s).c_str());
  std::fprintf(f, "  \"scans_dropped\": %zu,\n  \"ring_drops\": %llu,\n  \"odom_rejected\": %llu,\n", s.scans_dropped,
               static_cast<unsigned long long>(s.ring_drops), static_cast<unsigned long long>(s.odom_rejected));
  std::fprintf(f, "  \"scans_restamped\": %zu,\n  \"deadline_misses\": %llu,\n", s.scans_restamped,
               static_cast<unsigned long long>(s.deadline_misses));
  std::fprintf(f, "  \"scans_held\": %llu,\n  \"step_errors\": %llu,\n", static_cast<unsigned long long>(s.scans_held),
               static_cast<unsigned long long>(s.step_errors));
  write_transport_json(f, s);
  std::fprintf(f, "}\n");
  const bool ok = std::fclose(f) == 0;
  if (!ok) *err = "error writing '" + path + "'";
  return ok;
}

bool is_placeholder_pose(const hal::PoseEstimate& e) {
  if (!std::isfinite(e.x) || !std::isfinite(e.y) || !std::isfinite(e.theta)) return true;
  if (e.x != 0.0f || e.y != 0.0f || e.theta != 0.0f) return false;
  for (float c : e.cov) {
    if (c != 0.0f) return false;
  }
  return true;
}

bool estimate_has_pose(const hal::PoseEstimate& e) {
  if (e.status == hal::LocalizationStatus::kSearching || e.status == hal::LocalizationStatus::kFault) return false;
  return !is_placeholder_pose(e);
}

void summarize_steps(const std::vector<StepRecord>& steps, SimSummary* s) {
  const SimSummary keep = *s;
  // Start from the defaults for every derived field, keep what the caller measured.
  *s = SimSummary();
  s->source = keep.source;
  s->localizer = keep.localizer;
  s->scans_dropped = keep.scans_dropped;
  s->wall_s = keep.wall_s;
  s->scans_per_s = keep.scans_per_s;
  s->load_s = keep.load_s;
  s->odom_rejected = keep.odom_rejected;
  s->scans_held = keep.scans_held;
  s->ring_drops = keep.ring_drops;
  s->transport = keep.transport;
  s->transport_stats = keep.transport_stats;
  s->step_errors = keep.step_errors;
  s->scans_restamped = keep.scans_restamped;
  s->deadline_misses = keep.deadline_misses;
  s->steps = steps.size();
  if (steps.empty()) return;

  std::vector<double> ms, err_loc, trk_m, trk_deg, glob_m, glob_deg, pl_xy, pl_th;
  bool any_tracking = false;
  double kidnap_travelled = 0, kidnap_t = 0;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const StepRecord& r = steps[i];
    const hal::PoseEstimate& e = r.estimate;
    const long step = static_cast<long>(i);
    const bool loc = e.status == hal::LocalizationStatus::kLocalized;
    const bool scored = std::isfinite(r.err_m) && std::isfinite(r.err_deg);
    ms.push_back(r.step_ms);
    const int k = static_cast<int>(e.status);
    if (k >= 0 && k < 5) ++s->status_counts[k];

    // Kidnapping: detection = the first step from the kidnap scan on that is not `localized`; the
    // re-fix = the first `localized` step after that.
    if (r.kidnapped && s->kidnap_step < 0) {
      s->kidnap_step = step;
      kidnap_travelled = r.travelled_m;
      kidnap_t = r.t;
      if (i > 0 && steps[i - 1].has_truth && r.has_truth) {
        s->kidnap_jump_m = std::hypot(r.truth.x - steps[i - 1].truth.x, r.truth.y - steps[i - 1].truth.y);
      }
    }
    const bool undetected_kidnap = s->kidnap_step >= 0 && s->kidnap_detected_step < 0;
    if (undetected_kidnap && !loc) {
      s->kidnap_detected_step = step;
      s->kidnap_detection_delay_steps = step - s->kidnap_step;
    } else if (s->kidnap_detected_step >= 0 && s->relocalized_step < 0 && loc) {
      s->relocalized_step = step;
      s->refix_travelled_m = r.travelled_m - kidnap_travelled;
      s->refix_s = r.t - kidnap_t;
      s->refix_err_m = r.err_m;
    }

    // Availability over the steps after the first fix (the unknown area left out).
    if (s->first_localized_step >= 0) {
      if (r.in_unknown) {
        ++s->unknown_area_steps;
      } else {
        ++s->availability_steps;
        if (loc) ++s->availability_localized;
      }
    }

    if (loc) {
      ++s->localized_steps;
      if (s->first_localized_step < 0) {
        s->first_localized_step = step;
        s->first_localized_t = r.t;
        s->first_localized_travelled_m = r.travelled_m;
        s->first_localized_err_m = r.err_m;
        if (e.protection_xy_m > 0) s->first_localized_pl_xy_m = e.protection_xy_m;
      }
      if (scored) {
        err_loc.push_back(r.err_m);
        if (r.err_m >= kWrongM || r.err_deg >= kWrongDeg) ++s->wrong_localized_steps;
        if (r.err_m > kIntegrityLimitM || r.err_deg > kIntegrityLimitDeg) {
          ++s->integrity_failures;
          if (undetected_kidnap) ++s->integrity_failures_kidnap;
          if (s->first_integrity_failure_step < 0) s->first_integrity_failure_step = step;
        }
        if (e.mode == hal::LocalizationMode::kTracking) {
          any_tracking = true;
          trk_m.push_back(r.err_m);
          trk_deg.push_back(r.err_deg);
        } else {
          glob_m.push_back(r.err_m);
          glob_deg.push_back(r.err_deg);
        }
      }
      if (e.protection_xy_m > 0 || e.protection_theta_rad > 0) {
        ++s->pl_steps;
        pl_xy.push_back(e.protection_xy_m);
        pl_th.push_back(e.protection_theta_rad * kRadToDeg);
        if (scored) {
          ++s->pl_scored;
          if (r.err_m > e.protection_xy_m || r.err_deg > e.protection_theta_rad * kRadToDeg) ++s->pl_exceeded;
        }
      }
    }
    if (r.has_pose) {
      s->final_pose_step = step;
      s->final_pose_status = hal::status_name(e.status);
      s->final_err_m = r.err_m;
      s->final_err_deg = r.err_deg;
    }
  }
  if (s->availability_steps > 0) {
    s->availability = static_cast<double>(s->availability_localized) / static_cast<double>(s->availability_steps);
  }
  if (!err_loc.empty()) {
    double sum = 0;
    for (double v : err_loc) sum += v;
    s->mean_err_localized_m = sum / static_cast<double>(err_loc.size());
    s->max_err_localized_m = *std::max_element(err_loc.begin(), err_loc.end());
  }
  // A localizer without a tracking mode (mml): its `localized` steps are the tracking error.
  if (!any_tracking) {
    trk_m.swap(glob_m);
    trk_deg.swap(glob_deg);
  }
  s->tracking_steps = trk_m.size();
  if (!trk_m.empty()) {
    s->tracking_err_m_p50 = percentile(trk_m, 0.5);
    s->tracking_err_m_p95 = percentile(trk_m, 0.95);
    s->tracking_err_deg_p50 = percentile(trk_deg, 0.5);
    s->tracking_err_deg_p95 = percentile(trk_deg, 0.95);
  }
  if (s->pl_scored > 0) s->pl_exceedance_rate = static_cast<double>(s->pl_exceeded) / static_cast<double>(s->pl_scored);
  if (!pl_xy.empty()) {
    s->pl_xy_m_p50 = percentile(pl_xy, 0.5);
    s->pl_xy_m_max = *std::max_element(pl_xy.begin(), pl_xy.end());
    s->pl_theta_deg_p50 = percentile(pl_th, 0.5);
    s->pl_theta_deg_max = *std::max_element(pl_th.begin(), pl_th.end());
  }
  s->path_length_m = steps.back().travelled_m;
  double tot = 0;
  for (double v : ms) tot += v;
  s->step_ms_mean = tot / static_cast<double>(ms.size());
  s->step_ms_p50 = percentile(ms, 0.5);
  s->step_ms_p99 = percentile(ms, 0.99);
  s->step_ms_max = *std::max_element(ms.begin(), ms.end());
}

std::string summary_line(const SimSummary& s) {
  std::string t = "mml-sim summary: " + s.source + ", " + s.localizer + ", " + std::to_string(s.steps) + " steps: ";
  if (s.first_localized_step >= 0) {
    t += fmt("first fix at step %ld (%.1f s, %.1f m)", s.first_localized_step, s.first_localized_t,
             s.first_localized_travelled_m);
  } else {
    t += "no fix";
  }
  t += "; " + availability_text(s);
  t += fmt("; integrity failures %zu (> %.1f m or > %.0f deg)", s.integrity_failures, kIntegrityLimitM,
           kIntegrityLimitDeg);
  t += "; " + pl_text(s);
  if (std::isfinite(s.tracking_err_m_p50)) {
    t += fmt("; tracking error median %.3f m, p95 %.3f m", s.tracking_err_m_p50, s.tracking_err_m_p95);
  }
  if (s.kidnap_step >= 0) t += "; " + kidnap_text(s);
  t += fmt("; step p50 %.2f ms, p99 %.2f ms", s.step_ms_p50, s.step_ms_p99);
  t += "; " + final_error_text(s);
  if (s.transport != "none") t += "; " + transport_text(s);
  return t;
}

std::string summary_story(const SimSummary& s) {
  std::string t;
  if (s.first_localized_step < 0) {
    t += fmt("  no fix in %zu steps (%.1f m driven)\n", s.steps, s.path_length_m);
  } else {
    t += fmt("  first fix at step %ld after %.1f s and %.1f m", s.first_localized_step, s.first_localized_t,
             s.first_localized_travelled_m);
    if (std::isfinite(s.first_localized_err_m)) t += fmt(", error %.2f m", s.first_localized_err_m);
    if (std::isfinite(s.first_localized_pl_xy_m)) t += fmt(", protection level %.2f m", s.first_localized_pl_xy_m);
    t += "\n  then: " + availability_text(s);
    if (std::isfinite(s.tracking_err_m_p50)) {
      t += fmt("; error while localized median %.3f m, p95 %.3f m (%.2f / %.2f deg)", s.tracking_err_m_p50,
               s.tracking_err_m_p95, s.tracking_err_deg_p50, s.tracking_err_deg_p95);
    }
    t += "\n";
  }
  if (s.kidnap_step >= 0) {
    t += fmt("  kidnapped at step %ld", s.kidnap_step);
    if (std::isfinite(s.kidnap_jump_m)) t += fmt(" (carried %.1f m; the odometry saw nothing)", s.kidnap_jump_m);
    if (s.kidnap_detected_step < 0) {
      t += ": never detected, localized to the end";
    } else {
      t += fmt(": not localized from step %ld (detected after %ld steps)", s.kidnap_detected_step,
               s.kidnap_detection_delay_steps);
      if (s.relocalized_step < 0) {
        t += "; no re-fix before the end of the run";
      } else {
        t += fmt("; localized again at step %ld after %.1f m / %.1f s", s.relocalized_step, s.refix_travelled_m,
                 s.refix_s);
        if (std::isfinite(s.refix_err_m)) t += fmt(", error %.2f m", s.refix_err_m);
      }
    }
    t += "\n";
  }
  t += fmt("  integrity: %zu of %zu localized steps off by > %.1f m or > %.0f deg", s.integrity_failures,
           s.localized_steps, kIntegrityLimitM, kIntegrityLimitDeg);
  if (s.integrity_failures_kidnap > 0) t += fmt(" (%zu before the kidnap was detected)", s.integrity_failures_kidnap);
  t += "; " + pl_text(s) + "\n";
  t += "  " + final_error_text(s) + "\n";
  if (s.transport != "none") t += "  " + transport_text(s) + "\n";
  return t;
}

// --dataset NAME: the raw log, its reference poses and the global map built from the corrected log
// (cached by sim/map/global_maps.h under build/maps).
bool resolve_dataset(SimConfig* cfg, std::string* err) {
  const Dataset* ds = find_dataset(cfg->dataset);
  if (ds == nullptr) {
    std::string names;
    for (const Dataset& d : datasets()) names += (names.empty() ? "" : ", ") + d.name;
    *err = "unknown dataset '" + cfg->dataset + "' (known: " + names + ")";
    return false;
  }
  if (ds->raw_log.empty()) {
    *err = "dataset '" + cfg->dataset + "' has no raw log";
    return false;
  }
  cfg->log_path = data_path(ds->raw_log);
  if (!std::filesystem::exists(cfg->log_path)) {
    *err = "dataset '" + cfg->dataset + "': log '" + cfg->log_path + "' not found (MMLFW_DATA_DIR=" + data_dir() + ")";
    return false;
  }
  if (cfg->reference_path.empty() && !ds->corrected_poses.empty()) cfg->reference_path = data_path(ds->corrected_poses);
  if (cfg->map_yaml.empty()) {
    RosMap m;
    if (!ensure_global_map(cfg->dataset, 0.0, map_cache_dir(), &m, err)) {
      *err = "dataset '" + cfg->dataset + "': global map: " + *err;
      return false;
    }
    cfg->map_yaml = global_map_yaml_path(cfg->dataset);
  }
  return true;
}

bool run_simulation(const SimConfig& cfg_in, SimResult* out, std::string* err) {
  *out = SimResult();
  const auto load_start = std::chrono::steady_clock::now();
  SimConfig cfg = cfg_in;
  if (!cfg.dataset.empty()) {
    if (!cfg.world.empty() || !cfg.log_path.empty()) {
      *err = "--dataset excludes --world and --log";
      return false;
    }
    if (!resolve_dataset(&cfg, err)) return false;
  }
  if (!cfg.out_dir.empty()) {  // fail before a long run, not after it
    std::error_code ec;
    std::filesystem::create_directories(cfg.out_dir, ec);
    if (ec || !std::filesystem::is_directory(cfg.out_dir)) {
      *err = "cannot create output directory '" + cfg.out_dir + "'" + (ec ? ": " + ec.message() : "");
      return false;
    }
  }
  if (cfg.localizer.empty()) {
    cfg.localizer = "odom";
    for (const LocalizerInfo& l : localizer_names()) {
      if (l.name == fw::kDefaultLocalizer) cfg.localizer = fw::kDefaultLocalizer;  // the firmware's default
    }
  }
  if (cfg.custom_world != nullptr) {
    if (!cfg.world.empty() || !cfg.log_path.empty()) {
      *err = "a custom world excludes --world and --log";
      return false;
    }
    cfg.world = cfg.custom_world->name.empty() ? "custom" : cfg.custom_world->name;
  }
  if (cfg.world.empty() == cfg.log_path.empty()) {
    *err = "give exactly one of a world (--world) or a log (--log)";
    return false;
  }
  if (!cfg.reference_path.empty() && cfg.log_path.empty()) {
    *err = "--reference needs --log";
    return false;
  }
  // ---- source and map ----
  std::vector<std::uint8_t> image;  // the compiled map image the firmware loads
  bool image_from_file = false;
  World world;
  SyntheticRun synthetic;
  std::vector<Frame> log_frames;
  OccupancyGrid grid;
  bool have_grid = false;
  std::size_t total = 0;
  SimSummary& sum = out->summary;
  sum.localizer = cfg.localizer;
  if (!cfg.world.empty()) {
    if (cfg.custom_world != nullptr) {
      world = *cfg.custom_world;
    } else if (!make_builtin_world(cfg.world, &world, err)) {
      return false;
    }
    SyntheticRunOptions so = cfg.synthetic;
    so.seed = cfg.seed;
    if (cfg.steps > 0) so.max_scans = cfg.steps;
    if (!synthetic.init(world, so, err)) {
      *err = "world '" + cfg.world + "': " + *err;
      return false;
    }
    if (!rasterize_world(world, cfg.raster, &grid, err)) return false;
    have_grid = true;
    total = synthetic.num_scans();
    sum.source = "world:" + cfg.world;
  } else {
    if (!load_log_frames(cfg, &log_frames, &sum.scans_restamped, err)) return false;
    total = log_frames.size();
    if (!cfg.map_yaml.empty()) {
      if (is_map_image_file(cfg.map_yaml)) {
        // A compiled map image (mml-mapc / mml-mapbuild): used as it is, relation table included.
        if (!read_file_bytes(cfg.map_yaml, &image, err)) return false;
        image_from_file = true;
      } else {
        RosMap rm;
        if (!read_ros_map(cfg.map_yaml, &rm, err) || !ros_map_to_grid(rm, &grid, err)) return false;
      }
      have_grid = true;
    }
    sum.source = cfg.dataset.empty() ? "log:" + std::filesystem::path(cfg.log_path).filename().string()
                                     : "dataset:" + cfg.dataset;
  }

  // ---- compiled map image, loaded by the firmware's own loader into a start-up arena ----
  fw::StartupArena arena;
  fw::GlobalMap global_map;
  if (have_grid) {
    if (!image_from_file) {
      MapImageWriter writer;
      if (!writer.set_grid(grid, err)) return false;
      image = writer.bytes();
    }
    const std::string what = image_from_file ? cfg.map_yaml : std::string("simulated map");
    fw::Status s = arena.init_mapped(fw::map_image_arena_bytes(image.data(), image.size()) + (1u << 20), false, "map");
    if (s.is_ok()) s = fw::load_map_image(image.data(), image.size(), arena, &global_map, what.c_str());
    if (!s.is_ok()) {
      *err = (image_from_file ? cfg.map_yaml + ": " : std::string("map: ")) + s.message();
      return false;
    }
    if (image_from_file && cfg.progress) {
      std::size_t table_len = 0;
      const bool table = fw::find_section(image.data(), image.size(), fw::MapSectionType::kRelationTable2D,
                                          &table_len) != nullptr;
      std::fprintf(stderr, "mml-sim: map image %s: %ux%u cells at %.3g m; relation table: %s\n", cfg.map_yaml.c_str(),
                   global_map.geometry.width, global_map.geometry.height,
                   static_cast<double>(global_map.geometry.resolution),
                   table ? "in the image (used as it is)" : "none (the localizer fills its own at start-up)");
    }
    if (image_from_file) {
      // The host grid (pictures, map.yaml, the MCL baseline) from the image's own occupancy.
      grid.geometry = global_map.geometry;
      grid.cells.assign(grid.geometry.cell_count(), fw::kCellUnknown);
      for (std::uint32_t cy = 0; cy < grid.geometry.height; ++cy) {
        for (std::uint32_t cx = 0; cx < grid.geometry.width; ++cx) {
          grid.cells[grid.geometry.index(cx, cy)] =
              global_map.cell(static_cast<std::int32_t>(cx), static_cast<std::int32_t>(cy));
        }
      }
    }
  }

  // ---- localizer ----
  LocalizerHooks hooks;
  LocalizerContext ctx;
  ctx.global_map = have_grid ? &global_map : nullptr;
  ctx.map_image = have_grid ? &image : nullptr;
  ctx.grid = have_grid ? &grid : nullptr;
  ctx.map_name = cfg.world.empty() ? cfg.map_yaml : cfg.world;
  ctx.seed = cfg.seed;
  ctx.threads = cfg.threads;
  ctx.options = cfg.localizer_options;
  ctx.hooks = &hooks;
  if (!cfg.world.empty()) {
    ctx.has_true_start = true;
    ctx.true_start = synthetic.trajectory().pose_at(0);
  } else if (!log_frames.empty() && log_frames.front().has_truth) {
    ctx.has_true_start = true;
    ctx.true_start = log_frames.front().truth;
  }
  std::unique_ptr<fw::Localizer> localizer = make_localizer(cfg.localizer, ctx, err);
  if (!localizer) return false;

  // ---- HAL (simulation backend) and the firmware loop ----
  auto sim_hal = std::make_unique<hal_sim::SimHal>();
  hal_sim::SteppedClock* clock = &sim_hal->clock;
  hal_sim::SimLaserSource* laser = &sim_hal->laser;
  hal_sim::SimOdometrySource* odom = &sim_hal->odometry;
  hal_sim::SimPoseSink* sink = &sim_hal->pose_sink;
  hal_sim::SimLogSink* logs = &sim_hal->log;
  hal_sim::SimTaskRunner* tasks = &sim_hal->tasks;
  hal::Hal& hal = sim_hal->hal;
  hal_linux::LinuxClock wall_clock;
  hal_sim::SteppedClock frozen_clock;  // perf clock when timing is off: every duration is 0
  // --transport can: the loop reads the firmware's CanNode on the hal/sim loopback bus instead of
  // the rings (sim/devices/sensor_transport.h), on the same stepped clock.
  auto transport = std::make_unique<SensorTransport>();
  TransportOptions topt = cfg.transport;
  topt.seed = cfg.seed;
  if (!transport->init(topt, clock, err)) return false;
  if (topt.transport != Transport::kNone) hal.laser = &transport->laser();
  if (transport->carries_odometry()) hal.odometry = &transport->odometry();
  sum.transport = transport_name(topt.transport);
  auto loop = std::make_unique<fw::LocalizationLoop>();
  fw::LocalizationLoopOptions lo;
  lo.perf_clock = cfg.wall_timing ? static_cast<const hal::Clock*>(&wall_clock) : &frozen_clock;
  lo.step_deadline_ns = static_cast<std::uint64_t>(cfg.deadline_ms * 1e6);
  fw::Status s = loop->init(hal, *localizer, lo);
  if (!s.is_ok()) {
    *err = s.message();
    return false;
  }
  struct TaskCtx {
    fw::LocalizationLoop* loop;
    fw::Status status;
  } task_ctx{loop.get(), fw::Status::ok()};
  tasks->add_task("localization", [](void* c) {
    auto* tc = static_cast<TaskCtx*>(c);
    tc->status = tc->loop->spin_once();
  }, &task_ctx, 0);

  // ---- run ----
  std::vector<FrameInfo> info;
  info.reserve(total);
  const auto wall_start = std::chrono::steady_clock::now();
  out->summary.load_s = std::chrono::duration<double>(wall_start - load_start).count();
  auto last_progress = wall_start - std::chrono::seconds(1);
  const bool tty = isatty(fileno(stderr)) != 0;
  hal::LocalizationStatus last_status = hal::LocalizationStatus::kSearching;
  std::uint64_t ring_drops = 0;

  // hypotheses.csv: every hypothesis of every step, when the localizer exposes them.
  std::vector<HypothesisPoint> step_hyps;
  std::FILE* hyp_csv = nullptr;
  if (hooks.hypotheses && !cfg.out_dir.empty()) {
    const std::string path = cfg.out_dir + "/hypotheses.csv";
    hyp_csv = std::fopen(path.c_str(), "w");
    if (hyp_csv == nullptr) {
      *err = "cannot write '" + path + "'";
      return false;
    }
    std::fprintf(hyp_csv, "step,x,y,theta,weight\n");
  }
  auto drain = [&]() {
    hal::PoseEstimate e;
    while (sink->pop(&e)) {
      StepRecord r;
      r.step = static_cast<std::uint32_t>(out->steps.size());
      r.estimate = e;
      if (e.scan_id < info.size()) {
        const FrameInfo& fi = info[e.scan_id];
        r.t = fi.t;
        r.has_truth = fi.has_truth;
        r.truth = fi.truth;
        r.travelled_m = fi.travelled_m;
        r.kidnapped = fi.kidnapped;
        r.in_unknown = fi.in_unknown;
      }
      r.has_pose = estimate_has_pose(e);
      if (r.has_truth && r.has_pose) {
        r.err_m = std::hypot(e.x - r.truth.x, e.y - r.truth.y);
        r.err_deg = std::fabs(fw::wrap_angle(static_cast<double>(e.theta) - r.truth.theta)) * kRadToDeg;
      }
      const hal::Odometry& o = loop->last_odometry();
      r.odom = fw::Se2d(o.x, o.y, o.theta);
      r.step_ms = static_cast<double>(loop->last_step_ns()) * 1e-6;
      // Status changes worth a line of their own: becoming sure (or faulty, or outside the map)
      // and losing it; searching <-> ambiguous flapping stays in the progress line.
      const auto notable = [](hal::LocalizationStatus st) {
        return st == hal::LocalizationStatus::kLocalized || st == hal::LocalizationStatus::kOutsideMap ||
               st == hal::LocalizationStatus::kFault;
      };
      if (e.status != last_status && cfg.progress && (notable(e.status) || notable(last_status))) {
        std::fprintf(stderr, "%sstep %u (t=%.1f s, %.1f m): %s -> %s at (%.2f, %.2f, %.1f deg)", tty ? "\r\033[K" : "",
                     r.step, r.t, r.travelled_m, hal::status_name(last_status), hal::status_name(e.status), e.x, e.y,
                     e.theta * kRadToDeg);
        if (!r.has_pose) std::fprintf(stderr, " (no pose)");
        if (r.has_truth) std::fprintf(stderr, "; truth (%.2f, %.2f)", r.truth.x, r.truth.y);
        if (r.has_truth && r.has_pose) std::fprintf(stderr, ", error %.2f m", r.err_m);
        if (e.protection_xy_m > 0) {
          std::fprintf(stderr, ", PL %.2f m / %.1f deg", e.protection_xy_m, e.protection_theta_rad * kRadToDeg);
        }
        std::fprintf(stderr, "\n");
      }
      last_status = e.status;
      out->steps.push_back(r);
      if (hooks.hypotheses) {
        step_hyps.clear();
        hooks.hypotheses(&step_hyps);
        if (!step_hyps.empty()) {
          out->last_hypotheses = step_hyps;
          out->last_hypotheses_step = r.step;
          if (hyp_csv != nullptr) {
            for (const HypothesisPoint& h : step_hyps) {
              std::fprintf(hyp_csv, "%u,%.4f,%.4f,%.5f,%.5f\n", r.step, h.x, h.y, h.theta, h.weight);
            }
          }
        }
      }
    }
  };

  Frame frame;
  SyntheticFrame sframe;
  double t_first = 0;
  // Whether a step's truth lies in the unknown area is known for a world whose unknown area was
  // erased from the map (availability leaves those steps out: there is nothing to localize on).
  const bool unknown_known = !cfg.world.empty() && cfg.raster.erase_unknown_areas && !world.unknown_areas.empty();
  for (std::size_t k = 0; k < total; ++k) {
    if (!cfg.world.empty()) {
      if (!synthetic.next(&sframe)) break;
      frame.index = sframe.index;
      frame.t = sframe.t;
      frame.has_truth = true;
      frame.truth = sframe.truth;
      frame.travelled_m = sframe.travelled_m;
      frame.kidnapped = sframe.kidnapped;
      frame.odometry.swap(sframe.odometry);
      frame.scan = sframe.scan;
    } else {
      frame = std::move(log_frames[k]);
    }
    if (k == 0) t_first = frame.t;
    if (cfg.paced) {
      const auto due = wall_start + std::chrono::duration_cast<std::chrono::steady_clock::duration>(
                                        std::chrono::duration<double>((frame.t - t_first) / cfg.pace_speed));
      std::this_thread::sleep_until(due);
    }
    if (info.size() <= frame.scan.scan_id) info.resize(frame.scan.scan_id + 1);
    bool in_unknown = false;
    if (unknown_known && frame.has_truth) {
      for (const Box& b : world.unknown_areas) in_unknown |= b.contains(Vec2(frame.truth.x, frame.truth.y));
    }
    info[frame.scan.scan_id] = {frame.t, frame.has_truth, frame.truth, frame.travelled_m, frame.kidnapped, in_unknown};
    // With --transport can|sick (or --sensor-resolution can|sick) the simulated sensors report what
    // the wire carries, so the driver path and the direct one see the same values.
    for (hal::Odometry& o : frame.odometry) transport->to_sensor_resolution(&o);
    transport->to_sensor_resolution(&frame.scan);
    for (const hal::Odometry& o : frame.odometry) {
      if (transport->carries_odometry()) {
        transport->send_odometry(o);
      } else if (!odom->push(o)) {
        ++ring_drops;
      }
    }
    if (topt.transport != Transport::kNone) {
      transport->send_scan(frame.scan);
    } else if (!laser->push(frame.scan)) {
      ++ring_drops;
    }
    if (frame.scan.timestamp_ns > clock->now_ns()) clock->set_ns(frame.scan.timestamp_ns);
    tasks->run_once();
    if (!task_ctx.status.is_ok()) ++sum.step_errors;
    drain();
    if (cfg.progress) {
      const auto now = std::chrono::steady_clock::now();
      if (now - last_progress > std::chrono::milliseconds(tty ? 200 : 5000) || k + 1 == total) {
        last_progress = now;
        const StepRecord* lr = out->steps.empty() ? nullptr : &out->steps.back();
        std::fprintf(stderr, "%s[%s %s] step %zu/%zu  t=%.1f s  %.1f m  status=%s", tty ? "\r\033[K" : "",
                     sum.source.c_str(), cfg.localizer.c_str(), k + 1, total, frame.t, frame.travelled_m,
                     lr ? hal::status_name(lr->estimate.status) : "-");
        if (lr && std::isfinite(lr->err_m)) std::fprintf(stderr, "  err=%.2f m", lr->err_m);
        if (lr) std::fprintf(stderr, "  hyps=%u  %.2f ms/step", lr->estimate.hypothesis_count, lr->step_ms);
        if (!tty) std::fprintf(stderr, "\n");
      }
    }
  }
  // Flush a scan still waiting for odometry.
  if (loop->scan_pending()) {
    clock->advance_ns(lo.odom_wait_ns + 1);
    tasks->run_once();
    drain();
  }
  if (hyp_csv != nullptr && std::fclose(hyp_csv) != 0) {
    *err = "error writing '" + cfg.out_dir + "/hypotheses.csv'";
    return false;
  }
  if (cfg.progress && tty) std::fprintf(stderr, "\n");
  const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();

  // ---- summary ----
  sum.steps = out->steps.size();
  sum.wall_s = wall_s;
  sum.scans_per_s = wall_s > 0 ? static_cast<double>(sum.steps) / wall_s : 0;
  sum.scans_dropped = loop->health().dropped_scans;
  sum.ring_drops = ring_drops + laser->stats().dropped + odom->stats().dropped;
  sum.odom_rejected = loop->counters().odom_rejected;
  sum.scans_held = loop->counters().scans_held;
  sum.deadline_misses = loop->health().deadline_misses;
  sum.transport_stats = transport->stats();
  summarize_steps(out->steps, &sum);
  if (cfg.progress) {
    if (sum.first_localized_step < 0) {
      std::fprintf(stderr, "not localized in %zu steps (%.1f m); localizer '%s'\n", sum.steps, sum.path_length_m,
                   cfg.localizer.c_str());
    }
    if (cfg.wall_timing) {
      for (const fw::PerfCounter* pc : {&loop->perf_poll(), &loop->perf_pair(), &loop->perf_step(),
                                        &loop->perf_publish(), &loop->perf_total()}) {
        pc->print(stderr);
      }
    }
    const std::size_t shown = std::min<std::size_t>(logs->size(), 10);
    for (std::size_t i = logs->size() - shown; i < logs->size(); ++i) {
      std::fprintf(stderr, "firmware: %s\n", logs->line(i).text);
    }
    if (logs->total() > shown) {
      std::fprintf(stderr, "firmware: (%llu warnings/errors in total, last %zu shown)\n",
                   static_cast<unsigned long long>(logs->total()), shown);
    }
    std::fputs(summary_story(sum).c_str(), stderr);
  }

  // ---- outputs ----
  if (!cfg.out_dir.empty()) {
    if (!write_steps_csv(cfg.out_dir + "/steps.csv", out->steps, err)) return false;
    if (!write_summary_json(cfg.out_dir + "/summary.json", sum, err)) return false;
    if (have_grid && !write_ros_map(cfg.out_dir + "/map.yaml", grid_to_ros_map(grid, "map.pgm"), err)) return false;
    if (cfg.pictures && !write_pictures(cfg, *out, cfg.world.empty() ? nullptr : &synthetic.world(),
                                        have_grid ? &grid : nullptr, err)) {
      return false;
    }
  }
  return true;
}

}  // namespace sim
