// Datasets of the product evaluation on the real logs (../shared/data, MMLFW_DATA_DIR): fr101 (only a
// corrected log: synthesised odometry, map from the corrected log), the reference-quality rule on
// intel, the path-based loader on intel's own files, and a short mml-track kidnap run on fr101.
#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <string>

#include "sim/eval/mml_eval/mml_eval.h"
#include "sim/eval/mml_eval/mml_systems.h"
#include "sim/io/datasets.h"

namespace sim::mmleval {
namespace {

bool data_available() {
  struct stat st;
  return stat(data_path("README.md").c_str(), &st) == 0;
}

#define REQUIRE_DATA()                                                                              \
  if (!data_available()) GTEST_SKIP() << "dataset folder not found: " << data_dir()                \
                                      << " (set MMLFW_DATA_DIR to ../shared/data)"

TEST(LocalizeData, Fr101SynthesisedOdometry) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("fr101", &ds, &err)) << err;
  EXPECT_TRUE(ds.synthetic_odometry);
  ASSERT_EQ(ds.log.scans.size(), 292u);
  ASSERT_EQ(ds.odometry.size(), ds.reference.size());
  // Increments close to the reference's (noise ~5 % of the motion), drift grows over the log.
  double worst = 0;
  for (std::size_t i = 1; i < ds.odometry.size(); ++i) {
    const fw::Se2d a = ds.odometry[i - 1].between(ds.odometry[i]), b = ds.reference[i - 1].between(ds.reference[i]);
    const double len = std::hypot(b.x, b.y);
    worst = std::max(worst, std::hypot(a.x - b.x, a.y - b.y) / (len + 0.05));
  }
  EXPECT_LT(worst, 0.5);
  EXPECT_GT(ds.map.num_points, 1000u);
}

TEST(LocalizeData, IntelReferenceExclusionIsReported) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("intel", &ds, &err)) << err;
  EXPECT_GT(ds.ref_excluded_scans, 0u);
  EXPECT_LT(ds.ref_excluded_scans, ds.log.scans.size() / 2);
  EXPECT_NE(ds.ref_check_note.find("scans excluded"), std::string::npos) << ds.ref_check_note;
}

TEST(LocalizeData, PathLoaderOnIntelFiles) {
  REQUIRE_DATA();
  LoadedDataset ref;
  std::string err;
  ASSERT_TRUE(load_dataset("intel", &ref, &err)) << err;  // builds / reads the cached map
  DatasetFiles f;
  f.name = "intel-by-path";
  f.log = data_path("intel/intel.clf.gz");
  f.map_yaml = ref.ros.yaml_path;
  f.reference = data_path("intel/intel.corrected-poses.txt");
  f.relations = data_path("intel/intel.relations");
  LoadedDataset ds;
  ASSERT_TRUE(load_dataset_files(f, &ds, &err)) << err;
  ASSERT_EQ(ds.reference.size(), ref.reference.size());
  EXPECT_EQ(ds.ref_excluded_scans, ref.ref_excluded_scans);
  EXPECT_DOUBLE_EQ(ds.reference[5000].x, ref.reference[5000].x);
  // Relations of another log: none match → a clear error.
  f.relations = data_path("aces/aces.relations");
  EXPECT_FALSE(load_dataset_files(f, &ds, &err));
  EXPECT_NE(err.find("aces.relations: no relation's timestamps"), std::string::npos) << err;
}

TEST(LocalizeData, Fr101KidnapRunKeepsOdometryContinuous) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("fr101", &ds, &err)) << err;
  auto loc = OwnedLocalizer::make_track(ds.map, ds.image, mml_track_config(3, 1), fw::track::TrackOptions(), 1, &err);
  ASSERT_TRUE(loc) << err;
  TrialOptions opt;
  opt.max_steps = 0;
  opt.kidnap_at_step = 60;
  opt.kidnap_to_scan = 200;
  opt.kidnap_steps_after = 60;
  const TrialResult t = run_trial(*loc, ds, 0, opt);
  ASSERT_EQ(t.kidnap_step, 60u);
  const fw::Se2d jump = t.steps[59].odom.between(t.steps[60].odom);
  const fw::Se2d logd = ds.odometry[200].between(ds.odometry[t.steps[60].scan]);
  EXPECT_NEAR(jump.x, logd.x, 1e-6);
  EXPECT_NEAR(jump.y, logd.y, 1e-6);
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_TRUE(m.kidnapped);
  for (const auto& s : t.steps)
    if (s.status == hal::LocalizationStatus::kSearching) EXPECT_TRUE(std::isnan(s.err_m));
}

// A carried trial of mml-track (MML config 3, seed 13): started at scan `start`, carried at step `at`
// to scan `target` (the dataset's stepping picks the first scan after it) and run `steps_after` steps
// there. Empty when the localizer cannot be built (reported as a failure).
// `unmapped_hypothesis` false: MML without the unmapped-space hypothesis before its first fix
// (firmware/map/unmapped_space.h), for a replay whose scenario is the carry after that fix.
TrialResult carried_trial(const LoadedDataset& ds, const fw::track::TrackOptions& to, std::size_t start, std::size_t at,
                          std::size_t target, std::size_t steps_after, bool unmapped_hypothesis = true) {
  std::string err;
  fw::mml::MmlLocalizerConfig cfg = mml_track_config(3, 13);
  if (!unmapped_hypothesis) cfg.mml.unmapped_space_min_area_m2 = 0.0f;
  auto loc = OwnedLocalizer::make_track(ds.map, ds.image, cfg, to, 1, &err);
  if (!loc) {
    ADD_FAILURE() << err;
    return TrialResult();
  }
  TrialOptions opt;
  opt.max_steps = 0;
  opt.kidnap_at_step = at;
  opt.kidnap_target = [target](std::size_t) { return target; };
  opt.kidnap_steps_after = steps_after;
  return run_trial(*loc, ds, start, opt);
}

// Steps from the carry on that are `localized` off by more than the integrity bounds (0.5 m, 5°).
std::size_t wrong_after_carry(const TrialResult& t) {
  std::size_t wrong = 0;
  for (std::size_t i = t.kidnap_step; i < t.steps.size(); ++i) {
    const StepLog& st = t.steps[i];
    if (st.status == hal::LocalizationStatus::kLocalized && (st.err_m > 0.5 || st.err_rad > 0.0873)) ++wrong;
  }
  return wrong;
}

// The carry of the 420-run kidnap stress that once ended `localized` 15 m off (intel, seed 13, trial 7:
// started at scan 4383, carried 60 steps after its first fix from scan 4658 to 6325, MML's fix confirmed on the
// scans before it): its first carried scan still fit the old place roughly and left the position open
// 0.5 m along both axes, and the PL leant on the odometry (TrackOptions::confidence_cap_needs_a_pinned_axis).
// With the rule no step after the carry is `localized` off by more than the bounds; without it, the
// same replay is the witness that the scenario still exercises the rule.
TEST(LocalizeData, IntelCarryWhoseFirstScanFitsTheOldPlaceIsNotLocalized) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("intel", &ds, &err)) << err;
  for (const bool rule : {true, false}) {
    fw::track::TrackOptions to;
    to.confirm_fix_on_past_scans = true;
    to.confidence_cap_needs_a_pinned_axis = rule;
    // Step 76: 60 steps after the first fix when MML's fix was confirmed on its own scan.
    const TrialResult t = carried_trial(ds, to, 4383, 76, 6325, 8);  // the first step after it: 6330
    ASSERT_EQ(t.kidnap_step, 76u);
    ASSERT_EQ(t.steps[76].scan, 6330u);
    ASSERT_EQ(t.steps[75].status, hal::LocalizationStatus::kLocalized) << "the track before the carry changed";
    const std::size_t wrong = wrong_after_carry(t);
    if (rule) EXPECT_EQ(wrong, 0u);
    else EXPECT_GE(wrong, 1u) << "the replay no longer reaches the carried scan that fits the old place";
  }
}

// A carry along a corridor whose first scan fits the old place a little worse (the kidnap stress of
// 2026-11-28): mit-killian, seed 13, started at scan 3605, carried 157–159 steps later from scans
// 3912–3916 to 3828, 11 m back along the same corridor, the wheels still. The first carried scan fit
// the old place worse (inliers 177 → 127 of 177, RMS 0.033 → 0.074 m, fit-drop z ≈ 2.7 < 3.09), its
// rival 1.8 m along the corridor was not credible (beyond the prediction's PL, not significantly
// better), and five unique scans later the track said `localized` 11.5 m off (7–8 steps), with
// forward confirmation and with MML's fix confirmed on past scans alike (the carry comes long after
// the fix). TrackOptions::alias_trust_needs_steady_fit: no step is wrong; without it (carried at step
// 158), the witness.
// One mit-killian carry replay (a whole start of 3605 scans, ~9 s in the release build): `rule`
// sets TrackOptions::alias_trust_needs_steady_fit; returns the steps `localized` beyond the bounds.
// The first fix is MML's without the unmapped-space hypothesis: with it (the default since issue
// 56) MML waits longer on this map — 13,000 m² of building interiors it never mapped — and the
// track is not yet `localized` 157 steps after the start; the carry, the scenario here, comes after
// the first fix, where the hypothesis is off anyway.
std::size_t mit_killian_carry_wrong_steps(const LoadedDataset& ds, bool rule, bool past_scans, std::size_t at) {
  fw::track::TrackOptions to;
  to.confirm_fix_on_past_scans = past_scans;
  to.alias_trust_needs_steady_fit = rule;
  const TrialResult t = carried_trial(ds, to, 3605, at, 3826, 40, /*unmapped_hypothesis=*/false);  // first after it: 3828
  EXPECT_EQ(t.steps[t.kidnap_step].scan, 3828u);
  EXPECT_EQ(t.steps[t.kidnap_step - 1].status, hal::LocalizationStatus::kLocalized)
      << "the track before the carry changed";
  return wrong_after_carry(t);
}

// The defaults, carried at step 158, with both ways of confirming the fix. The cases below (the
// neighbouring steps, and the witness without the rule) repeat the replay to judge the scenario,
// not memory safety: the sanitized build leaves them out (toolchain/project.cmake).
TEST(LocalizeData, MitKillianCarryAlongTheCorridorIsNotLocalized) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("mit-killian", &ds, &err)) << err;
  EXPECT_EQ(mit_killian_carry_wrong_steps(ds, true, false, 158), 0u) << "forward confirmation";
  EXPECT_EQ(mit_killian_carry_wrong_steps(ds, true, true, 158), 0u) << "fix confirmed on past scans";
}

TEST(LocalizeData, MitKillianCarryOneStepEarlierOrLaterIsNotLocalized) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("mit-killian", &ds, &err)) << err;
  for (const std::size_t at : {157u, 159u}) {
    EXPECT_EQ(mit_killian_carry_wrong_steps(ds, true, true, at), 0u) << "carried at step " << at;
  }
}

TEST(LocalizeData, MitKillianCarryWithoutTheRuleIsTheWitness) {
  REQUIRE_DATA();
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset("mit-killian", &ds, &err)) << err;
  for (const bool past_scans : {false, true}) {
    EXPECT_GE(mit_killian_carry_wrong_steps(ds, false, past_scans, 158), 1u)
        << "the replay no longer reaches the carry the rule is for" << (past_scans ? " (past scans)" : "");
  }
}

}  // namespace
}  // namespace sim::mmleval
