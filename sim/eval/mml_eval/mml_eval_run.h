// The evaluation plan shared by `mml-eval` (full runs, flags) and `bench_mml` (20-minute budget).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/common/bench_json.h"
#include "sim/eval/mml_eval/mml_eval.h"

namespace sim::mmleval {

struct EvalPlan {
  std::vector<std::string> datasets = {"intel", "fr079", "aces", "fr-clinic", "mit-killian"};
  std::size_t trials = 10;
  std::uint64_t seed = 1;
  int threads = 2;
  TrialOptions trial;
  TrialOptions trial_mit;         // mit-killian: longer corridors
  int mml_config = 3;
  std::vector<int> extra_mml_configs;  // C1..C4 besides the main one (side by side)
  // Local map correction (Eq. 5.23–5.27) / reduction (Eq. 5.28–5.30) on in every MML run.
  bool mml_correct = false;
  bool mml_reduce = false;
  bool mml_unique = true;   // --no-unique: MmlOptions::unique_check off (pose_uniqueness.h)
  // Also run the main configuration with correction and with reduction side by side.
  bool compare_local_map_options = false;
  std::uint32_t mcl_particles = 30000;
  std::uint32_t mcl_particles_mit = 120000;
  std::size_t mcl_trials = 0;     // 0 = same as trials (MCL is the slow one)
  std::size_t mcl_trials_mit = 0; // 0 = mcl_trials (120k particles on mit-killian are slower still)
  bool run_mcl = true;
  bool run_handoff = true;
  std::vector<std::string> handoff_datasets = {"intel", "aces"};
  bool run_unknown = true;
  std::string unknown_dataset = "intel";
  std::size_t unknown_trials = 3;
  std::string out_dir = "build/bench/mml";
  bool verbose = true;
};

// Runs everything, writes out_dir/{summary.md, *.svg, *.png} and fills `json` with the keys.
bool run_evaluation(const EvalPlan& plan, BenchJson* json, std::string* err);

}  // namespace sim::mmleval
