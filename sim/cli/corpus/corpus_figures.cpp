#include "sim/cli/corpus/corpus_figures.h"

#include <algorithm>
#include <cmath>

#include "hal/msg/pose_estimate.h"

namespace sim::corpus {

namespace {

using hal::LocalizationMode;
using hal::LocalizationStatus;

bool localized(const CorpusStep& s) { return s.status == static_cast<std::uint8_t>(LocalizationStatus::kLocalized); }
bool tracking(const CorpusStep& s) { return s.mode == static_cast<std::uint8_t>(LocalizationMode::kTracking) && s.has_pose; }
bool right(const CorpusStep& s) { return s.has_pose && s.err_m < kRightM && s.err_deg < kRightDeg; }

// Nearest-rank quantile (q in [0, 1]) of an unsorted copy; NaN for none.
double quantile(std::vector<double> v, double q) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const std::size_t i = static_cast<std::size_t>(std::ceil(q * static_cast<double>(v.size())));
  return v[std::min(v.size() - 1, i == 0 ? 0 : i - 1)];
}

// Which steps count for availability and gaps: after the run's first fix, not in unmapped space,
// not between a kidnap and the next `localized` step.
std::vector<char> judged_steps(const CorpusRun& run, std::size_t first_fix) {
  std::vector<char> judged(run.steps.size(), 0);
  bool carried = false;
  for (std::size_t i = first_fix; i < run.steps.size(); ++i) {
    const CorpusStep& s = run.steps[i];
    if (s.kidnapped) carried = true;
    if (carried && localized(s)) carried = false;
    judged[i] = !carried && !s.in_unknown;
  }
  return judged;
}

}  // namespace

RunFigures run_figures(const CorpusRun& run) {
  RunFigures f;
  std::size_t first = run.steps.size();
  for (std::size_t i = 0; i < run.steps.size(); ++i) {
    if (localized(run.steps[i])) {
      first = i;
      break;
    }
  }
  if (first == run.steps.size()) return f;
  f.fixed = true;
  f.metres_to_fix = run.steps[first].travelled_m - run.steps.front().travelled_m;
  const std::vector<char> judged = judged_steps(run, first);
  // A gap: consecutive judged steps withheld while right, measured from the last step before it.
  double gap_start = -1;
  for (std::size_t i = first; i < run.steps.size(); ++i) {
    const CorpusStep& s = run.steps[i];
    if (s.kidnapped) f.carried_after_fix = true;
    if (f.carried_after_fix && localized(s) && !s.kidnapped) f.refixed = true;
    if (!judged[i]) {
      gap_start = -1;
      continue;
    }
    ++f.judged;
    if (localized(s)) {
      ++f.judged_localized;
      gap_start = -1;
    } else if (tracking(s) && right(s)) {
      if (gap_start < 0) gap_start = run.steps[i - 1].travelled_m;
      f.longest_gap_m = std::max(f.longest_gap_m, static_cast<double>(s.travelled_m) - gap_start);
    } else {
      gap_start = -1;
    }
  }
  return f;
}

double binomial_ucb95(std::size_t k, std::size_t n) {
  if (n == 0) return 1.0;
  if (k >= n) return 1.0;
  // P(X ≤ k | n, p) falls with p: bisect for 0.05 (log-space terms, k small or large alike).
  const auto cdf = [&](double p) {
    const double lp = std::log(p), lq = std::log1p(-p);
    double sum = 0;
    for (std::size_t j = 0; j <= k; ++j) {
      const double lt = std::lgamma(n + 1.0) - std::lgamma(j + 1.0) - std::lgamma(n - j + 1.0) + j * lp + (n - j) * lq;
      sum += std::exp(lt);
    }
    return sum;
  };
  double lo = static_cast<double>(k) / n, hi = 1.0;
  for (int it = 0; it < 100; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cdf(mid) > 0.05 ? lo : hi) = mid;
  }
  return hi;
}

CorpusFigures corpus_figures(const std::vector<const CorpusRun*>& runs) {
  CorpusFigures f;
  std::vector<double> avail, gaps, to_fix, em, ed, ms, gms, plxy, plth;
  for (const CorpusRun* r : runs) {
    ++f.runs;
    if (!r->ok) {
      ++f.runs_failed;
      continue;
    }
    const RunFigures rf = run_figures(*r);
    if (rf.fixed) {
      ++f.runs_fixed;
      to_fix.push_back(rf.metres_to_fix);
      gaps.push_back(rf.longest_gap_m);
      if (rf.judged > 0) avail.push_back(static_cast<double>(rf.judged_localized) / rf.judged);
      f.kidnap_runs += rf.carried_after_fix;
      f.kidnap_refixed += rf.refixed;
    }
    for (const CorpusStep& s : r->steps) {
      ++f.steps;
      if (s.mode == static_cast<std::uint8_t>(LocalizationMode::kGlobal)) gms.push_back(s.step_ms);
      if (tracking(s)) {
        ++f.tracking_steps;
        ms.push_back(s.step_ms);
        if (!localized(s) && right(s) && !s.in_unknown) {
          ++f.withheld_while_right;
          ++f.withheld_by_reason[std::min<std::size_t>(s.reason, 15)];
          if (s.reason == static_cast<std::uint8_t>(hal::StatusReason::kTrackAwaitingMml)) {
            ++f.awaiting_by_cause[wait_cause_names()[std::min<std::size_t>(s.wait_cause, wait_cause_names().size() - 1)]];
          }
        }
      }
      if (!localized(s) || !s.has_pose) continue;
      ++f.localized_steps;
      if (s.err_m > kAlertM || s.err_deg > kAlertDeg) ++f.integrity_failures;
      if (tracking(s)) {
        em.push_back(s.err_m);
        ed.push_back(s.err_deg);
      }
      if (s.pl_xy_m > 0) {
        ++f.pl_steps;
        plxy.push_back(s.pl_xy_m);
        plth.push_back(s.pl_theta_deg);
        if (s.err_m > s.pl_xy_m) ++f.pl_exceed_xy;
        if (s.err_deg > s.pl_theta_deg) ++f.pl_exceed_theta;
      }
    }
  }
  const double n = static_cast<double>(std::max<std::size_t>(f.pl_steps, 1));
  f.pl_exceed_xy_rate = f.pl_exceed_xy / n;
  f.pl_exceed_theta_rate = f.pl_exceed_theta / n;
  f.pl_exceed_xy_ucb95 = binomial_ucb95(f.pl_exceed_xy, f.pl_steps);
  f.pl_exceed_theta_ucb95 = binomial_ucb95(f.pl_exceed_theta, f.pl_steps);
  f.integrity_failure_rate_ucb95 = binomial_ucb95(f.integrity_failures, f.localized_steps);
  f.availability_median = quantile(avail, 0.5);
  f.availability_p10 = quantile(avail, 0.1);
  f.withheld_while_right_rate =
      f.tracking_steps > 0 ? static_cast<double>(f.withheld_while_right) / f.tracking_steps : NAN;
  f.longest_gap_m_p99 = quantile(gaps, 0.99);
  f.longest_gap_m_max = quantile(gaps, 1.0);
  const std::size_t ok = f.runs - f.runs_failed;
  f.first_fix_success = ok > 0 ? static_cast<double>(f.runs_fixed) / ok : NAN;
  f.metres_to_fix_median = quantile(to_fix, 0.5);
  f.metres_to_fix_p90 = quantile(to_fix, 0.9);
  f.track_err_m_p50 = quantile(em, 0.5);
  f.track_err_m_p95 = quantile(em, 0.95);
  f.track_err_deg_p50 = quantile(ed, 0.5);
  f.track_err_deg_p95 = quantile(ed, 0.95);
  f.pl_xy_m_p50 = quantile(plxy, 0.5);
  f.pl_theta_deg_p50 = quantile(plth, 0.5);
  f.track_step_ms_p50 = quantile(ms, 0.5);
  f.track_step_ms_p99 = quantile(ms, 0.99);
  f.global_step_ms_p50 = quantile(gms, 0.5);
  f.global_step_ms_p99 = quantile(gms, 0.99);
  f.global_step_ms_max = quantile(gms, 1.0);
  return f;
}

void add_figures(const std::string& p, const CorpusFigures& f, bool with_timing, BenchJson* j) {
  j->add_int(p + "runs", static_cast<long long>(f.runs));
  j->add_int(p + "runs_failed", static_cast<long long>(f.runs_failed));
  j->add_int(p + "steps", static_cast<long long>(f.steps));
  j->add_int(p + "localized_steps", static_cast<long long>(f.localized_steps));
  j->add_int(p + "integrity_failures", static_cast<long long>(f.integrity_failures));
  j->add(p + "integrity_failures_ucb95", f.integrity_failure_rate_ucb95);
  j->add_int(p + "pl_steps", static_cast<long long>(f.pl_steps));
  j->add(p + "pl_exceed_xy_rate", f.pl_exceed_xy_rate);
  j->add(p + "pl_exceed_xy_rate_ucb95", f.pl_exceed_xy_ucb95);
  j->add(p + "pl_exceed_theta_rate", f.pl_exceed_theta_rate);
  j->add(p + "pl_exceed_theta_rate_ucb95", f.pl_exceed_theta_ucb95);
  j->add(p + "availability_median", f.availability_median);
  j->add(p + "availability_p10", f.availability_p10);
  j->add_int(p + "tracking_steps", static_cast<long long>(f.tracking_steps));
  j->add(p + "withheld_while_right_rate", f.withheld_while_right_rate);
  for (std::uint8_t r = 1; r < hal::kStatusReasonCount; ++r) {
    if (f.withheld_by_reason[r] == 0) continue;
    j->add_int(p + "withheld_while_right_" + hal::reason_name(static_cast<hal::StatusReason>(r)),
               static_cast<long long>(f.withheld_by_reason[r]));
  }
  for (const auto& [cause, count] : f.awaiting_by_cause) {
    j->add_int(p + "withheld_while_right_awaiting_mml_" + cause, static_cast<long long>(count));
  }
  j->add(p + "longest_gap_m_p99", f.longest_gap_m_p99);
  j->add(p + "longest_gap_m_max", f.longest_gap_m_max);
  j->add(p + "first_fix_success", f.first_fix_success);
  j->add(p + "metres_to_fix_median", f.metres_to_fix_median);
  j->add(p + "metres_to_fix_p90", f.metres_to_fix_p90);
  j->add(p + "track_err_m_p50", f.track_err_m_p50);
  j->add(p + "track_err_m_p95", f.track_err_m_p95);
  j->add(p + "track_err_deg_p50", f.track_err_deg_p50);
  j->add(p + "track_err_deg_p95", f.track_err_deg_p95);
  j->add_int(p + "kidnap_runs", static_cast<long long>(f.kidnap_runs));
  j->add_int(p + "kidnap_refixed", static_cast<long long>(f.kidnap_refixed));
  j->add(p + "pl_xy_m_p50", f.pl_xy_m_p50);
  j->add(p + "pl_theta_deg_p50", f.pl_theta_deg_p50);
  if (with_timing) {
    j->add(p + "track_step_ms_p50", f.track_step_ms_p50);
    j->add(p + "track_step_ms_p99", f.track_step_ms_p99);
    j->add(p + "global_step_ms_p50", f.global_step_ms_p50);
    j->add(p + "global_step_ms_p99", f.global_step_ms_p99);
    j->add(p + "global_step_ms_max", f.global_step_ms_max);
  }
}

}  // namespace sim::corpus
