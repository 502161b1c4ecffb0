// The summary figures of a run from its steps (summarize_steps, declared in sim_runner.h).
#include <algorithm>
#include <cmath>
#include <vector>

#include "sim/cli/sim_runner.h"
#include "sim/common/units.h"
#include "sim/eval/mml_eval/reference_map_check.h"

namespace sim {

namespace {

// Success bounds of the dissertation (Sec. 5.7): a localized estimate farther off is a failure.
constexpr double kWrongM = 0.5, kWrongDeg = 20.0;

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  size_t idx = static_cast<size_t>(p * static_cast<double>(v.size() - 1) + 0.5);
  return v[std::min(idx, v.size() - 1)];
}

// Start from the defaults for every derived field, keep what the caller measured.
void reset_derived_fields(SimSummary* s) {
  const SimSummary keep = *s;
  *s = SimSummary();
  s->source = keep.source;
  s->localizer = keep.localizer;
  s->scans_dropped = keep.scans_dropped;
  s->wall_s = keep.wall_s;
  s->scans_per_s = keep.scans_per_s;
  s->load_s = keep.load_s;
  s->odom_rejected = keep.odom_rejected;
  s->scans_held = keep.scans_held;
  s->ring_drops = keep.ring_drops;
  s->transport = keep.transport;
  s->transport_stats = keep.transport_stats;
  s->step_errors = keep.step_errors;
  s->scans_restamped = keep.scans_restamped;
  s->hint_step = keep.hint_step;  // issue 60: what the run sent and wrote, not derived from the steps
  s->hint_reply = keep.hint_reply;
  s->blackbox_frames = keep.blackbox_frames;
  s->blackbox_bytes = keep.blackbox_bytes;
  s->blackbox_serial_chunks = keep.blackbox_serial_chunks;
  s->blackbox_serial_bytes = keep.blackbox_serial_bytes;
  s->deadline_misses = keep.deadline_misses;
}

// What the pass over the steps gathers besides counts: samples for the means and percentiles, and
// where the kidnapping happened.
struct StepSamples {
  std::vector<double> ms, err_loc, trk_m, trk_deg, glob_m, glob_deg, pl_xy, pl_th;
  bool any_tracking = false;
  double kidnap_travelled = 0, kidnap_t = 0;
};

// Kidnapping: detection = the first step from the kidnap scan on that is not `localized`; the
// re-fix = the first `localized` step after that. Returns whether step i came after a kidnapping
// not yet detected before it.
bool follow_kidnap(const std::vector<StepRecord>& steps, std::size_t i, bool loc, StepSamples* x, SimSummary* s) {
  const StepRecord& r = steps[i];
  const long step = static_cast<long>(i);
  if (r.kidnapped && s->kidnap_step < 0) {
    s->kidnap_step = step;
    x->kidnap_travelled = r.travelled_m;
    x->kidnap_t = r.t;
    if (i > 0 && steps[i - 1].has_truth && r.has_truth) {
      s->kidnap_jump_m = std::hypot(r.truth.x - steps[i - 1].truth.x, r.truth.y - steps[i - 1].truth.y);
    }
  }
  const bool undetected_kidnap = s->kidnap_step >= 0 && s->kidnap_detected_step < 0;
  if (undetected_kidnap && !loc) {
    s->kidnap_detected_step = step;
    s->kidnap_detection_delay_steps = step - s->kidnap_step;
  } else if (s->kidnap_detected_step >= 0 && s->relocalized_step < 0 && loc) {
    s->relocalized_step = step;
    s->refix_travelled_m = r.travelled_m - x->kidnap_travelled;
    s->refix_s = r.t - x->kidnap_t;
    s->refix_err_m = r.err_m;
  }
  return undetected_kidnap;
}

// Availability over the steps after the first fix (the unknown area left out, and the steps from a
// carry until the next `localized` one: silence while carried is right; the corpus's rule,
// corpus_figures.cpp).
void count_availability(const StepRecord& r, bool loc, bool carried, SimSummary* s) {
  if (s->first_localized_step < 0) return;
  if (r.in_unknown) {
    ++s->unknown_area_steps;
  } else if (carried) {
    ++s->carried_steps;
  } else {
    ++s->availability_steps;
    if (loc) {
      ++s->availability_localized;
    } else {
      const auto k = static_cast<std::size_t>(r.estimate.reason);
      if (k < hal::kStatusReasonCount) ++s->unavailable_by_reason[k];
    }
  }
}

// Beyond (limit_m, limit_deg) as mml-eval judges it (reference_map_check.h: the truth's own error
// bound, and the map's pose for the scan where the map explains it clearly better).
bool judged_beyond(const StepRecord& r, double limit_m, double limit_deg) {
  mmleval::JudgedError e;
  e.ref_m = r.err_m;
  e.ref_ang = r.err_deg;
  e.bound_m = r.truth_bound_m;
  e.bound_ang = r.truth_bound_deg;
  e.map_improves = r.map_checked && r.map_pose_better;
  e.map_m = r.map_err_m;
  e.map_ang = r.map_err_deg;
  return mmleval::judged_beyond(e, limit_m, limit_deg);
}

// Error of a `localized` step with a pose and a truth: wrong, integrity failure, tracking or global.
void score_localized_error(const StepRecord& r, long step, bool undetected_kidnap, StepSamples* x, SimSummary* s) {
  x->err_loc.push_back(r.err_m);
  if (judged_beyond(r, kWrongM, kWrongDeg)) ++s->wrong_localized_steps;
  if (judged_beyond(r, kIntegrityLimitM, kIntegrityLimitDeg)) {
    ++s->integrity_failures;
    if (undetected_kidnap) ++s->integrity_failures_kidnap;
    if (s->first_integrity_failure_step < 0) s->first_integrity_failure_step = step;
  } else if (r.err_m > kIntegrityLimitM || r.err_deg > kIntegrityLimitDeg) {
    ++s->integrity_not_judged;
  }
  if (r.estimate.mode == hal::LocalizationMode::kTracking) {
    x->any_tracking = true;
    x->trk_m.push_back(r.err_m);
    x->trk_deg.push_back(r.err_deg);
  } else {
    x->glob_m.push_back(r.err_m);
    x->glob_deg.push_back(r.err_deg);
  }
}

void score_localized_step(const StepRecord& r, long step, bool undetected_kidnap, StepSamples* x, SimSummary* s) {
  const hal::PoseEstimate& e = r.estimate;
  const bool scored = std::isfinite(r.err_m) && std::isfinite(r.err_deg);
  ++s->localized_steps;
  if (s->first_localized_step < 0) {
    s->first_localized_step = step;
    s->first_localized_t = r.t;
    s->first_localized_travelled_m = r.travelled_m;
    s->first_localized_err_m = r.err_m;
    if (e.protection_xy_m > 0) s->first_localized_pl_xy_m = e.protection_xy_m;
  }
  if (scored) score_localized_error(r, step, undetected_kidnap, x, s);
  if (e.protection_xy_m > 0 || e.protection_theta_rad > 0) {
    ++s->pl_steps;
    x->pl_xy.push_back(e.protection_xy_m);
    x->pl_th.push_back(e.protection_theta_rad * kRadToDeg);
    if (scored) {
      ++s->pl_scored;
      const double pl_deg = e.protection_theta_rad * kRadToDeg;
      if (judged_beyond(r, e.protection_xy_m, pl_deg)) {
        ++s->pl_exceeded;
      } else if (r.err_m > e.protection_xy_m || r.err_deg > pl_deg) {
        ++s->pl_not_judged;
      }
    }
  }
}

void note_final_pose(const StepRecord& r, long step, SimSummary* s) {
  if (!r.has_pose) return;
  s->final_pose_step = step;
  s->final_pose_status = hal::status_name(r.estimate.status);
  s->final_err_m = r.err_m;
  s->final_err_deg = r.err_deg;
}

void finish_localized_error_figures(StepSamples* x, SimSummary* s) {
  if (!x->err_loc.empty()) {
    double sum = 0;
    for (double v : x->err_loc) sum += v;
    s->mean_err_localized_m = sum / static_cast<double>(x->err_loc.size());
    s->max_err_localized_m = *std::max_element(x->err_loc.begin(), x->err_loc.end());
  }
  // A localizer without a tracking mode (mml): its `localized` steps are the tracking error.
  if (!x->any_tracking) {
    x->trk_m.swap(x->glob_m);
    x->trk_deg.swap(x->glob_deg);
  }
  s->tracking_steps = x->trk_m.size();
  if (!x->trk_m.empty()) {
    s->tracking_err_m_p50 = percentile(x->trk_m, 0.5);
    s->tracking_err_m_p95 = percentile(x->trk_m, 0.95);
    s->tracking_err_deg_p50 = percentile(x->trk_deg, 0.5);
    s->tracking_err_deg_p95 = percentile(x->trk_deg, 0.95);
  }
}

void finish_protection_level_figures(const StepSamples& x, SimSummary* s) {
  if (s->pl_scored > 0) s->pl_exceedance_rate = static_cast<double>(s->pl_exceeded) / static_cast<double>(s->pl_scored);
  if (!x.pl_xy.empty()) {
    s->pl_xy_m_p50 = percentile(x.pl_xy, 0.5);
    s->pl_xy_m_max = *std::max_element(x.pl_xy.begin(), x.pl_xy.end());
    s->pl_theta_deg_p50 = percentile(x.pl_th, 0.5);
    s->pl_theta_deg_max = *std::max_element(x.pl_th.begin(), x.pl_th.end());
  }
}

void finish_step_times(const std::vector<double>& ms, SimSummary* s) {
  double tot = 0;
  for (double v : ms) tot += v;
  s->step_ms_mean = tot / static_cast<double>(ms.size());
  s->step_ms_p50 = percentile(ms, 0.5);
  s->step_ms_p99 = percentile(ms, 0.99);
  s->step_ms_max = *std::max_element(ms.begin(), ms.end());
}

}  // namespace

void summarize_steps(const std::vector<StepRecord>& steps, SimSummary* s) {
  reset_derived_fields(s);
  s->steps = steps.size();
  if (steps.empty()) return;

  StepSamples x;
  bool carried = false;
  for (std::size_t i = 0; i < steps.size(); ++i) {
    const StepRecord& r = steps[i];
    const long step = static_cast<long>(i);
    const bool loc = r.estimate.status == hal::LocalizationStatus::kLocalized;
    x.ms.push_back(r.step_ms);
    const int k = static_cast<int>(r.estimate.status);
    if (k >= 0 && k < 5) ++s->status_counts[k];
    const bool undetected_kidnap = follow_kidnap(steps, i, loc, &x, s);
    if (r.kidnapped) carried = true;
    if (loc) carried = false;
    count_availability(r, loc, carried, s);
    if (loc) score_localized_step(r, step, undetected_kidnap, &x, s);
    note_final_pose(r, step, s);
  }
  if (s->availability_steps > 0) {
    s->availability = static_cast<double>(s->availability_localized) / static_cast<double>(s->availability_steps);
  }
  finish_localized_error_figures(&x, s);
  finish_protection_level_figures(x, s);
  s->path_length_m = steps.back().travelled_m;
  finish_step_times(x.ms, s);
}

}  // namespace sim
