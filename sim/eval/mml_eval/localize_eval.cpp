#include "sim/eval/mml_eval/localize_eval.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "firmware/base/rng.h"
#include "sim/common/reason_list.h"
#include "sim/common/stopwatch.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/eval/mml_eval/reference_rest_scatter.h"

namespace sim::mmleval {

namespace {

std::size_t count_for(const std::vector<std::pair<std::string, std::size_t>>& ov, const std::string& name,
                      std::size_t def) {
  for (const auto& p : ov)
    if (p.first == name) return p.second;
  return def;
}

MetricBounds bounds_for(const LoadedDataset& ds) {
  MetricBounds b;
  b.bound_m = ds.success_bound_m;  // dataset bound: 0.5 m (1 m at mit-killian)
  return b;
}

// Integrity failures and the status history before them, for the lead (stdout + report).
void describe_failures(const LoadedDataset& ds, const std::string& label, std::size_t trial, const TrialResult& t,
                       const MetricBounds& b, std::ostringstream* notes, bool verbose) {
  std::size_t shown = 0, total = 0;
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    const StepLog& s = t.steps[k];
    if (s.status != hal::LocalizationStatus::kLocalized || !s.ref_ok || !std::isfinite(s.err_m)) continue;
    if (!integrity_beyond(s, b.bound_m, b.bound_rad)) continue;
    ++total;
    // One line per failure episode (first step of a run of failures), at most 5 per trial.
    const StepLog* p = k > 0 ? &t.steps[k - 1] : nullptr;
    const bool new_episode = p == nullptr || !(p->status == hal::LocalizationStatus::kLocalized && p->ref_ok &&
                                               std::isfinite(p->err_m) && integrity_beyond(*p, b.bound_m, b.bound_rad));
    if (!new_episode || shown >= 5) continue;
    ++shown;
    std::string hist;
    for (std::size_t j = k >= 8 ? k - 8 : 0; j <= k; ++j) {
      const StepLog& h = t.steps[j];
      char c = '?';
      switch (h.status) {
        case hal::LocalizationStatus::kSearching: c = 's'; break;
        case hal::LocalizationStatus::kAmbiguous: c = 'a'; break;
        case hal::LocalizationStatus::kLocalized: c = h.mode == hal::LocalizationMode::kTracking ? 'T' : 'L'; break;
        case hal::LocalizationStatus::kOutsideMap: c = 'o'; break;
        default: c = 'f';
      }
      hist += c;
    }
    char buf[512];
    std::snprintf(buf, sizeof(buf),
                  "integrity failure: %s %s trial %zu (start scan %zu) step %zu scan %zu%s: err %.2f m %.1f deg, PL %.2f m "
                  "%.1f deg, mode %s, unsupported %u, history (s=searching a=ambiguous L=localized-global "
                  "T=localized-tracking o=outside) %s",
                  ds.name.c_str(), label.c_str(), trial, t.start, k + 1, s.scan,
                  s.segment ? " (after kidnap)" : "", s.err_m, s.err_rad * 57.2958, s.pl_xy, s.pl_theta * 57.2958,
                  s.mode == hal::LocalizationMode::kTracking ? "tracking" : "global", s.unsupported_steps, hist.c_str());
    *notes << "- " << buf << "\n";
    if (verbose) std::printf("    %s\n", buf);
  }
  // Steps excluded by the reference checks (never silently): the first 3 per trial.
  std::size_t listed = 0, excluded = 0;
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    const StepLog& s = t.steps[k];
    if (!s.ref_map_contradicted && !s.ref_within_bound) continue;
    ++excluded;
    if (listed >= 3) continue;
    ++listed;
    char buf[400];
    std::snprintf(buf, sizeof(buf),
                  "excluded: %s %s trial %zu step %zu scan %zu: err vs log reference %.2f m %.1f deg, vs map pose %.2f m "
                  "%.1f deg, reference bound %.2f m %.1f deg, PL %.2f m %.1f deg (%s)",
                  ds.name.c_str(), label.c_str(), trial, k + 1, s.scan, s.err_m, s.err_rad * 57.2958, s.map_err_m,
                  s.map_err_rad * 57.2958, s.ref_bound_m, s.ref_bound_rad * 57.2958, s.pl_xy, s.pl_theta * 57.2958,
                  s.ref_map_contradicted ? "the map's pose clears it" : "within the reference's own bound");
    *notes << "- " << buf << "\n";
  }
  if (excluded > listed) *notes << "  (" << ds.name << " " << label << " trial " << trial << ": " << excluded
                                << " steps excluded by the reference checks in total)\n";
  if (total > 0) {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "  (%s %s trial %zu: %zu integrity-failure steps in total)", ds.name.c_str(),
                  label.c_str(), trial, total);
    *notes << buf << "\n";
    if (verbose) std::printf("  %s\n", buf);
  }
}

// Protection-level exceedances (judged, as counted in the PL exceedance rate), for the lead: the first
// step of each run of exceedances, at most 5 per trial, with the error against both references, so
// that an exceedance the reference's own scatter could explain (reference_rest_scatter.h) is seen as such.
void describe_pl_exceedances(const LoadedDataset& ds, const std::string& label, std::size_t trial, const TrialResult& t,
                             std::ostringstream* notes) {
  auto exceeded = [](const StepLog& s) {
    return s.status == hal::LocalizationStatus::kLocalized && s.ref_ok && std::isfinite(s.err_m) &&
           (pl_xy_beyond(s) || pl_theta_beyond(s));
  };
  std::size_t shown = 0, total = 0;
  for (std::size_t k = 0; k < t.steps.size(); ++k) {
    const StepLog& s = t.steps[k];
    if (!exceeded(s)) continue;
    ++total;
    if ((k > 0 && exceeded(t.steps[k - 1])) || shown >= 5) continue;
    ++shown;
    char buf[400];
    std::snprintf(buf, sizeof(buf),
                  "PL exceeded: %s %s trial %zu step %zu scan %zu: err %.3f m %.2f deg vs PL %.3f m %.2f deg; against "
                  "the map's pose %.3f m %.2f deg; reference bound %.3f m %.2f deg",
                  ds.name.c_str(), label.c_str(), trial, k + 1, s.scan, s.err_m, s.err_rad * 57.2958, s.pl_xy,
                  s.pl_theta * 57.2958, s.map_err_m, s.map_err_rad * 57.2958, s.ref_bound_m, s.ref_bound_rad * 57.2958);
    *notes << "- " << buf << "\n";
  }
  if (total > shown)
    *notes << "  (" << ds.name << " " << label << " trial " << trial << ": " << total << " steps beyond the PL in total)\n";
}

void progress(const LoadedDataset& ds, const std::string& label, std::size_t k, std::size_t n, const TrialResult& t,
              const MetricBounds& b, double secs) {
  const TrialMetrics m = trial_metrics(t, b);
  std::printf("  %-11s %-12s %2zu/%zu start %5zu: %5zu steps %6.0f m, first fix %s %.1f m, avail %.3f, integrity "
              "failures %zu/%zu, PL exceed %zu/%zu (xy %zu, theta %zu)%s (%.0f s)\n",
              ds.name.c_str(), label.c_str(), k + 1, n, t.start, t.steps.size(),
              t.steps.empty() ? 0.0 : t.steps.back().travelled,
              m.first_fix ? (m.first_fix_success ? "ok" : "WRONG") : "none", m.first_fix ? m.m_to_fix : 0.0,
              m.avail_steps ? static_cast<double>(m.avail_localized) / m.avail_steps : 0.0, m.integrity_failures,
              m.localized_steps, m.pl_exceed, m.pl_steps, m.pl_exceed_xy, m.pl_exceed_theta, t.error.empty() ? "" : (" error: " + t.error).c_str(), secs);
  if (m.kidnapped) {
    std::printf("  %-11s %-12s      kidnap at step %zu (scan %zu -> %zu): detected %s after %.0f steps, re-fix %s "
                "after %.1f m, wrong localized after kidnap %zu\n",
                ds.name.c_str(), label.c_str(), t.kidnap_step, t.kidnap_scan_from,
                t.kidnap_step < t.steps.size() ? t.steps[t.kidnap_step].scan : 0, m.kidnap_detected ? "yes" : "NO",
                m.kidnap_delay_steps, m.kidnap_refix ? "yes" : "NO", m.refix_m, m.kidnap_integrity_failures);
  }
  std::fflush(stdout);
}

struct Run {
  std::vector<TrialResult> trials;
};

void write_plots(const LocalizePlan& plan, const LoadedDataset& ds, const std::string& label,
                 const std::vector<TrialResult>& trials, const double* region) {
  if (!plan.plots || trials.empty()) return;
  const std::string base = plan.out_dir + "/" + ds.key + "_" + label;
  std::string e;
  // Every step of every trial, for a person (or a script) to look at a failure in detail.
  {
    std::ofstream csv(base + "_steps.csv");
    csv << "trial,step,scan,segment,status,mode,est_x,est_y,est_theta,ref_x,ref_y,ref_theta,ref_ok,err_m,err_deg,"
           "pl_xy_m,pl_theta_deg,unsupported,reason,map_err_m,map_err_deg\n";
    for (std::size_t k = 0; k < trials.size(); ++k)
      for (std::size_t i = 0; i < trials[k].steps.size(); ++i) {
        const StepLog& s = trials[k].steps[i];
        char buf[384];
        std::snprintf(buf, sizeof(buf), "%zu,%zu,%zu,%zu,%s,%s,%.4f,%.4f,%.5f,%.4f,%.4f,%.5f,%d,%.4f,%.3f,%.3f,%.3f,%u,%s,%.4f,%.3f\n", k, i,
                      s.scan, s.segment, hal::status_name(s.status),
                      s.mode == hal::LocalizationMode::kTracking ? "tracking" : "global", s.estimate.x, s.estimate.y,
                      s.estimate.theta, s.truth.x, s.truth.y, s.truth.theta, s.ref_ok ? 1 : 0, s.err_m,
                      s.err_rad * 57.29578, s.pl_xy, s.pl_theta * 57.29578, s.unsupported_steps,
                      hal::reason_name(s.reason), s.map_err_m, s.map_err_rad * 57.29578);  // map: NaN if not judged
        csv << buf;
      }
  }
  if (!write_error_plot(base + "_error.svg", ds.name + " - " + label + ": error over metres", trials,
                        ds.success_bound_m, &e) ||
      !write_map_plot(base + "_map.svg", base + "_map.png", ds, ds.name + " - " + label, trials, region, &e)) {
    std::fprintf(stderr, "localize: plots of %s %s: %s\n", ds.name.c_str(), label.c_str(), e.c_str());
  }
}

}  // namespace

namespace {

// State of one evaluation shared by its steps.
struct LocalizeRun {
  const LocalizePlan& plan;
  BenchJson* json;
  std::chrono::steady_clock::time_point t_all;
  std::vector<SystemSummary> rows;
  std::ostringstream notes, refnotes, plnotes, mclnotes;
  std::vector<double> track_ms_all;
  // The same steps less their inline global step (StepLog::global_ms): the sensor context's share,
  // what mmlfw's sensor thread runs (the global step runs on the global context there).
  std::vector<double> track_sensor_ms_all;
  std::vector<TrialResult> kidnap_all;
  MetricBounds kidnap_bounds;
  fw::mml::MmlLocalizerConfig mml_cfg;
};

// Whole-log runs: kidnapped starts drawn over the first whole_start_fraction of the path, to the end.
void run_whole_logs(LocalizeRun& run, const LoadedDataset& ds, OwnedLocalizer& loc, const MetricBounds& b,
                    std::vector<TrialResult>* all) {
  const LocalizePlan& plan = run.plan;
  const std::size_t nwhole = count_for(plan.whole_runs_override, ds.name, plan.whole_runs);
  const double total = ds.travelled.back();
  std::size_t last = 0;
  for (std::size_t i = 0; i < ds.travelled.size(); ++i)
    if (ds.travelled[i] <= plan.whole_start_fraction * total) last = i;
  fw::RandomStream rng(plan.seed, 501);
  TrialOptions opt = plan.step_rule;
  opt.max_steps = plan.whole_max_steps;
  // Every scan, as the firmware sees them: the step rule (a scan after 0.15 m / 0.15 rad of odometry)
  // skips exactly the scans where the wheels under-report a motion (fr079 scans 729 and 3277 were
  // two `localized` poses 5° off that only every-scan runs showed).
  opt.min_move_m = 0.0;
  opt.min_turn_rad = 0.0;
  std::vector<TrialResult> whole;
  for (std::size_t k = 0; k < nwhole; ++k) {
    const std::size_t start = last > 0 ? rng.uniform_index(static_cast<std::uint32_t>(last)) : 0;
    const auto tk = std::chrono::steady_clock::now();
    TrialResult t = run_trial(loc, ds, start, opt);
    t.whole_log = true;
    if (plan.verbose) progress(ds, "whole-log", k, nwhole, t, b, seconds_since(tk));
    describe_failures(ds, "whole-log", k, t, b, &run.notes, plan.verbose);
    describe_pl_exceedances(ds, "whole-log", k, t, &run.plnotes);
    whole.push_back(t);
    all->push_back(std::move(t));
  }
  write_plots(plan, ds, "mml-track_whole", whole, nullptr);
}

// First-fix trials from kidnapped starts, fix_steps long each.
void run_fix_trials(LocalizeRun& run, const LoadedDataset& ds, OwnedLocalizer& loc, const MetricBounds& b,
                    const std::vector<std::size_t>& starts, const TrialOptions& fopt, std::vector<TrialResult>* all,
                    std::vector<TrialResult>* fix_out) {
  std::vector<TrialResult>& fix = *fix_out;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const auto tk = std::chrono::steady_clock::now();
    TrialResult t = run_trial(loc, ds, starts[k], fopt);
    if (run.plan.verbose) progress(ds, "fix-trial", k, starts.size(), t, b, seconds_since(tk));
    describe_failures(ds, "fix-trial", k, t, b, &run.notes, run.plan.verbose);
    describe_pl_exceedances(ds, "fix-trial", k, t, &run.plnotes);
    fix.push_back(t);
    all->push_back(std::move(t));
  }
  write_plots(run.plan, ds, "mml-track_fix", fix, nullptr);
}

// The dataset's flat figures (D_first_fix_success, ...).
void add_dataset_figures(BenchJson* json, const std::string& D, const SystemSummary& s) {
  json->add(D + "_first_fix_success", s.first_fix_success);
  json->add(D + "_m_to_fix_median", s.m_to_fix_median);
  json->add(D + "_availability", s.availability);
  json->add_int(D + "_integrity_failures", static_cast<long long>(s.integrity_failures));
  json->add_int(D + "_localized_steps_checked", static_cast<long long>(s.localized_checked));
  json->add(D + "_pl_exceed_rate", s.pl_exceed_rate);
  // The same against the log reference alone, and what the reference checks excluded.
  json->add_int(D + "_integrity_failures_vs_log_reference", static_cast<long long>(s.integrity_failures_raw));
  json->add(D + "_pl_exceed_rate_vs_log_reference",
            s.pl_steps_raw ? static_cast<double>(s.pl_exceed_raw) / s.pl_steps_raw : NAN);
  json->add_int(D + "_excluded_map_steps", static_cast<long long>(s.excluded_map_steps));
  json->add_int(D + "_excluded_ref_bound_steps", static_cast<long long>(s.excluded_bound_steps));
  json->add(D + "_pl_exceed_xy_rate", s.pl_steps ? static_cast<double>(s.pl_exceed_xy) / s.pl_steps : NAN);
  json->add(D + "_pl_exceed_theta_rate", s.pl_steps ? static_cast<double>(s.pl_exceed_theta) / s.pl_steps : NAN);
  json->add(D + "_availability_steps", static_cast<double>(s.avail_steps));
  // Left out as unmapped (unmapped_scan.h), and the availability with them counted in.
  json->add_int(D + "_unmapped_steps_excluded", static_cast<long long>(s.unmapped_steps));
  json->add(D + "_availability_with_unmapped", s.availability_with_unmapped);
  // `outside-map` published where the map covers the reference's scan (unmapped_scan.h): a false one.
  json->add_int(D + "_outside_map_steps", static_cast<long long>(s.outside_map_steps));
  json->add_int(D + "_outside_map_false_steps", static_cast<long long>(s.outside_map_false_steps));
  // Shown only: availability steps where the map explains less than half of the scan at the reference.
  json->add(D + "_ref_off_map_share", s.avail_steps ? static_cast<double>(s.off_map_steps) / s.avail_steps : NAN);
  // Where the availability went: share of the availability steps not `localized`, per reason
  // (hal::StatusReason; names with '-' as '_').
  for (std::size_t r = 1; r < hal::kStatusReasonCount; ++r) {
    std::string name = hal::reason_name(static_cast<hal::StatusReason>(r));
    for (char& c : name) c = c == '-' ? '_' : c;
    json->add(D + "_unavailable_" + name,
              s.avail_steps ? static_cast<double>(s.unavailable_by_reason[r]) / static_cast<double>(s.avail_steps) : NAN);
  }
  json->add(D + "_track_err_m_median", s.track_err_median_m);
  json->add(D + "_track_err_m_p95", s.track_err_p95_m);
  json->add(D + "_step_ms_p50", s.step_ms_p50);
  json->add(D + "_step_ms_p99", s.step_ms_p99);
  json->add_int(D + "_trials", static_cast<long long>(s.trials));
}

// MCL baseline: metres to the first fix on the first fix-trial starts, and mml-track's figure on the
// same starts (`fix`: its fix trials, in start order), so the two medians compare like with like.
bool run_mcl_baseline(LocalizeRun& run, const LoadedDataset& ds, const MetricBounds& b,
                      const std::vector<std::size_t>& starts, const TrialOptions& fopt,
                      const std::vector<TrialResult>& fix, std::string* err) {
  const LocalizePlan& plan = run.plan;
  std::string e;
  auto mcl = OwnedLocalizer::make_mcl(ds.map, mcl_baseline_options(plan.mcl_particles, plan.seed), plan.threads, &e);
  if (!mcl) return (*err = ds.name + ": mcl: " + e, false);
  std::vector<TrialResult> mt;
  const std::string label = "mcl-" + std::to_string(plan.mcl_particles / 1000) + "k";
  for (std::size_t k = 0; k < std::min(plan.mcl_trials, starts.size()); ++k) {
    const auto tk = std::chrono::steady_clock::now();
    mt.push_back(run_trial(*mcl, ds, starts[k], fopt));
    if (plan.verbose) progress(ds, label, k, std::min(plan.mcl_trials, starts.size()), mt.back(), b, seconds_since(tk));
  }
  SystemSummary ms = summarize(ds.name, label, mt, mcl->static_bytes() / (1024.0 * 1024.0), b);
  run.rows.push_back(ms);
  run.json->add(ds.key + "_mcl_m_to_fix_median", ms.m_to_fix_median);
  run.json->add(ds.key + "_mcl_first_fix_success", ms.first_fix_success);
  const std::vector<TrialResult> same(fix.begin(), fix.begin() + static_cast<std::ptrdiff_t>(std::min(mt.size(), fix.size())));
  const SystemSummary paired = summarize(ds.name, "mml-track", same, 0.0, b);
  run.json->add(ds.key + "_m_to_fix_median_mcl_starts", paired.m_to_fix_median);
  run.json->add(ds.key + "_first_fix_success_mcl_starts", paired.first_fix_success);
  // Start by start, for the report: metres to the first fix and whether it was right.
  auto fix_text = [&](const TrialResult& t) {
    const TrialMetrics m = trial_metrics(t, b);
    char buf[64];
    if (!m.first_fix) std::snprintf(buf, sizeof buf, "none");
    else std::snprintf(buf, sizeof buf, "%.1f m%s", m.m_to_fix, m.first_fix_success ? "" : " WRONG");
    return std::string(buf);
  };
  char head[256];
  std::snprintf(head, sizeof head, "- %s: mml-track %.2f m (%zu/%zu right) vs %s %.2f m (%zu/%zu right); per start",
                ds.name.c_str(), paired.m_to_fix_median, paired.first_fix_successes, same.size(), label.c_str(),
                ms.m_to_fix_median, ms.first_fix_successes, mt.size());
  run.mclnotes << head << " (scan: mml-track | " << label << "):";
  for (std::size_t k = 0; k < same.size(); ++k)
    run.mclnotes << (k ? "," : "") << " " << starts[k] << ": " << fix_text(same[k]) << " | " << fix_text(mt[k]);
  run.mclnotes << "\n";
  return true;
}

// Kidnaps: a fix, then carried to a random scan at least kidnap_min_dist_m away.
void run_kidnaps(LocalizeRun& run, const LoadedDataset& ds, OwnedLocalizer& loc, const MetricBounds& b) {
  const LocalizePlan& plan = run.plan;
  TrialOptions kopt = plan.step_rule;
  kopt.kidnap_after_fix_steps = plan.kidnap_after_fix;
  kopt.kidnap_at_step = plan.kidnap_latest_step;
  kopt.kidnap_steps_after = plan.kidnap_steps_after;
  kopt.max_steps = 0;
  TrialOptions sopt = kopt;
  sopt.max_steps = plan.kidnap_latest_step + plan.kidnap_steps_after;
  const std::vector<std::size_t> kstarts = draw_starts(ds, plan.kidnap_runs, plan.seed + 7, sopt);
  fw::RandomStream krng(plan.seed, 733);
  // Targets: a random scan at least kidnap_min_dist_m from the robot's true position, with room
  // for kidnap_steps_after steps of log after it.
  const double need = static_cast<double>(plan.kidnap_steps_after) * plan.step_rule.min_move_m * 0.5;
  std::size_t last = 0;
  for (std::size_t i = 0; i < ds.travelled.size(); ++i)
    if (ds.travelled[i] <= ds.travelled.back() - need) last = i;
  kopt.kidnap_target = [&](std::size_t from) -> std::size_t {
    for (int attempt = 0; attempt < 200; ++attempt) {
      const std::size_t j = krng.uniform_index(static_cast<std::uint32_t>(std::max<std::size_t>(last, 1)));
      const fw::Se2d& a = ds.reference[from];
      const fw::Se2d& c = ds.reference[j];
      if (std::hypot(a.x - c.x, a.y - c.y) >= plan.kidnap_min_dist_m) return j;
    }
    return krng.uniform_index(static_cast<std::uint32_t>(std::max<std::size_t>(last, 1)));
  };
  std::vector<TrialResult> kt;
  for (std::size_t k = 0; k < kstarts.size(); ++k) {
    const auto tk = std::chrono::steady_clock::now();
    kt.push_back(run_trial(loc, ds, kstarts[k], kopt));
    if (plan.verbose) progress(ds, "kidnap", k, kstarts.size(), kt.back(), run.kidnap_bounds, seconds_since(tk));
    describe_failures(ds, "kidnap", k, kt.back(), b, &run.notes, plan.verbose);
    describe_pl_exceedances(ds, "kidnap", k, kt.back(), &run.plnotes);
  }
  SystemSummary ks = summarize(ds.name, "mml-track kidnap", kt, 0, b);
  run.rows.push_back(ks);
  run.json->add(ds.key + "_kidnap_refix_success", ks.kidnap_refix_success);
  run.json->add_int(ds.key + "_kidnap_integrity_failures", static_cast<long long>(ks.kidnap_integrity_failures));
  write_plots(plan, ds, "mml-track_kidnap", kt, nullptr);
  run.kidnap_all.insert(run.kidnap_all.end(), kt.begin(), kt.end());
}

// The reference's own motion where the wheels report rest (reference_rest_scatter.h): shown beside
// the PL exceedance, never used to clear a step. Not for synthesised odometry (made from the
// reference itself, so it rests exactly when the reference does).
void add_rest_scatter(LocalizeRun& run, const LoadedDataset& ds) {
  if (ds.synthetic_odometry) return;
  const RestScatter r = reference_rest_scatter(ds.reference, ds.odometry);
  char buf[400];
  std::snprintf(buf, sizeof(buf),
                "%s: reference at rest: %zu scan pairs where the wheels report no motion; the reference moves between "
                "them p50 %.3f m / %.2f deg, p99 %.3f m / %.2f deg (its own per-scan error; a PL exceedance smaller "
                "than that cannot be told from the reference's)",
                ds.name.c_str(), r.pairs, r.m_p50, r.rad_p50 * 57.29578, r.m_p99, r.rad_p99 * 57.29578);
  run.refnotes << "- " << buf << "\n";
  if (run.plan.verbose) std::printf("  %s\n", buf);
  run.json->add_int(ds.key + "_ref_rest_pairs", static_cast<long long>(r.pairs));
  run.json->add(ds.key + "_ref_rest_scatter_m_p99", r.m_p99);
  run.json->add(ds.key + "_ref_rest_scatter_deg_p99", r.rad_p99 * 57.29578);
}

// One dataset (built-in or given by path): whole logs, fix trials, MCL, kidnaps.
bool evaluate_dataset(LocalizeRun& run, const std::string& name, const DatasetFiles* files, std::string* err) {
  const LocalizePlan& plan = run.plan;
  BenchJson* json = run.json;
  const auto t0 = std::chrono::steady_clock::now();
  LoadedDataset ds;
  if (files ? !load_dataset_files(*files, &ds, err) : !load_dataset(name, &ds, err)) return false;
  if (plan.verbose) {
    std::printf("dataset %s: %zu scans, %.0f m of path, map %ux%u @ %.2f m, reference: %s%s (loaded in %.1f s)\n  %s\n",
                ds.name.c_str(), ds.log.scans.size(), ds.travelled.back(), ds.map.geometry.width,
                ds.map.geometry.height, ds.map.geometry.resolution, ds.reference_note.c_str(),
                ds.synthetic_odometry ? " [synthetic odometry]" : "", seconds_since(t0), ds.ref_check_note.c_str());
    std::fflush(stdout);
  }
  run.refnotes << "- " << ds.name << ": " << ds.ref_check_note << "\n";
  json->add_int(ds.key + "_ref_excluded_scans", static_cast<long long>(ds.ref_excluded_scans));
  add_rest_scatter(run, ds);
  const MetricBounds b = bounds_for(ds);
  std::string e;
  auto loc = OwnedLocalizer::make_track(ds.map, ds.image, run.mml_cfg, plan.track, plan.threads, &e);
  if (!loc) return (*err = ds.name + ": mml-track: " + e, false);

  std::vector<TrialResult> all;  // every mml-track trial on this dataset (whole + fix)
  run_whole_logs(run, ds, *loc, b, &all);
  const std::size_t nfix = count_for(plan.fix_trials_override, ds.name, plan.fix_trials);
  TrialOptions fopt = plan.step_rule;
  fopt.max_steps = plan.fix_steps;
  const std::vector<std::size_t> starts = draw_starts(ds, nfix, plan.seed, fopt);
  std::vector<TrialResult> fix;  // the fix trials alone, in start order (the MCL comparison's)
  run_fix_trials(run, ds, *loc, b, starts, fopt, &all, &fix);
  SystemSummary s = summarize(ds.name, "mml-track", all, loc->static_bytes() / (1024.0 * 1024.0), b);
  run.rows.push_back(s);
  std::vector<double> track_ms, sensor_ms, global_ms;
  for (const auto& t : all)
    for (const auto& st : t.steps) {
      if (st.global_ms > 0.0) global_ms.push_back(st.global_ms);  // a global step ran on this scan
      if (st.mode == hal::LocalizationMode::kTracking) {
        track_ms.push_back(st.step_ms);
        sensor_ms.push_back(st.step_ms - st.global_ms);
      }
    }
  run.track_ms_all.insert(run.track_ms_all.end(), track_ms.begin(), track_ms.end());
  run.track_sensor_ms_all.insert(run.track_sensor_ms_all.end(), sensor_ms.begin(), sensor_ms.end());
  add_dataset_figures(json, ds.key, s);
  json->add(ds.key + "_track_step_ms_p50", percentile(track_ms, 50));
  json->add(ds.key + "_track_step_ms_p99", percentile(track_ms, 99));
  json->add(ds.key + "_track_sensor_step_ms_p50", percentile(sensor_ms, 50));
  json->add(ds.key + "_track_sensor_step_ms_p99", percentile(sensor_ms, 99));
  // MML's global steps themselves (inline, GlobalContext's timer; issue 58: p99 ≤ 100 ms).
  json->add(ds.key + "_global_step_ms_p50", percentile(global_ms, 50));
  json->add(ds.key + "_global_step_ms_p99", percentile(global_ms, 99));
  json->add(ds.key + "_global_step_ms_max", percentile(global_ms, 100));

  if (std::find(plan.mcl_datasets.begin(), plan.mcl_datasets.end(), ds.name) != plan.mcl_datasets.end() &&
      plan.mcl_trials > 0) {
    if (!run_mcl_baseline(run, ds, b, starts, fopt, fix, err)) return false;
  }
  if (std::find(plan.kidnap_datasets.begin(), plan.kidnap_datasets.end(), ds.name) != plan.kidnap_datasets.end() &&
      plan.kidnap_runs > 0) {
    run_kidnaps(run, ds, *loc, b);
  }
  if (plan.verbose) {
    std::printf("dataset %s done in %.1f s (total %.1f s)\n", ds.name.c_str(), seconds_since(t0), seconds_since(run.t_all));
    std::fflush(stdout);
  }
  return true;
}

// Unknown area: as mml_eval_run.cpp (same region and starts), with mml-track.
bool run_unknown_area(LocalizeRun& run, std::string* err) {
  const LocalizePlan& plan = run.plan;
  BenchJson* json = run.json;
  const auto t0 = std::chrono::steady_clock::now();
  UnknownArea ua;
  if (!prepare_unknown_area(plan.unknown_dataset, plan.seed, plan.unknown_trials, &ua, err)) return false;
  const auto& [ds, region, starts] = ua;
  std::string e;
  auto loc = OwnedLocalizer::make_track(ds.map, ds.image, run.mml_cfg, plan.track, plan.threads, &e);
  if (!loc) return (*err = "unknown area: mml-track: " + e, false);
  TrialOptions uo = plan.step_rule;
  uo.max_steps = plan.unknown_steps;
  const MetricBounds b = bounds_for(ds);
  std::vector<TrialResult> ut;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    const auto tk = std::chrono::steady_clock::now();
    ut.push_back(run_trial(*loc, ds, starts[k], uo, region));
    if (plan.verbose) progress(ds, "unknown-area", k, starts.size(), ut.back(), b, seconds_since(tk));
    describe_failures(ds, "unknown-area", k, ut.back(), b, &run.notes, plan.verbose);
    describe_pl_exceedances(ds, "unknown-area", k, ut.back(), &run.plnotes);
  }
  SystemSummary us = summarize(ds.name + "-erased", "mml-track", ut, 0, b);
  run.rows.push_back(us);
  std::size_t in_region = 0, in_region_loc = 0, in_region_wrong = 0;
  for (const auto& t : ut)
    for (const auto& st : t.steps) {
      if (!st.in_region) continue;
      ++in_region;
      if (st.status == hal::LocalizationStatus::kLocalized) {
        ++in_region_loc;
        in_region_wrong += std::isfinite(st.err_m) && (st.err_m > b.bound_m || st.err_rad > b.bound_rad);
      }
    }
  json->add_int("unknown_area_integrity_failures", static_cast<long long>(us.integrity_failures));
  json->add_int("unknown_area_in_region_steps", static_cast<long long>(in_region));
  json->add("unknown_area_in_region_localized_fraction",
            in_region ? static_cast<double>(in_region_loc) / in_region : NAN);
  json->add("unknown_area_availability_outside_region", us.availability);
  // How often the robot in the erased region is told it is outside the map, and how often it is told
  // so elsewhere (outside the region, where the map covers the reference's scan).
  json->add("unknown_area_in_region_outside_map_fraction", us.outside_map_in_region);
  json->add_int("unknown_area_outside_map_false_steps", static_cast<long long>(us.outside_map_false_steps));
  write_plots(plan, ds, "mml-track_unknown", ut, region);
  if (plan.verbose)
    std::printf("unknown area (%s, 8 x 8 m erased): %zu in-region steps, %zu localized there (%zu wrong), %.3f of them "
                "outside-map; %zu outside-map steps elsewhere; integrity failures %zu; done in %.1f s\n",
                ds.name.c_str(), in_region, in_region_loc, in_region_wrong, us.outside_map_in_region,
                us.outside_map_false_steps, us.integrity_failures, seconds_since(t0));
  return true;
}

// Where the availability went, per row: the reason published with each step after the first fix
// that was not `localized`, as a share of the availability steps, largest first.
std::string unavailability_text(const std::vector<SystemSummary>& rows) {
  std::ostringstream t;
  for (const SystemSummary& s : rows) {
    if (s.avail_steps == 0) continue;
    const std::string why = reason_list(s.unavailable_by_reason, s.avail_steps);
    t << "- " << s.dataset << " (" << s.system << ", " << s.avail_steps << " steps): "
      << (why.empty() ? "always localized" : why);
    if (s.unmapped_steps > 0) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "; %zu steps in unmapped areas left out (%zu of them localized; availability %.3f with them)",
                    s.unmapped_steps, s.unmapped_localized, s.availability_with_unmapped);
      t << buf;
    }
    if (s.off_map_steps > 0) {
      char buf[200];
      std::snprintf(buf, sizeof buf, "; at %zu steps (%.4f) the map explains less than half of the scan at the reference (%zu localized there)",
                    s.off_map_steps, static_cast<double>(s.off_map_steps) / static_cast<double>(s.avail_steps), s.off_map_localized);
      t << buf;
    }
    t << "\n";
  }
  return t.str();
}

// localize.md: the table, the reference notes and the integrity failures.
void write_localize_report(LocalizeRun& run) {
  const LocalizePlan& plan = run.plan;
  const std::string table = product_markdown_table(run.rows);
  const std::string unavailable = unavailability_text(run.rows);
  std::ofstream md(plan.out_dir + "/localize.md");
  md << "# Localizer (mml-track) product evaluation\n\nSeed " << plan.seed << "; per dataset " << plan.whole_runs
     << " whole-log runs (kidnapped start drawn over the first " << plan.whole_start_fraction * 100
     << " % of the path, to the end of the log, every scan) + " << plan.fix_trials << " kidnapped-start trials of "
     << plan.fix_steps << " steps (overrides: see the bench source) where a step is a scan after >= "
     << plan.step_rule.min_move_m << " m or >= " << plan.step_rule.min_turn_rad
     << " rad of odometry motion. Bounds: dataset position bound (0.5 m; 1 m at mit-killian) and 5 deg. "
        "Definitions: sim/eval/mml_eval/README.md.\n\n"
     << table << "\n## Where the availability went (share of the steps after the first fix, by the reason published)\n\n"
     << unavailable << "\n## Reference quality\n\n" << run.refnotes.str() << "\n## Integrity failures\n\n"
     << (run.notes.str().empty() ? std::string("none\n") : run.notes.str())
     << "\n## Protection-level exceedances (judged; compare with the reference's scatter at rest above)\n\n"
     << (run.plnotes.str().empty() ? std::string("none\n") : run.plnotes.str())
     << "\n## First fix against MCL on the same starts (median metres to the first right fix; a wrong or "
        "missing fix counts as never)\n\n"
     << (run.mclnotes.str().empty() ? std::string("not run\n") : run.mclnotes.str());
  if (plan.verbose)
    std::printf("\n%s\nnot localized after the first fix, by reason:\n%sreference:\n%s\ntotal %.1f s\n", table.c_str(),
                unavailable.c_str(), run.refnotes.str().c_str(), seconds_since(run.t_all));
}

}  // namespace

bool run_localize_evaluation(const LocalizePlan& plan, BenchJson* json, std::string* err) {
  LocalizeRun run{plan, json, std::chrono::steady_clock::now(), {}, {}, {}, {}, {}, {}, {}, {}, {},
                  mml_track_config(plan.mml_config, plan.seed)};
  run.mml_cfg.mml.pool_cluster_support = plan.pool_cluster_support;
  if (!plan.unmapped_space) run.mml_cfg.mml.unmapped_space_min_area_m2 = 0.0f;
  run.mml_cfg.mml.keep_support_across_empty_steps = plan.keep_support_across_empty_steps;
  run.mml_cfg.mml.keep_support_across_contested_steps = plan.keep_support_across_contested_steps;
  std::filesystem::create_directories(plan.out_dir);
  json->add_int("seed", static_cast<long long>(plan.seed));
  json->add_int("whole_runs_per_dataset", static_cast<long long>(plan.whole_runs));
  json->add_int("fix_trials_per_dataset", static_cast<long long>(plan.fix_trials));
  json->add_int("fix_steps", static_cast<long long>(plan.fix_steps));
  for (const auto& n : plan.datasets)
    if (!evaluate_dataset(run, n, nullptr, err)) return false;
  for (const auto& f : plan.custom)
    if (!evaluate_dataset(run, f.name, &f, err)) return false;
  if (!run.kidnap_all.empty()) {
    SystemSummary ks = summarize("all", "mml-track kidnap", run.kidnap_all, 0, run.kidnap_bounds);
    json->add("kidnap_refix_success", ks.kidnap_refix_success);
    json->add_int("kidnap_integrity_failures", static_cast<long long>(ks.kidnap_integrity_failures));
    json->add_int("kidnap_runs", static_cast<long long>(ks.kidnaps));
    json->add("kidnap_detected_rate", ks.kidnaps ? static_cast<double>(ks.kidnaps_detected) / ks.kidnaps : NAN);
    json->add("kidnap_delay_steps_median", ks.kidnap_delay_median);
    json->add("kidnap_refix_m_median", ks.kidnap_refix_m_median);
  }
  if (plan.run_unknown && !run_unknown_area(run, err)) return false;
  json->add("track_step_ms_p50", percentile(run.track_ms_all, 50));
  json->add("track_step_ms_p99", percentile(run.track_ms_all, 99));
  json->add("track_sensor_step_ms_p50", percentile(run.track_sensor_ms_all, 50));
  json->add("track_sensor_step_ms_p99", percentile(run.track_sensor_ms_all, 99));
  json->add("localize_eval_seconds", seconds_since(run.t_all));
  write_localize_report(run);
  return true;
}

}  // namespace sim::mmleval
