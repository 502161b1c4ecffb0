// Product evaluation of the localizer (`mml-track`) on the real logs and on any building given by
// path: first fix, availability, integrity, protection-level exceedance, tracking error over whole
// logs, kidnaps with continuous odometry, an erased (unknown) region, reference-quality exclusion.
// Shared by `mml-eval --localize` and bench_localize (scripts/bench.sh localize). Metric
// definitions: sim/eval/mml_eval/README.md "Localizer product metrics".
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "firmware/track/track_options.h"
#include "sim/common/bench_json.h"
#include "sim/eval/mml_eval/mml_eval.h"

namespace sim::mmleval {

struct LocalizePlan {
  fw::track::TrackOptions track;  // the shipped options; --odom-noise sets the odometry noise model
  std::vector<std::string> datasets = {"intel", "fr079", "aces", "fr-clinic", "mit-killian", "fr101", "fr-campus"};
  std::vector<DatasetFiles> custom;  // buildings given by path (evaluated after `datasets`)
  std::uint64_t seed = 1;
  int threads = 2;
  int mml_config = 3;
  bool keep_support_across_contested_steps = true;  // --no-keep-contested: off (MmlOptions)
  bool keep_support_across_empty_steps = true;  // --no-keep-support: off (MmlOptions::keep_support_across_empty_steps)
  bool pool_cluster_support = true;  // --no-pool: mml-track's MML without the pooled support (mml_track_preset)
  bool unmapped_space = true;  // --no-unmapped-space: unknown inner regions count as misses (map/unmapped_space.h)
  TrialOptions step_rule;            // min_move_m / min_turn_rad (the suite's step rule)
  // Whole-log runs: kidnapped starts drawn over the first `whole_start_fraction` of the log's path,
  // each run continues to the END of the log (whole_max_steps = 0) or to that many steps.
  std::size_t whole_runs = 3;
  std::size_t whole_max_steps = 0;
  double whole_start_fraction = 0.5;
  // Shorter kidnapped-start trials for the first fix.
  std::size_t fix_trials = 10;
  std::size_t fix_steps = 200;
  // Per-dataset overrides of the trial counts (name → count), e.g. fewer runs on a slow dataset.
  std::vector<std::pair<std::string, std::size_t>> whole_runs_override, fix_trials_override;
  // MCL baseline (metres to the first fix) on the first `mcl_trials` fix-trial starts; mml-track's
  // figure on the same starts beside it (D_m_to_fix_median_mcl_starts). 10 = every fix-trial start.
  std::vector<std::string> mcl_datasets = {"intel", "fr079"};
  std::size_t mcl_trials = 10;
  std::uint32_t mcl_particles = 30000;
  // Kidnaps: `kidnap_runs` per dataset; the robot is carried `kidnap_after_fix` steps after its first
  // fix (at step kidnap_latest_step at the latest) to a random scan ≥ kidnap_min_dist_m away and the
  // run continues kidnap_steps_after steps.
  std::vector<std::string> kidnap_datasets = {"intel", "fr079", "aces", "fr-clinic", "mit-killian", "fr101", "fr-campus"};
  std::size_t kidnap_runs = 3;
  std::size_t kidnap_after_fix = 60;
  std::size_t kidnap_latest_step = 200;
  std::size_t kidnap_steps_after = 250;
  double kidnap_min_dist_m = 10.0;
  // Unknown area: a 8 × 8 m box erased around a mid-log pose; runs start 8 / 18 / 28 m before it.
  bool run_unknown = true;
  std::string unknown_dataset = "intel";
  std::size_t unknown_trials = 3;
  std::size_t unknown_steps = 260;
  std::string out_dir = "build/eval/localize";
  bool verbose = true;
  bool plots = true;
};

// Runs the plan, writes out_dir/{localize.md, *_error.svg/png, *_map.svg/png} and fills `json`
// (keys listed in README "bench_localize").
bool run_localize_evaluation(const LocalizePlan& plan, BenchJson* json, std::string* err);

}  // namespace sim::mmleval
