// MML evaluation on the real logs (issue 6 §5): kidnapped starts drawn from a seed, MML / MCL /
// hand-off side by side, per-step status and error against the reference trajectory, per-trial
// metres to the first `localized`, success / failure, step times; unknown-area runs on a map with
// a region erased. Reports: flat JSON (BenchJson), markdown table, SVG plots.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/se2.h"
#include "firmware/map/global_map.h"
#include "firmware/runtime/localizer.h"
#include "hal/msg/pose_estimate.h"
#include "sim/io/carmen_log.h"
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
};

// Loads log, reference and the cached global map (built on first use under build/maps).
bool load_dataset(const std::string& name, LoadedDataset* out, std::string* err);
// Replaces the map by a copy with the axis-aligned box erased (cells → unknown); the image and
// GlobalMap are rebuilt.
bool erase_region(LoadedDataset* ds, double x0, double y0, double x1, double y1, std::string* err);

struct TrialOptions {
  std::size_t max_steps = 150;      // localizer steps per trial
  double max_metres = 1e9;          // stop when the robot travelled this far
  double min_move_m = 0.15;         // a scan is a step once odometry moved this far …
  double min_turn_rad = 0.15;       // … or turned this much (same rule for every system)
  bool stop_after_localized = false;  // stop once localized for `settle_steps` steps
  std::size_t settle_steps = 20;
};

struct StepLog {
  std::size_t scan = 0;
  double travelled = 0;  // since the trial start
  hal::LocalizationStatus status = hal::LocalizationStatus::kSearching;
  hal::LocalizationMode mode = hal::LocalizationMode::kGlobal;
  double err_m = 0, err_rad = 0;
  double step_ms = 0;
  fw::Se2d estimate, truth;
  bool in_region = false;  // inside the erased region (unknown-area runs)
  std::size_t matched_points = 0;  // MML: local map points handed to pRANSAM (0: not matched / not MML)
};

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
};

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
  double tracking_err_median_m = 0;  // steps in tracking mode (hand-off)
  double tracking_step_ms_p50 = 0, tracking_step_ms_p99 = 0;
  double matched_points_mean = 0;    // MML: mean local map points matched per matching step (NaN: none)
};

SystemSummary summarize(const std::string& dataset, const std::string& system, const std::vector<TrialResult>& trials,
                        double memory_mib);

// Percentile of a copy (p in [0, 100]); NaN for empty input.
double percentile(std::vector<double> v, double p);

// Reports.
std::string markdown_table(const std::vector<SystemSummary>& rows);
// Error / status over metres travelled, one polyline per trial (Figs. 5.7–5.22 style).
bool write_error_plot(const std::string& path, const std::string& title, const std::vector<TrialResult>& trials,
                      double bound_m, std::string* err);
// Map with true path, estimates (coloured by status) and the start markers of the trials.
bool write_map_plot(const std::string& path_svg, const std::string& path_png, const LoadedDataset& ds,
                    const std::string& title, const std::vector<TrialResult>& trials, const double* region,
                    std::string* err);

}  // namespace sim::mmleval
