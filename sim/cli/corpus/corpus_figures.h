// The figures of a corpus (issue 55 "Measure"), over any group of its runs: pooled, per family, per
// sensor or odometry profile, the distorted-map draws on their own. Definitions (README of this
// folder): a step is judged against the exact truth, with no exclusions but the steps whose truth
// lies in space erased from the map and the steps between a kidnap and the next fix (the robot was
// carried; being silent then is right).
#pragma once

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "sim/cli/corpus/corpus_run.h"
#include "sim/common/bench_json.h"

namespace sim::corpus {

// "Right" while withheld: within these of the truth (issue 55: 0.1 m and 1.5°).
constexpr double kRightM = 0.1, kRightDeg = 1.5;
// An integrity failure: `localized` beyond the product's alert limits (0.5 m, 5°).
constexpr double kAlertM = 0.5, kAlertDeg = 5.0;

struct CorpusFigures {
  std::size_t runs = 0, runs_failed = 0, runs_fixed = 0;
  std::size_t steps = 0, localized_steps = 0, integrity_failures = 0;
  std::size_t pl_steps = 0, pl_exceed_xy = 0, pl_exceed_theta = 0;
  double pl_exceed_xy_rate = 0, pl_exceed_xy_ucb95 = 0, pl_exceed_theta_rate = 0, pl_exceed_theta_ucb95 = 0;
  double integrity_failure_rate_ucb95 = 0;
  double availability_median = 0, availability_p10 = 0;
  std::size_t tracking_steps = 0, withheld_while_right = 0;
  std::size_t withheld_by_reason[16] = {};  // hal::StatusReason
  // Withheld while right with reason track-awaiting-mml, by what the wait is charged to
  // (TrackedLocalizer::wait_cause: the large fault's monitor, alias-beyond-alert, hint, mml-conflict).
  std::map<std::string, std::size_t> awaiting_by_cause;
  double withheld_while_right_rate = 0;
  double longest_gap_m_p99 = 0, longest_gap_m_max = 0;
  double first_fix_success = 0, metres_to_fix_median = 0, metres_to_fix_p90 = 0;
  double track_err_m_p50 = 0, track_err_m_p95 = 0, track_err_deg_p50 = 0, track_err_deg_p95 = 0;
  double pl_xy_m_p50 = 0, pl_theta_deg_p50 = 0;
  double track_step_ms_p50 = 0, track_step_ms_p99 = 0;
  // Steps in global mode (MML searching, run inline on the scan): issue 58's bound on the global step.
  double global_step_ms_p50 = 0, global_step_ms_p99 = 0, global_step_ms_max = 0;
  // Kidnapped runs: carried once after their first fix; re-fixed = `localized` again after the carry.
  std::size_t kidnap_runs = 0, kidnap_refixed = 0;
};

// Per run: figures a group pools (exposed for tests).
struct RunFigures {
  bool fixed = false;
  double metres_to_fix = 0;
  std::size_t judged = 0, judged_localized = 0;  // availability: steps after the fix, not in unmapped space
  double longest_gap_m = 0;                       // withheld while right, metres driven
  bool carried_after_fix = false, refixed = false;  // a kidnap after the first fix, and `localized` after it
};
RunFigures run_figures(const CorpusRun& run);

CorpusFigures corpus_figures(const std::vector<const CorpusRun*>& runs);

// Clopper–Pearson one-sided upper bound at 95 % for k events in n trials.
double binomial_ucb95(std::size_t k, std::size_t n);

// Adds the figures with their keys: prefix "corpus_" for the pool, "FAMILY_office_" … for groups.
void add_figures(const std::string& prefix, const CorpusFigures& f, bool with_timing, BenchJson* json);

}  // namespace sim::corpus
