#include "sim/eval/mml_eval/mml_eval_run.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>

#include "firmware/base/rng.h"
#include "sim/common/stopwatch.h"
#include "sim/eval/mml_eval/mml_systems.h"

namespace sim::mmleval {

namespace {

struct SystemRun {
  std::string label;
  std::vector<TrialResult> trials;
  SystemSummary summary;
};

SystemRun run_system(OwnedLocalizer& loc, const LoadedDataset& ds, const std::string& label,
                     const std::vector<std::size_t>& starts, const TrialOptions& opt, bool verbose,
                     const double* region = nullptr) {
  SystemRun r;
  r.label = label;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t k = 0; k < starts.size(); ++k) {
    std::function<std::size_t()> probe;
    if (loc.mml() != nullptr && loc.handoff() == nullptr) probe = [&loc] { return loc.mml()->matched_points(); };
    r.trials.push_back(run_trial(loc, ds, starts[k], opt, region, probe));
    const TrialResult& t = r.trials.back();
    if (verbose && t.localized) {
      std::printf("  %-12s %-10s trial %zu start %5zu: localized%s after %.1f m (%zu steps), err %.2f m%s%s\n", ds.name.c_str(),
                  label.c_str(), k, t.start, t.failure ? " [FAILURE]" : "", t.metres_to_localize, t.steps_to_localize,
                  t.mean_err_localized, t.error.empty() ? "" : " error: ", t.error.c_str());
    } else if (verbose) {
      std::printf("  %-12s %-10s trial %zu start %5zu: not localized in %zu steps%s%s\n", ds.name.c_str(), label.c_str(), k,
                  t.start, t.steps.size(), t.error.empty() ? "" : " error: ", t.error.c_str());
      std::fflush(stdout);
    }
  }
  r.summary = summarize(ds.name, label, r.trials, loc.static_bytes() / (1024.0 * 1024.0));
  if (verbose) std::printf("  %-12s %-10s done in %.1f s\n", ds.name.c_str(), label.c_str(), seconds_since(t0));
  return r;
}

// Configuration C`config` with the plan's local map options (plus `correct` / `reduce`).
struct MmlVariant {
  std::string label;
  fw::mml::MmlLocalizerConfig cfg;
};
MmlVariant mml_variant(const EvalPlan& plan, int config, bool correct, bool reduce) {
  MmlVariant v;
  v.cfg = mml_config(config, plan.seed);
  v.cfg.mml.correct_local_map = correct || plan.mml_correct;
  v.cfg.mml.reduce_observations = reduce || plan.mml_reduce;
  v.cfg.mml.unique_check = plan.mml_unique;
  v.label = "mml-C" + std::to_string(config);
  if (v.cfg.mml.correct_local_map) v.label += "+corr";
  if (v.cfg.mml.reduce_observations) v.label += "+red";
  return v;
}

void add_pair(BenchJson* json, const std::string& key, const std::string& sys, const SystemSummary& s) {
  json->add(key + "_" + sys + "_failure_rate", s.failure_rate);
  json->add(key + "_" + sys + "_success_rate", s.success_rate);
  json->add(key + "_" + sys + "_m_to_localize", s.m_to_localize_median);
  json->add(key + "_" + sys + "_step_ms_p99", s.step_ms_p99);
  json->add(key + "_" + sys + "_step_ms_p50", s.step_ms_p50);
  json->add(key + "_" + sys + "_mean_err_m", s.mean_err_m);
  json->add_int(key + "_" + sys + "_trials", static_cast<long long>(s.trials));
  json->add_int(key + "_" + sys + "_localized", static_cast<long long>(s.localized));
}

// State of one evaluation shared by its steps.
struct EvalRun {
  const EvalPlan& plan;
  BenchJson* json;
  std::vector<SystemSummary> rows;
  double static_mib = 0;
  std::vector<double> track_err, track_ms;  // hand-off tracking steps
};

// MML: the main configuration, then the extra ones side by side. Returns the main one's summary.
bool run_mml_configs(EvalRun& run, const LoadedDataset& ds, const std::vector<std::size_t>& starts,
                     const TrialOptions& topt, std::vector<SystemRun>* runs, SystemSummary* mml_main, std::string* err) {
  const EvalPlan& plan = run.plan;
  std::vector<MmlVariant> configs = {mml_variant(plan, plan.mml_config, false, false)};
  for (int c : plan.extra_mml_configs)
    if (c != plan.mml_config) configs.push_back(mml_variant(plan, c, false, false));
  if (plan.compare_local_map_options) {
    if (!plan.mml_correct) configs.push_back(mml_variant(plan, plan.mml_config, true, false));
    if (!plan.mml_reduce) configs.push_back(mml_variant(plan, plan.mml_config, false, true));
  }
  for (std::size_t ci = 0; ci < configs.size(); ++ci) {
    std::string e;
    const auto ti = std::chrono::steady_clock::now();
    auto loc = OwnedLocalizer::make_mml(ds.map, ds.image, configs[ci].cfg, plan.threads, &e);
    if (!loc) return (*err = e, false);
    if (plan.verbose) {
      std::printf("  %s init %.1f s (precomputed table: %s)\n", configs[ci].label.c_str(), seconds_since(ti),
                  loc->mml()->using_precomputed_table() ? "yes" : "no");
    }
    SystemRun r = run_system(*loc, ds, configs[ci].label, starts, topt, plan.verbose);
    if (plan.verbose) {
      std::printf("  %-12s %-10s matched points per step %.0f, corrections %u, observations accepted %u (last trial)\n",
                  ds.name.c_str(), configs[ci].label.c_str(), r.summary.matched_points_mean,
                  loc->mml()->corrections_applied(), loc->mml()->observations_accepted());
    }
    if (ci > 0 && (configs[ci].cfg.mml.correct_local_map || configs[ci].cfg.mml.reduce_observations)) {
      std::string key = "mml_c" + std::to_string(plan.mml_config);
      if (configs[ci].cfg.mml.correct_local_map) key += "_corr";
      if (configs[ci].cfg.mml.reduce_observations) key += "_red";
      add_pair(run.json, ds.key, key, r.summary);
      run.json->add(ds.key + "_" + key + "_matched_points_mean", r.summary.matched_points_mean);
    }
    if (ci == 0) {
      *mml_main = r.summary;
      run.static_mib = std::max(run.static_mib, r.summary.memory_mib + ds.arena->used() / (1024.0 * 1024.0));
    }
    run.rows.push_back(r.summary);
    runs->push_back(std::move(r));
  }
  return true;
}

// MCL baseline on the same starts (fewer trials where the plan says so).
bool run_mcl(EvalRun& run, const LoadedDataset& ds, bool mit, const std::vector<std::size_t>& starts,
             const TrialOptions& topt, std::vector<SystemRun>* runs, SystemSummary* mcl_main, std::string* err) {
  const EvalPlan& plan = run.plan;
  std::string e;
  const std::uint32_t particles = mit ? plan.mcl_particles_mit : plan.mcl_particles;
  auto loc = OwnedLocalizer::make_mcl(ds.map, mcl_baseline_options(particles, plan.seed), plan.threads, &e);
  if (!loc) return (*err = e, false);
  std::vector<std::size_t> mstarts = starts;
  const std::size_t mt = (mit && plan.mcl_trials_mit) ? plan.mcl_trials_mit : plan.mcl_trials;
  if (mt && mt < mstarts.size()) mstarts.resize(mt);
  SystemRun r = run_system(*loc, ds, "mcl-" + std::to_string(particles / 1000) + "k", mstarts, topt, plan.verbose);
  *mcl_main = r.summary;
  run.rows.push_back(r.summary);
  runs->push_back(std::move(r));
  return true;
}

// MML → MCL hand-off, with its tracking error and step time.
bool run_handoff(EvalRun& run, const LoadedDataset& ds, const std::vector<std::size_t>& starts,
                 const TrialOptions& topt, std::vector<SystemRun>* runs, std::string* err) {
  const EvalPlan& plan = run.plan;
  std::string e;
  auto loc = OwnedLocalizer::make_handoff(ds.map, ds.image, mml_variant(plan, plan.mml_config, false, false).cfg,
                                          mcl_tracking_options(plan.seed), fw::mml::HandoffOptions(), plan.threads, &e);
  if (!loc) return (*err = e, false);
  TrialOptions ho = topt;
  ho.max_steps = topt.max_steps + 100;  // leave time to track after the hand-off
  SystemRun r = run_system(*loc, ds, "handoff", starts, ho, plan.verbose);
  for (const auto& t : r.trials)
    for (const auto& s : t.steps)
      if (s.mode == hal::LocalizationMode::kTracking && std::isfinite(s.err_m) && s.ref_ok) {
        run.track_err.push_back(s.err_m);
        run.track_ms.push_back(s.step_ms);
      }
  if (plan.verbose) {
    std::printf("  %-12s handoff    tracking median err %.3f m, step p50 %.3f ms, p99 %.3f ms, fallbacks %u\n",
                ds.name.c_str(), r.summary.tracking_err_median_m, r.summary.tracking_step_ms_p50,
                r.summary.tracking_step_ms_p99, loc->handoff()->fallbacks());
  }
  run.rows.push_back(r.summary);
  runs->push_back(std::move(r));
  return true;
}

// Error-over-metres and map pictures of every system run on a dataset.
bool write_run_plots(const EvalPlan& plan, const LoadedDataset& ds, const std::vector<SystemRun>& runs,
                     std::string* err) {
  for (const auto& r : runs) {
    const std::string base = plan.out_dir + "/" + ds.key + "_" + r.label;
    std::string e;
    if (!write_error_plot(base + "_error.svg", ds.name + " - " + r.label + ": error over metres (kidnapped starts)",
                          r.trials, ds.success_bound_m, &e) ||
        !write_map_plot(base + "_map.svg", base + "_map.png", ds, ds.name + " - " + r.label, r.trials, nullptr, &e)) {
      return (*err = e, false);
    }
  }
  return true;
}

// One dataset: MML configurations, MCL, hand-off, figures and pictures.
bool evaluate_dataset(EvalRun& run, const std::string& name, std::string* err) {
  const EvalPlan& plan = run.plan;
  const auto t0 = std::chrono::steady_clock::now();
  LoadedDataset ds;
  if (!load_dataset(name, &ds, err)) return false;
  if (plan.verbose) {
    std::printf("dataset %s: %zu scans, %.0f m of path, map %ux%u @ %.2f m, %u points (loaded in %.1f s)\n",
                name.c_str(), ds.log.scans.size(), ds.travelled.back(), ds.map.geometry.width, ds.map.geometry.height,
                ds.map.geometry.resolution, ds.map.num_points, seconds_since(t0));
  }
  const bool mit = name == "mit-killian";
  const TrialOptions& topt = mit ? plan.trial_mit : plan.trial;
  const std::vector<std::size_t> starts = draw_starts(ds, plan.trials, plan.seed, topt);
  std::vector<SystemRun> runs;
  SystemSummary mml_main, mcl_main;
  if (!run_mml_configs(run, ds, starts, topt, &runs, &mml_main, err)) return false;
  if (plan.run_mcl && !run_mcl(run, ds, mit, starts, topt, &runs, &mcl_main, err)) return false;
  if (plan.run_handoff &&
      std::find(plan.handoff_datasets.begin(), plan.handoff_datasets.end(), name) != plan.handoff_datasets.end() &&
      !run_handoff(run, ds, starts, topt, &runs, err)) {
    return false;
  }
  add_pair(run.json, ds.key, "mml", mml_main);
  add_pair(run.json, ds.key, "mcl", mcl_main);
  if (mit) {
    run.json->add("mit_killian_mml_speedup_vs_mcl", mcl_main.step_ms_mean / mml_main.step_ms_mean);
    run.json->add("mit_killian_mml_speedup_vs_mcl_p50", mcl_main.step_ms_p50 / mml_main.step_ms_p50);
  }
  if (!write_run_plots(plan, ds, runs, err)) return false;
  if (plan.verbose) std::printf("dataset %s done in %.1f s\n", name.c_str(), seconds_since(t0));
  return true;
}

// Unknown area: a region around a mid-log pose is erased from the map; trials start 8–30 m
// before it, so the robot can localize first and then drive through the erased part.
bool run_unknown_area(EvalRun& run, std::string* err) {
  const EvalPlan& plan = run.plan;
  BenchJson* json = run.json;
  const auto t0 = std::chrono::steady_clock::now();
  UnknownArea ua;
  if (!prepare_unknown_area(plan.unknown_dataset, plan.seed, plan.unknown_trials, &ua, err)) return false;
  const auto& [ds, region, starts] = ua;
  TrialOptions uo = plan.trial;
  uo.max_steps = plan.trial.max_steps + 60;
  std::string e;
  auto mml = OwnedLocalizer::make_mml(ds.map, ds.image, mml_variant(plan, plan.mml_config, false, false).cfg, plan.threads, &e);
  if (!mml) return (*err = e, false);
  SystemRun rm = run_system(*mml, ds, "mml-unknown", starts, uo, plan.verbose, region);
  auto mcl = OwnedLocalizer::make_mcl(ds.map, mcl_baseline_options(plan.mcl_particles, plan.seed), plan.threads, &e);
  if (!mcl) return (*err = e, false);
  SystemRun rc2 = run_system(*mcl, ds, "mcl-unknown", starts, uo, plan.verbose, region);
  json->add("unknown_area_mml_failure_rate", rm.summary.failure_rate);
  json->add("unknown_area_mcl_failure_rate", rc2.summary.failure_rate);
  json->add("unknown_area_mml_outside_map_fraction", rm.summary.outside_map_in_region);
  json->add("unknown_area_mcl_success_rate", rc2.summary.success_rate);
  json->add_int("unknown_area_trials", static_cast<long long>(starts.size()));
  run.rows.push_back(rm.summary);
  run.rows.push_back(rc2.summary);
  for (const SystemRun* r : {&rm, &rc2}) {
    const std::string base = plan.out_dir + "/unknown_" + ds.key + "_" + r->label;
    if (!write_error_plot(base + "_error.svg", ds.name + " with an erased region - " + r->label, r->trials,
                          ds.success_bound_m, &e) ||
        !write_map_plot(base + "_map.svg", base + "_map.png", ds, ds.name + " with an erased region - " + r->label,
                        r->trials, region, &e)) {
      return (*err = e, false);
    }
  }
  if (plan.verbose) std::printf("unknown area done in %.1f s\n", seconds_since(t0));
  return true;
}

// summary.md: the plan and the table.
void write_summary(const EvalRun& run) {
  const EvalPlan& plan = run.plan;
  std::ofstream md(plan.out_dir + "/summary.md");
  md << "# MML evaluation\n\nKidnapped starts drawn with seed " << plan.seed << "; " << plan.trials
     << " trials per dataset (MCL: " << (plan.mcl_trials ? plan.mcl_trials : plan.trials) << "), at most "
     << plan.trial.max_steps << " steps per trial (mit-killian: " << plan.trial_mit.max_steps
     << "); a step is a scan after ≥ " << plan.trial.min_move_m << " m or ≥ " << plan.trial.min_turn_rad
     << " rad of odometry motion. Success: first `localized` within 0.5 m / 20° (1 m at mit-killian) and never "
        "beyond; failure: any `localized` estimate beyond the bound. Step times are wall-clock on this machine ("
     << plan.threads << " threads).\n\n";
  md << markdown_table(run.rows) << "\n";
  md << "Plots: `<dataset>_<system>_error.svg` (error over metres, coloured by status) and `_map.svg/.png`.\n";
}

}  // namespace

bool run_evaluation(const EvalPlan& plan, BenchJson* json, std::string* err) {
  std::filesystem::create_directories(plan.out_dir);
  EvalRun run{plan, json, {}, 0, {}, {}};
  json->add_int("trials_per_dataset", static_cast<long long>(plan.trials));
  json->add_int("mcl_trials_per_dataset", static_cast<long long>(plan.mcl_trials ? plan.mcl_trials : plan.trials));
  json->add_int("max_steps_per_trial", static_cast<long long>(plan.trial.max_steps));
  json->add_int("seed", static_cast<long long>(plan.seed));
  for (const std::string& name : plan.datasets)
    if (!evaluate_dataset(run, name, err)) return false;
  if (plan.run_unknown && !run_unknown_area(run, err)) return false;
  json->add("handoff_tracking_err_m", percentile(run.track_err, 50));
  json->add("handoff_step_ms_p50", percentile(run.track_ms, 50));
  json->add("handoff_step_ms_p99", percentile(run.track_ms, 99));
  json->add("static_memory_mib", run.static_mib);
  write_summary(run);
  return true;
}

}  // namespace sim::mmleval
