// The simulator driver behind mml-sim: feeds a synthetic world or a CARMEN log through the hal/sim
// backend into the firmware's LocalizationLoop in lockstep (stepped clock set to each scan's time)
// or paced at the data's real time, and records per step: estimate, status, ground truth, error,
// timing. Writes steps.csv, summary.json, run.svg, run.png (and the map as map.yaml/.pgm).
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "firmware/base/se2.h"
#include "hal/msg/pose_estimate.h"
#include "sim/cli/localizer_factory.h"
#include "sim/world/raster.h"
#include "sim/world/synthetic_run.h"

namespace sim {

struct SimConfig {
  std::string world;           // built-in world name, or
  const World* custom_world = nullptr;  // a world built in code (tests: a unique room, a symmetric corridor), or
  std::string dataset;         // a dataset of ../shared/data (log, reference and cached global map), or
  std::string log_path;        // CARMEN log (plain or .gz)
  std::string reference_path;  // *.corrected-poses.txt for a log (ground truth)
  std::string map_yaml;        // ROS map for a log replay (optional)
  // Empty: "mml-track" when it is registered (the product, firmware/app/system.h), else "odom".
  std::string localizer;
  std::map<std::string, std::string> localizer_options;
  std::uint64_t seed = 1;
  std::size_t steps = 0;       // 0 = all
  bool paced = false;          // sleep to the data's real time (× speed)
  double pace_speed = 1.0;
  bool wall_timing = true;     // false: step times are not measured (CSV byte-identical across runs)
  bool progress = true;        // \r-updated progress line on stderr
  bool pictures = true;
  int threads = 1;
  double deadline_ms = 0;      // Localizer::step longer than this counts a deadline miss (0 = off)
  std::string out_dir;         // empty: no files
  SyntheticRunOptions synthetic;
  RasterOptions raster;
};

struct StepRecord {
  std::uint32_t step = 0;
  double t = 0;  // s since the first scan
  hal::PoseEstimate estimate;
  bool has_truth = false;
  fw::Se2d truth;
  double err_m = 0, err_deg = 0;
  double travelled_m = 0;
  bool kidnapped = false;  // the robot was carried away just before this scan
  fw::Se2d odom;
  double step_ms = 0;
};

struct SimSummary {
  std::string source, localizer;
  std::size_t steps = 0, scans_dropped = 0;
  long first_localized_step = -1;
  long kidnap_step = -1;
  // After a kidnapping: first step localized again (−1 = never).
  long relocalized_step = -1;
  double first_localized_t = 0, first_localized_travelled_m = 0, first_localized_err_m = 0;
  std::size_t localized_steps = 0, wrong_localized_steps = 0;  // wrong: error ≥ 0.5 m or ≥ 20° while localized
  double mean_err_localized_m = 0, max_err_localized_m = 0, final_err_m = 0;
  std::size_t status_counts[5] = {};
  double step_ms_mean = 0, step_ms_p50 = 0, step_ms_p99 = 0, step_ms_max = 0;
  // wall_s / scans_per_s: the run through hal/sim and the localizer (log parsing and map building
  // excluded: load_s).
  double path_length_m = 0, wall_s = 0, scans_per_s = 0, load_s = 0;
  std::uint64_t odom_rejected = 0, scans_held = 0, ring_drops = 0, step_errors = 0;
  std::size_t scans_restamped = 0;
  std::uint64_t deadline_misses = 0;  // log scans whose time stamp stepped back (re-stamped, see sim_runner.cpp)
};

struct SimResult {
  std::vector<StepRecord> steps;
  SimSummary summary;
  // Hypotheses of the last step that had any (from LocalizerHooks::hypotheses) and its step.
  std::vector<HypothesisPoint> last_hypotheses;
  long last_hypotheses_step = -1;
};

// Runs the whole simulation; false with *err naming the bad input (world, log, map, localizer).
bool run_simulation(const SimConfig& cfg, SimResult* out, std::string* err);

// Output writers (also used by tests).
bool write_steps_csv(const std::string& path, const std::vector<StepRecord>& steps, std::string* err);
bool write_summary_json(const std::string& path, const SimSummary& s, std::string* err);

}  // namespace sim
