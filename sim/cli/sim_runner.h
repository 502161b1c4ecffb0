// The simulator driver behind mml-sim: feeds a synthetic world or a CARMEN log through the hal/sim
// backend into the firmware's LocalizationLoop in lockstep (stepped clock set to each scan's time)
// or paced at the data's real time, and records per step: estimate, status, ground truth, error,
// protection level, timing. Writes steps.csv, summary.json, run.svg, run.png (and the map as
// map.yaml/.pgm). Errors are computed only for steps that have a pose (estimate_has_pose): a
// `searching` step or a placeholder pose (0, 0, 0) is never scored against the truth.
#pragma once

#include <cmath>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "hal/msg/pose_estimate.h"
#include "sim/cli/localizer_factory.h"
#include "sim/cli/operator_sim.h"
#include "sim/devices/sensor_transport.h"
#include "sim/io/carmen_log.h"
#include "sim/world/map_changes.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace sim {

// --kidnap-at with a log: the replay jumps to a scan at least this far from the robot's pose.
constexpr double kLogKidnapMinJumpM = 5.0;

struct SimConfig {
  std::string world;           // built-in world name, or
  const World* custom_world = nullptr;  // a world built in code (tests: a unique room, a symmetric corridor), or
  // With custom_world: the world the map is drawn from, when it is not the world the laser sees
  // (sim/world/map_changes.h: clutter, doors, furniture moved, a wing drawn bent); nullptr = the same.
  const World* custom_map_world = nullptr;
  // With custom_map_world drawn bent: how the map draws the world. The truth is judged where the map
  // draws the robot's place (the pose a navigation stack on that map needs), not in the world's
  // frame, which no scan can observe; nullptr = the world's frame.
  const MapDrawing* map_drawing = nullptr;
  std::string dataset;         // a dataset of ../shared/data (log, reference and cached global map), or
  std::string log_path;        // CARMEN log (plain or .gz)
  std::string reference_path;  // *.corrected-poses.txt for a log (ground truth)
  std::string map_yaml;        // map for a log replay (optional): ROS map_server YAML, or a compiled map
                               // image (.mmap, "MMLFWMAP" magic; its relation table is used)
  std::size_t log_start = 0;   // --start: first scan of the log to replay (0-based)
  // --odom-noise with a log: extra Gaussian noise on every odometry increment (per scan step,
  // σ_t m on x and y, σ_r deg on θ; seeded by --seed); off when log_odom_noise is false.
  bool log_odom_noise = false;
  double log_odom_sigma_m = 0, log_odom_sigma_deg = 0;
  // --kidnap-at with a log: at this replayed scan (1-based count from --start) the replay jumps to
  // another part of the log (chosen by the seed, ≥ kLogKidnapMinJumpM away); the odometry continues
  // with the new part's increments and sees nothing. 0 = off.
  std::size_t log_kidnap_at = 0;
  std::uint64_t max_log_bytes = kDefaultMaxLogBytes;  // --max-log-mib: cap on the log, plain or inflated
  // Empty: "mml-track" when it is registered (the product, firmware/app/system.h), else "odom".
  std::string localizer;
  std::map<std::string, std::string> localizer_options;
  std::uint64_t seed = 1;
  std::size_t steps = 0;       // 0 = all
  bool paced = false;          // sleep to the data's real time (× speed)
  double pace_speed = 1.0;
  bool wall_timing = true;     // false: step times are not measured (CSV byte-identical across runs)
  // How the simulated sensors reach the firmware (--transport, --byte-fault-rate; the fault stream
  // is seeded by `seed`): sim/devices/sensor_transport.h.
  TransportOptions transport;
  bool progress = true;        // \r-updated progress line on stderr
  bool pictures = true;
  int threads = 1;             // the mml-sim CLI defaults to 2, as mml-eval (sim_args.cpp)
  double deadline_ms = 0;      // Localizer::step longer than this counts a deadline miss (0 = off)
  std::string out_dir;         // empty: no files
  SyntheticRunOptions synthetic;
  RasterOptions raster;
  // Issue 60: an operator's pose hint at a scan (--hint-at, --hint-offset / --hint-pose,
  // --hint-sigma) and the black box (--blackbox FILE, --replay-blackbox FILE), operator_sim.h.
  HintOptions hint;
  BlackBoxOptions blackbox;
};

// The placeholder a localizer leaves in a PoseEstimate before it has any pose: x = y = θ = 0 with a
// zero covariance (not finite counts as no pose either).
bool is_placeholder_pose(const hal::PoseEstimate& e);
// Whether a published estimate carries a pose to score: not `searching` or `fault`, and not the
// placeholder.
bool estimate_has_pose(const hal::PoseEstimate& e);

// Bounds of an integrity failure: a `localized` step farther off than the product's alert limits
// (firmware/track/track_options.h: 0.5 m, 5°).
constexpr double kIntegrityLimitM = 0.5, kIntegrityLimitDeg = 5.0;

struct StepRecord {
  std::uint32_t step = 0;
  double t = 0;  // s since the first scan
  hal::PoseEstimate estimate;
  bool has_pose = false;   // estimate_has_pose(estimate)
  bool has_truth = false;
  // The truth lies in the world's unknown area (erased from the map), or (log replays) its scan is
  // in an unmapped area there (reference_judge.h, mark_unmapped_steps).
  bool in_unknown = false;
  fw::Se2d truth;
  // The truth's own error bound (a log reference between corrected poses; 0 in a simulated world,
  // inf where the reference is extrapolated): an error counts against the localizer only beyond a
  // limit plus this bound, as in mml-eval's whole-log figures.
  double truth_bound_m = 0, truth_bound_deg = 0;
  // The map's own pose for this scan (cli/reference_judge.h), asked only where the step is beyond a
  // limit against the truth: map_pose_better = it explains the scan clearly better than the truth;
  // map_err_* = the estimate's error against it.
  bool map_checked = false, map_pose_better = false;
  double map_err_m = NAN, map_err_deg = NAN;
  double err_m = NAN, err_deg = NAN;  // NaN without truth or without a pose
  double travelled_m = 0;
  bool kidnapped = false;  // the robot was carried away just before this scan
  fw::Se2d odom;
  double step_ms = 0;
  // mml-track: why the track awaits MML's word (LocalizerHooks::wait_cause; a string literal).
  const char* wait_cause = "none";
};

struct SimSummary {
  std::string source, localizer;
  std::size_t steps = 0, scans_dropped = 0;
  long first_localized_step = -1;
  long kidnap_step = -1;
  // After a kidnapping: first step localized again after the detection (−1 = never).
  long relocalized_step = -1;
  double first_localized_t = 0, first_localized_travelled_m = 0, first_localized_err_m = NAN;
  double first_localized_pl_xy_m = NAN;  // its protection level (NaN: none published)
  std::size_t localized_steps = 0, wrong_localized_steps = 0;  // wrong: error ≥ 0.5 m or ≥ 20° while localized
  double mean_err_localized_m = NAN, max_err_localized_m = NAN;
  // Final error: of the last step that has a pose (final_pose_step, −1 = none; its status).
  long final_pose_step = -1;
  std::string final_pose_status;
  double final_err_m = NAN, final_err_deg = NAN;
  // Availability: share of the steps after the first fix that are `localized`. Steps whose truth
  // lies in the world's unknown area (not in the map: nothing to localize on) are left out when
  // known (built-in worlds with the unknown area erased); unknown_area_steps counts them.
  // From a kidnap until the next `localized` step the robot was carried: those steps
  // (carried_steps) are left out too, as the corpus leaves them out (silence while carried is right;
  // the re-fix has its own figures below).
  std::size_t availability_steps = 0, availability_localized = 0, unknown_area_steps = 0, carried_steps = 0;
  double availability = NAN;
  // The availability steps that were not `localized`, by the reason published with them
  // (hal::StatusReason): where the availability went.
  std::size_t unavailable_by_reason[hal::kStatusReasonCount] = {};
  // Integrity failures: `localized` steps with error > kIntegrityLimitM or > kIntegrityLimitDeg;
  // of them, those between a kidnapping and its detection.
  std::size_t integrity_failures = 0, integrity_failures_kidnap = 0;
  long first_integrity_failure_step = -1;
  // Beyond a limit against the truth, but not beyond the limit plus the truth's own error bound
  // (StepRecord::truth_bound_m), or within it against the map's pose for the scan where the map
  // explains the scan clearly better (StepRecord::map_*): not judged, counted apart.
  std::size_t integrity_not_judged = 0, pl_not_judged = 0;
  // Protection level over `localized` steps that carry one (> 0): exceedances (error beyond the PL
  // in position or heading; scored where the truth is known), median and maximum.
  std::size_t pl_steps = 0, pl_scored = 0, pl_exceeded = 0;
  double pl_exceedance_rate = NAN;
  double pl_xy_m_p50 = NAN, pl_xy_m_max = NAN, pl_theta_deg_p50 = NAN, pl_theta_deg_max = NAN;
  // Error of the `localized` steps in tracking mode (all `localized` steps for a localizer without one).
  std::size_t tracking_steps = 0;
  double tracking_err_m_p50 = NAN, tracking_err_m_p95 = NAN, tracking_err_deg_p50 = NAN, tracking_err_deg_p95 = NAN;
  // Kidnapping (--kidnap-at): the first step at or after it that is not `localized` (detection,
  // delay in steps; 0 = the kidnap scan itself), then the first `localized` step after that
  // (relocalized_step) with the metres / seconds since the kidnapping and its error.
  long kidnap_detected_step = -1, kidnap_detection_delay_steps = -1;
  double kidnap_jump_m = NAN;
  double refix_travelled_m = NAN, refix_s = NAN, refix_err_m = NAN;
  std::size_t status_counts[5] = {};
  double step_ms_mean = 0, step_ms_p50 = 0, step_ms_p99 = 0, step_ms_max = 0;
  // wall_s / scans_per_s: the run through hal/sim and the localizer (log parsing and map building
  // excluded: load_s).
  double path_length_m = 0, wall_s = 0, scans_per_s = 0, load_s = 0;
  std::uint64_t odom_rejected = 0, scans_held = 0, ring_drops = 0, step_errors = 0;
  std::size_t scans_restamped = 0;     // log scans whose time stamp stepped back (re-stamped, see log_frames.cpp)
  std::uint64_t deadline_misses = 0;  // Localizer::step longer than --deadline-ms
  // --transport can: frames through the hal/sim loopback bus, injected byte faults, and what the
  // firmware's CAN decoder made of them (scans dropped, CRC errors, lost segments, malformed frames,
  // broken odometry records).
  std::string transport = "none";
  TransportStats transport_stats;
  // Issue 60: the step at which the hint was sent (-1 = none) and the firmware's reply to it; the
  // black box written (--blackbox): frames kept, bytes of the file.
  long hint_step = -1;
  std::string hint_reply;
  std::size_t blackbox_frames = 0, blackbox_bytes = 0;
  // --transport sick: serial ring entries kept and bytes recorded (read and written).
  std::size_t blackbox_serial_chunks = 0, blackbox_serial_bytes = 0;
};

struct SimResult {
  std::vector<StepRecord> steps;
  SimSummary summary;
  // Hypotheses of the last step that had any (from LocalizerHooks::hypotheses) and its step.
  std::vector<HypothesisPoint> last_hypotheses;
  long last_hypotheses_step = -1;
};

// What mml-sim hands mml-track as odom_noise_per_step ("M,DEG", or "" for nothing): per axis, the
// simulated wheels' σ per scan step where the tracker's α model (odom_noise) gives less on the
// robot's nominal straight step (sim_runner.cpp says why). Worlds only, and not when given.
std::string wheel_noise_beyond_alpha(const SimConfig& cfg);

// Runs the whole simulation; false with *err naming the bad input (world, log, map, localizer).
bool run_simulation(const SimConfig& cfg, SimResult* out, std::string* err);
// --replay-blackbox: the map and localizer of `cfg` (the recording's --world / --dataset and
// options), the file's rx frames fed through the firmware's CanNode in lockstep (the simulation
// clock set to each frame's receive time, one loop cycle per frame); the POSE frames published
// are compared with the file's tx POSE frames. `out` holds the replay's steps.
bool replay_black_box(const SimConfig& cfg, SimResult* out, BlackBoxReplay* replay, std::string* err);

// Output writers (also used by tests).
bool write_steps_csv(const std::string& path, const std::vector<StepRecord>& steps, std::string* err);
bool write_summary_json(const std::string& path, const SimSummary& s, std::string* err);
// Summary figures of a run from its steps (also used by tests): first fix, availability, integrity,
// protection level, tracking error, kidnap detection and re-fix, final error, step times. Fills the
// fields of *s that derive from the steps; counters of the loop are left alone.
void summarize_steps(const std::vector<StepRecord>& steps, SimSummary* s);
// The one-line summary mml-sim prints last ("mml-sim summary: ...").
std::string summary_line(const SimSummary& s);
// A few lines that tell the run: fix, tracking, kidnapping, integrity.
std::string summary_story(const SimSummary& s);

}  // namespace sim
