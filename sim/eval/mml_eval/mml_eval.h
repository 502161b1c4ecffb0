// MML evaluation on the real logs (issue 6 §5): kidnapped starts drawn from a seed, MML / MCL /
// hand-off side by side, per-step status and error against the reference trajectory, per-trial
// metres to the first `localized`, success / failure, step times; unknown-area runs on a map with
// a region erased. Reports: flat JSON (BenchJson), markdown table, SVG plots.
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/runtime/localizer.h"
#include "hal/msg/pose_estimate.h"
#include "sim/io/synthetic_odometry.h"
#include "sim/io/carmen_log.h"
#include "sim/eval/mml_eval/reference_map_check.h"
#include "sim/io/relations.h"
#include "sim/io/ros_map.h"

namespace sim::mmleval {

struct LoadedDataset {
  std::string name;        // "intel", "mit-killian", ...
  std::string key;         // JSON key form: "intel", "mit_killian", ...
  CarmenLog log;
  std::vector<fw::Se2d> reference;  // pose at every scan (map frame)
  std::vector<fw::Se2d> odometry;   // odometry pose fed to the localizer at every scan
  std::vector<double> travelled;    // cumulative odometry path length at every scan (m)
  RosMap ros;
  OccupancyGrid grid;
  std::vector<std::uint8_t> image;  // compiled map image
  std::unique_ptr<fw::StartupArena> arena;
  fw::GlobalMap map;
  double success_bound_m = 0.5;     // 1 m for mit-killian
  double success_bound_rad = 20.0 * 3.14159265358979 / 180.0;
  std::string reference_note;
  // Reference quality (check_reference_against_relations): 1 = the reference at this scan disagrees
  // with a benchmark relation touching it; such scans are excluded from every error-based metric.
  // Empty = all reliable.
  std::vector<std::uint8_t> ref_unreliable;
  std::size_t ref_excluded_scans = 0;
  std::string ref_check_note;       // "checked against N relations: M scans excluded", or why not
  bool synthetic_odometry = false;  // odometry synthesised from the reference (synthesize_odometry)
  bool reference_unreliable(std::size_t scan) const { return scan < ref_unreliable.size() && ref_unreliable[scan]; }
  // Reference checked against the map (reference_map_check.h), lazily at the scans where a
  // `localized` error exceeds the bounds or the protection level; cached per scan (trials run one
  // after the other).
  mutable std::map<std::size_t, ReferenceMapFit> ref_map_checks;
  // The reference's own error bound at every scan (closure residual weights, reference_trajectory.h);
  // empty = exact reference (corrected logs).
  std::vector<double> ref_bound_m, ref_bound_rad;
  double reference_bound_m(std::size_t scan) const { return scan < ref_bound_m.size() ? ref_bound_m[scan] : 0.0; }
  double reference_bound_rad(std::size_t scan) const { return scan < ref_bound_rad.size() ? ref_bound_rad[scan] : 0.0; }
  const ReferenceMapFit& reference_map_fit(std::size_t scan) const;
};

// Loads log, reference and the cached global map (built on first use under build/maps).
// fr101 / fr-campus (only corrected logs exist): log = corrected log, reference = its poses,
// odometry synthesised (synthesize_odometry, seed 1). Datasets with relations matching the log are
// checked with check_reference_against_relations (defaults).
bool load_dataset(const std::string& name, LoadedDataset* out, std::string* err);

// Any building by path (mml-eval --log/--map/--reference): `log` = CARMEN log (.gz ok), `map_yaml`
// = ROS map (compiled to a map image here), `reference` = "flaser_index ipc logger x y theta" rows
// (like intel.corrected-poses.txt) or a CARMEN log with one scan per scan of `log` (its laser
// poses), `relations` optional (benchmark relations with the log's ipc timestamps),
// `synthetic_odometry`: feed odometry synthesised from the reference instead of the log's.
// Errors name the file and the problem.
struct DatasetFiles {
  std::string name = "custom";
  std::string log, map_yaml, reference, relations;
  bool synthetic_odometry = false;
  std::uint64_t odometry_seed = 1;
};
bool load_dataset_files(const DatasetFiles& files, LoadedDataset* out, std::string* err);

// Wheel odometry synthesised from reference increments (for logs without raw odometry): the model of
// sim/io/synthetic_odometry.h (also behind `mml-carmen synth-odom`).
using sim::synthesize_odometry;

// Reference-quality rule (README "Reference quality"): every benchmark relation with
// |t2 − t1| ≤ max_dt_s whose two scans are in the log is evaluated on the reference; if it
// disagrees by more than tol_m (translation) or tol_rad (rotation), every scan from t1's to t2's
// (inclusive, log order) is marked unreliable. Fills ds->ref_unreliable / ref_excluded_scans /
// ref_check_note. Returns the number of relations checked.
std::size_t check_reference_against_relations(LoadedDataset* ds, const std::vector<Relation>& relations,
                                              double max_dt_s = 3.0, double tol_m = 0.10,
                                              double tol_rad = 3.14159265358979 / 180.0);
// Replaces the map by a copy with the axis-aligned box erased (cells → unknown); the image and
// GlobalMap are rebuilt.
bool erase_region(LoadedDataset* ds, double x0, double y0, double x1, double y1, std::string* err);

// The unknown-area experiment, one definition for mml-eval and bench_localize: loads `name`, erases
// an 8 × 8 m box around a scan drawn from `seed` in the middle half of the log (region = x0 y0 x1
// y1) and returns `trials` starts 8, 18, 28 … m of travel before it.
struct UnknownArea {
  LoadedDataset ds;                  // the log with its map erased in `region`
  double region[4] = {0, 0, 0, 0};   // x0 y0 x1 y1
  std::vector<std::size_t> starts;
};
bool prepare_unknown_area(const std::string& name, std::uint64_t seed, std::size_t trials, UnknownArea* out,
                          std::string* err);

struct TrialOptions {
  std::size_t max_steps = 150;      // localizer steps per trial
  double max_metres = 1e9;          // stop when the robot travelled this far
  double min_move_m = 0.15;         // a scan is a step once odometry moved this far …
  double min_turn_rad = 0.15;       // … or turned this much (same rule for every system)
  bool stop_after_localized = false;  // stop once localized for `settle_steps` steps
  std::size_t settle_steps = 20;
  // max_steps == 0: no step cap (to the end of the log, or max_metres).
  // Kidnap: after `kidnap_at_step` steps (0 = none) the scan index jumps to `kidnap_to_scan` and the
  // run continues there for at most `kidnap_steps_after` steps (0 = to the end / max_steps). The
  // odometry fed to the localizer stays continuous: the new segment's odometry is shifted so that
  // its first scan has exactly the last fed odometry pose (the wheels do not see the carrying).
  std::size_t kidnap_at_step = 0;
  std::size_t kidnap_to_scan = 0;
  std::size_t kidnap_steps_after = 0;
  // Kidnap this many steps after the first `localized` instead (0 = off); kidnap_at_step then is
  // the latest step at which the kidnap happens anyway.
  std::size_t kidnap_after_fix_steps = 0;
  // Picks the target scan given the scan before the jump (overrides kidnap_to_scan when set).
  std::function<std::size_t(std::size_t from_scan)> kidnap_target;
};

struct StepLog {
  std::size_t scan = 0;
  double travelled = 0;  // since the trial start
  hal::LocalizationStatus status = hal::LocalizationStatus::kSearching;
  hal::LocalizationMode mode = hal::LocalizationMode::kGlobal;
  // Error against the reference; NaN when the localizer gave no pose (searching / fault: the
  // published pose is a placeholder and must never be compared).
  double err_m = 0, err_rad = 0;
  bool has_pose = true;
  bool ref_ok = true;       // reference reliable at this scan (check_reference_against_relations)
  bool ref_map_contradicted = false;  // the map contradicts the reference here (ref_ok false too)
  bool ref_within_bound = false;      // error beyond a limit by less than the reference's own bound (ref_ok false)
  // Per criterion, on a step kept (ref_ok) because the other criterion is judged beyond: this one is
  // not (within the reference's bound, or cleared by the map's pose; reference_map_check.h).
  bool integrity_cleared = false, pl_cleared = false;
  double map_err_m = 0, map_err_rad = 0;  // error against the map's pose (when the map check ran; else NaN)
  double ref_bound_m = 0, ref_bound_rad = 0;  // the reference's own bound at this scan
  float pl_xy = 0, pl_theta = 0;  // published protection level (0 = none)
  std::uint16_t unsupported_steps = 0;
  hal::StatusReason reason = hal::StatusReason::kNone;  // why not `localized` (published with the pose)
  std::size_t segment = 0;  // 1 after a kidnap
  double step_ms = 0;
  // Of step_ms, the global step run inline on this scan (mml-track's GlobalContext, timed by its
  // clock; 0 for other localizers): what mmlfw runs on the global context, not the sensor context.
  double global_ms = 0;
  fw::Se2d estimate, truth;
  fw::Se2d odom;            // odometry fed to the localizer
  bool in_region = false;  // inside the erased region (unknown-area runs)
  // The reference's scan is in an unmapped area (unmapped_scan.h; a reliable reference only): left
  // out of the availability like the erased region.
  bool ref_unmapped = false;
  // The map explains less than half of the scan at the reference (unmapped_scan.h,
  // reference_off_map): shown beside the availability, never used to leave a step out.
  bool ref_off_map = false;
  std::size_t matched_points = 0;  // MML: local map points handed to pRANSAM (0: not matched / not MML)
};

// A kept step's judged errors: beyond the integrity bounds / its protection level, unless the
// reference checks cleared that criterion.
inline bool integrity_beyond(const StepLog& s, double bound_m, double bound_rad) {
  return !s.integrity_cleared && (s.err_m > bound_m || s.err_rad > bound_rad);
}
inline bool pl_xy_beyond(const StepLog& s) { return !s.pl_cleared && s.pl_xy > 0.0f && s.err_m > s.pl_xy; }
inline bool pl_theta_beyond(const StepLog& s) { return !s.pl_cleared && s.pl_theta > 0.0f && s.err_rad > s.pl_theta; }

struct TrialResult {
  std::size_t start = 0;
  std::vector<StepLog> steps;
  bool localized = false;
  std::size_t steps_to_localize = 0;
  double metres_to_localize = 0;
  bool success = false;  // localized and the first localized estimate within the bound
  bool failure = false;  // any localized estimate beyond the bound
  double mean_err_localized = 0;
  std::string error;     // a localizer error that ended the trial
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);
  std::size_t kidnap_step = kNone;  // index in `steps` of the first step after the kidnap jump
  std::size_t kidnap_scan_from = 0;  // last scan before the jump
  double kidnap_travelled = 0;       // `travelled` at the jump
  bool whole_log = false;            // a whole-log run (label only)
};

// The product metrics of one trial (README "Metrics"). Bounds: position `bound_m` (dataset bound:
// 0.5 m, 1 m at mit-killian), heading `bound_rad` (5°).
struct MetricBounds {
  double bound_m = 0.5;
  double bound_rad = 5.0 * 3.14159265358979 / 180.0;
  std::size_t fix_within_steps = 200;    // first-fix success window
  std::size_t refix_within_steps = 200;  // kidnap re-fix window
};
struct TrialMetrics {
  std::size_t steps = 0;
  bool first_fix = false;          // some `localized` within fix_within_steps
  bool first_fix_success = false;  // … and correct (first such step with a reliable reference)
  std::size_t first_fix_index = TrialResult::kNone;  // index in steps
  double m_to_fix = 0;             // NaN when no first fix
  std::size_t avail_steps = 0, avail_localized = 0;  // after the first fix, before a kidnap, outside the erased region
  // Steps after the first fix left out of avail_steps as unmapped (ref_unmapped), and how many of
  // them were `localized` (shown beside the availability: never left out silently).
  std::size_t unmapped_steps = 0, unmapped_localized = 0;
  std::size_t off_map_steps = 0, off_map_localized = 0;  // availability steps with ref_off_map, and `localized`
  std::size_t unavailable_by_reason[hal::kStatusReasonCount] = {};  // avail_steps not `localized`, by reason
  std::size_t localized_steps = 0;      // `localized` with a reliable reference (error-checked)
  std::size_t integrity_failures = 0;   // of those: error beyond the bounds
  std::size_t pl_steps = 0, pl_exceed = 0;
  std::size_t pl_exceed_xy = 0, pl_exceed_theta = 0;  // which bound was exceeded (both may count)
  std::size_t excluded_ref_steps = 0;   // `localized` steps skipped: reference unreliable (relations or map)
  std::size_t excluded_map_steps = 0;   // … of those: the map contradicts the reference (reference_map_check.h)
  std::size_t excluded_bound_steps = 0; // … of those: beyond a limit by less than the reference's own bound
  // Judged against the log reference alone (no map check, no reference bound): shown beside the
  // judged figures so the exclusions can be weighed.
  std::size_t integrity_failures_raw = 0, pl_steps_raw = 0, pl_exceed_raw = 0;
  std::vector<double> track_err;        // localized, tracking mode, reliable reference
  bool kidnapped = false;
  bool kidnap_detected = false;         // status left `localized` after the kidnap
  double kidnap_delay_steps = 0;        // steps from the kidnap until not `localized` (NaN: never)
  bool kidnap_refix = false;            // correct `localized` within refix_within_steps after the kidnap
  double refix_m = 0;                   // metres from the kidnap to it (NaN: none)
  std::size_t kidnap_integrity_failures = 0;  // wrong `localized` steps from the kidnap on
};
TrialMetrics trial_metrics(const TrialResult& t, const MetricBounds& b);

// Drives `loc` (reset first) from scan `start` on. `region` (optional) marks steps inside it.
// `matched_points` (optional) reports the local map points matched in the last step (MML).
TrialResult run_trial(fw::Localizer& loc, const LoadedDataset& ds, std::size_t start, const TrialOptions& opt,
                      const double* region = nullptr, const std::function<std::size_t()>& matched_points = nullptr);

// Kidnapped starts from a seed: uniform over scans with enough log left for the trial.
std::vector<std::size_t> draw_starts(const LoadedDataset& ds, std::size_t count, std::uint64_t seed,
                                     const TrialOptions& opt);

struct SystemSummary {
  std::string dataset, system;
  std::size_t trials = 0, localized = 0, successes = 0, failures = 0;
  double success_rate = 0, failure_rate = 0;
  double m_to_localize_median = 0;  // over localized trials (NaN if none)
  double steps_to_localize_median = 0;
  double mean_err_m = 0;            // over localized steps of all trials
  double step_ms_p50 = 0, step_ms_p99 = 0, step_ms_mean = 0;
  double memory_mib = 0;
  double outside_map_in_region = 0;  // unknown-area runs: fraction of in-region steps reporting outside-map
  // Steps published `outside-map`, and of them those neither in the erased region nor unmapped at the
  // reference (unmapped_scan.h): an `outside-map` the map contradicts.
  std::size_t outside_map_steps = 0, outside_map_false_steps = 0;
  double tracking_err_median_m = 0;  // steps in tracking mode (hand-off)
  double tracking_step_ms_p50 = 0, tracking_step_ms_p99 = 0;
  double matched_points_mean = 0;    // MML: mean local map points matched per matching step (NaN: none)
  // Product metrics (trial_metrics pooled over the trials; NaN where nothing to measure).
  std::size_t first_fixes = 0, first_fix_successes = 0;
  double first_fix_success = 0;      // share of trials
  // Median metres to the first correct fix over all trials; a trial with a wrong or no first fix
  // within the window counts as never fixed (+∞); NaN when half or more never fixed.
  double m_to_fix_median = 0;
  double availability = 0;           // pooled avail_localized / avail_steps
  std::size_t avail_steps = 0;
  std::size_t unmapped_steps = 0, unmapped_localized = 0;  // pooled TrialMetrics::unmapped_*
  std::size_t off_map_steps = 0, off_map_localized = 0;   // pooled TrialMetrics::off_map_*
  double availability_with_unmapped = 0;  // the unmapped steps counted in: (avail + unmapped localized) / (both steps)
  std::size_t unavailable_by_reason[hal::kStatusReasonCount] = {};  // pooled: where the availability went
  std::size_t localized_checked = 0, integrity_failures = 0, excluded_ref_steps = 0, excluded_map_steps = 0,
              excluded_bound_steps = 0, integrity_failures_raw = 0, pl_steps_raw = 0, pl_exceed_raw = 0;
  double integrity_failure_rate = 0;  // per error-checked localized step
  std::size_t pl_steps = 0, pl_exceed = 0, pl_exceed_xy = 0, pl_exceed_theta = 0;
  double pl_exceed_rate = 0;
  double track_err_median_m = 0, track_err_p95_m = 0;
  std::size_t kidnaps = 0, kidnaps_detected = 0, kidnap_refixes = 0, kidnap_integrity_failures = 0;
  // Medians with a kidnap never detected / never re-fixed counted as +∞ (censored_median).
  double kidnap_delay_median = 0, kidnap_refix_m_median = 0, kidnap_refix_success = 0;
};

// Median of a sample where +∞ stands for "never" (a censored observation); NaN when empty or when
// the median itself is "never".
double censored_median(std::vector<double> v);

SystemSummary summarize(const std::string& dataset, const std::string& system, const std::vector<TrialResult>& trials,
                        double memory_mib, const MetricBounds& bounds = MetricBounds());

// Percentile of a copy (p in [0, 100]); NaN for empty input.
double percentile(std::vector<double> v, double p);

// Reports.
std::string markdown_table(const std::vector<SystemSummary>& rows);
// The product metrics (first fix, availability, integrity, PL, tracking error, kidnap).
std::string product_markdown_table(const std::vector<SystemSummary>& rows);
// Error / status over metres travelled, one polyline per trial (Figs. 5.7–5.22 style).
bool write_error_plot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials,
                      double bound_m, std::string* err);
// Map with true path, estimates (coloured by status) and the start markers of the trials.
bool write_map_plot(const std::string& path_svg, const std::string& path_png, const LoadedDataset& ds,
                    const std::string& title, const std::vector<TrialResult>& trials, const double* region,
                    std::string* err);

}  // namespace sim::mmleval
