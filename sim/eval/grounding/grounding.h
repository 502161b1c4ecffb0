// The grounding measurement of the world generator (issue 55, item 6): odometry error per metre and
// per radian, and scan-to-map residuals, measured with ONE estimator on the real logs of
// ../shared/data (against their corrected reference) and on simulated runs of every odometry and
// sensor profile (against their exact truth), with a verdict per profile: the real logs it
// resembles, or "no real log resembles it". README.md of this folder: definitions and caveats.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "sim/common/bench_json.h"
#include "sim/eval/grounding/odometry_windows.h"
#include "sim/eval/grounding/scan_residuals.h"
#include "sim/world/laser_model.h"
#include "sim/world/odometry_model.h"

namespace sim::ground {

struct GroundOptions {
  std::vector<std::string> logs;      // real datasets to measure; empty = all
  bool real = true, simulated = true;
  double short_window_m = 1.0, long_window_m = 5.0;
  double long_stride_m = 1.0;         // 5 m windows start every metre (overlapping)
  std::size_t residual_scans = 150;   // scans sampled evenly per log / per sensor profile
  int sim_seeds = 5;                  // synthetic runs per odometry profile
  std::string world = "large-office";
  ResidualOptions residual;
  bool progress = false;
  // The profiles also seen through a reference with this iid per-pose error (σ per axis, m / deg;
  // 0 = not done). run_grounding derives it from fr079's reference at rest (rest_noise_from).
  double ref_sigma_m = 0, ref_sigma_deg = 0;
};

struct OdometryMeasure {
  std::string name;      // dataset or profile
  bool is_log = true;
  bool measured = false;
  std::string note;      // why not measured, or a caveat
  std::size_t pairs = 0; // pose pairs (instants with a measured reference)
  double path_m = 0;     // the reference's path length over them
  OdometryErrorSummary short_w, long_w;
  // The reference's own motion where the odometry says the robot stood still (consecutive pairs):
  // the reference's noise floor (m, deg); NaN when no such pair.
  std::size_t rest_pairs = 0;
  double rest_m_p95 = 0, rest_deg_p95 = 0;
  // Profiles: the 5 m windows against the truth plus the reference-like noise of
  // GroundOptions::ref_sigma_* (measured only when that is > 0).
  bool through_ref = false;
  OdometryErrorSummary long_w_ref;
};

struct ResidualMeasure {
  std::string name;
  bool is_log = true;
  bool measured = false;
  std::string note;
  ResidualSummary s;
};

struct Verdict {
  std::string profile;
  bool is_odometry = true;
  std::vector<std::string> resembles;  // empty: no real log resembles it
  bool through_ref = false;
  std::vector<std::string> resembles_through_ref;  // the same with the profile seen through a SLAM-like reference
};

struct GroundReport {
  bool data_present = false;
  std::string data_dir;
  std::vector<OdometryMeasure> odometry;   // logs first, then profiles
  std::vector<ResidualMeasure> residuals;  // logs first, then sensor profiles
  std::vector<Verdict> verdicts;
  bool profiles_available = false;         // odometry_profiles() / sensor_profiles() linked in
  bool sensor_profiles_available = false;
  double ref_sigma_m = 0, ref_sigma_deg = 0;  // the reference-like noise the profiles were also seen through
};

// Real datasets measured for odometry (raw odometry + a reference) and for residuals (a global map).
const std::vector<std::string>& odometry_datasets();
const std::vector<std::string>& residual_datasets();

// One real log. False with *err when its files are missing or unreadable.
bool measure_log_odometry(const std::string& dataset, const GroundOptions& opt, OdometryMeasure* out, std::string* err);
bool measure_log_residuals(const std::string& dataset, const GroundOptions& opt, ResidualMeasure* out,
                           std::string* err);
// One simulated profile: synthetic runs in opt.world (seeds 1..opt.sim_seeds).
bool measure_profile_odometry(const std::string& name, const OdometryNoiseOptions& wheels, const GroundOptions& opt,
                              OdometryMeasure* out, std::string* err);
bool measure_sensor_residuals(const std::string& name, const LaserModelOptions& laser, const GroundOptions& opt,
                              ResidualMeasure* out, std::string* err);

// The pose pairs' windows summarised (the estimator as used for logs and profiles alike).
void summarize_pairs(const std::vector<fw::Se2d>& odom, const std::vector<fw::Se2d>& ref, const GroundOptions& opt,
                     OdometryMeasure* out);

// The per-pose reference error (σ per axis, m and deg) implied by a reference's motion at rest: the
// motion between two poses at rest is the difference of two independent errors (σ√2 per axis); its
// p95 is 2.45 σ√2 in the plane (Rayleigh) and 1.96 σ√2 in heading.
void rest_noise_from(const OdometryMeasure& log, double* sigma_m, double* sigma_deg);

// The verdict rule (fixed before any figure was seen): a profile resembles a log when, for both the
// translation error per metre and the heading error per metre of the 5 m windows, the profile's
// median lies within the log's central 80 % (p10..p90) and the log's median within the profile's.
// Sensors: the profile's residual p90 lies within the log's [p50, p99] and the log's p90 within the
// profile's.
bool odometry_resembles(const OdometryErrorSummary& profile, const OdometryErrorSummary& log);
bool residuals_resemble(const ResidualSummary& profile, const ResidualSummary& log);
void add_verdicts(GroundReport* r);

// Everything: the real logs (when the data is there) and the profiles.
GroundReport run_grounding(const GroundOptions& opt);

void add_json(const GroundReport& r, BenchJson* json);
std::string markdown(const GroundReport& r);
bool write_svg(const GroundReport& r, const std::string& path, std::string* err);

}  // namespace sim::ground
