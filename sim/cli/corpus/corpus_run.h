// One run of the corpus: the draw's building generated, the world and the map made to differ as
// drawn, and mml-track run on it through the same simulated HAL as mml-sim (sim_runner.h), with the
// truth exact at every scan. What a run keeps of its steps is what the corpus figures need.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "sim/cli/corpus/corpus_draw.h"
#include "sim/world/map_changes.h"

namespace sim::corpus {

// One published estimate, as the corpus figures read it.
struct CorpusStep {
  float err_m = 0, err_deg = 0;      // against the exact truth (NaN without a pose)
  float pl_xy_m = 0, pl_theta_deg = 0;
  float travelled_m = 0;             // true path length so far
  float step_ms = 0;
  std::uint8_t status = 0, mode = 0, reason = 0;  // hal::LocalizationStatus / LocalizationMode / StatusReason
  std::uint8_t has_pose = 0, in_unknown = 0, kidnapped = 0;
  std::uint8_t wait_cause = 0;  // StepRecord::wait_cause as an index of wait_cause_names()
};

// The names TrackedLocalizer::wait_cause gives, "none" first and "other" last (a step's index is
// memcpy'd between processes, a pointer would not be).
const std::vector<std::string>& wait_cause_names();
std::uint8_t wait_cause_index(const char* name);

struct CorpusRun {
  CorpusDraw draw;
  bool ok = false;
  std::string error;                 // why the run could not be made (a generator or option error)
  MapChangeReport changes;
  double width_m = 0, height_m = 0;  // of the generated building
  double seconds = 0;                // wall time of the run (generation included)
  std::vector<CorpusStep> steps;
};

struct CorpusRunOptions {
  bool timing = true;        // measure step times (false: every figure but timing is reproducible bit for bit)
  int threads = 1;           // the localizer's worker threads
  std::string picture_dir;   // non-empty: mml-sim's pictures and steps.csv of this run there
  std::size_t max_scans = 0; // 0 = the whole route (tests shorten it)
  double route_scale = 1.0;  // the drawn route length × this (tests shorten it)
  // mml-track's options for every run (mml-sim's --opt KEY=VALUE, e.g. valley=0): what a rule buys
  // is measured as the same corpus with and without it. They override the odometry profile's keys.
  std::map<std::string, std::string> localizer_options;
};

// The processed scan period of a sensor of `rate_hz`: every k-th scan, k = round(0.2 s × rate) ≥ 1
// (the corpus feeds the localizer about 5 scans a second, as the bench logs' step rule does).
double processed_scan_period(double rate_hz);

// Runs the draw; a draw that cannot be made is a run with ok = false and its error (counted, never
// dropped silently).
CorpusRun run_draw(const CorpusDraw& draw, const CorpusRunOptions& opt);

// A run as bytes (the corpus runs its draws in child processes and reads them back) and back.
std::string serialize_run(const CorpusRun& run);
bool deserialize_run(const std::string& bytes, CorpusRun* run, std::string* err);

}  // namespace sim::corpus
