// Product metrics (trial_metrics / summarize) on hand-made step logs, the odometry continuity of a
// kidnap in run_trial (fake localizer on a hand-made log), synthesised odometry, and the error
// messages of the path-based loader (load_dataset_files).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "sim/eval/mml_eval/mml_eval.h"

namespace sim::mmleval {
namespace {

using hal::LocalizationMode;
using hal::LocalizationStatus;

StepLog step(LocalizationStatus st, double err_m, double err_deg = 0.0, float pl_xy = 0.0f, float pl_deg = 0.0f,
             LocalizationMode mode = LocalizationMode::kTracking) {
  StepLog s;
  s.status = st;
  s.mode = mode;
  s.has_pose = st != LocalizationStatus::kSearching;
  s.err_m = s.has_pose ? err_m : std::numeric_limits<double>::quiet_NaN();
  s.err_rad = s.has_pose ? err_deg * M_PI / 180.0 : std::numeric_limits<double>::quiet_NaN();
  s.pl_xy = pl_xy;
  s.pl_theta = static_cast<float>(pl_deg * M_PI / 180.0);
  return s;
}

TrialResult trial(std::vector<StepLog> steps) {
  TrialResult t;
  for (std::size_t k = 0; k < steps.size(); ++k) steps[k].travelled = static_cast<double>(k);  // 1 m per step
  t.steps = std::move(steps);
  return t;
}

const auto S = LocalizationStatus::kSearching;
const auto A = LocalizationStatus::kAmbiguous;
const auto L = LocalizationStatus::kLocalized;
const auto O = LocalizationStatus::kOutsideMap;

TEST(LocalizeMetrics, FirstFixAndAvailability) {
  // s s L(ok) L L a L o L   → first fix at index 2 (2 m); after it 6 steps, 4 localized.
  TrialResult t = trial({step(S, 0), step(S, 0), step(L, 0.1), step(L, 0.1), step(L, 0.1), step(A, 3.0),
                         step(L, 0.1), step(O, 0.2), step(L, 0.1)});
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_TRUE(m.first_fix);
  EXPECT_TRUE(m.first_fix_success);
  EXPECT_EQ(m.first_fix_index, 2u);
  EXPECT_DOUBLE_EQ(m.m_to_fix, 2.0);
  EXPECT_EQ(m.avail_steps, 6u);
  EXPECT_EQ(m.avail_localized, 4u);
  EXPECT_EQ(m.integrity_failures, 0u);
}

TEST(LocalizeMetrics, UnavailableStepsCountedByTheirReason) {
  // s L a(alias) a(awaiting) a(alias) L o s: after the fix 6 steps, 1 localized; the 5 others by the
  // reason published with them (the searching step before the fix is not an availability step).
  TrialResult t = trial({step(S, 0), step(L, 0.1), step(A, 0.2), step(A, 0.2), step(A, 0.2), step(L, 0.1),
                         step(O, 0.2), step(S, 0)});
  t.steps[0].reason = t.steps[7].reason = hal::StatusReason::kSearching;
  t.steps[2].reason = t.steps[4].reason = hal::StatusReason::kTrackAlias;
  t.steps[3].reason = hal::StatusReason::kTrackAwaitingMml;
  t.steps[6].reason = hal::StatusReason::kOutsideMap;
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.avail_steps, 6u);
  EXPECT_EQ(m.avail_localized, 1u);
  EXPECT_EQ(m.unavailable_by_reason[static_cast<int>(hal::StatusReason::kTrackAlias)], 2u);
  EXPECT_EQ(m.unavailable_by_reason[static_cast<int>(hal::StatusReason::kTrackAwaitingMml)], 1u);
  EXPECT_EQ(m.unavailable_by_reason[static_cast<int>(hal::StatusReason::kOutsideMap)], 1u);
  EXPECT_EQ(m.unavailable_by_reason[static_cast<int>(hal::StatusReason::kSearching)], 1u);
  EXPECT_EQ(m.unavailable_by_reason[static_cast<int>(hal::StatusReason::kNone)], 0u);
}

TEST(LocalizeMetrics, AvailabilityExcludesErasedRegion) {
  TrialResult t = trial({step(L, 0.1), step(L, 0.1), step(S, 0), step(S, 0), step(L, 0.1)});
  t.steps[2].in_region = t.steps[3].in_region = true;
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.avail_steps, 2u);
  EXPECT_EQ(m.avail_localized, 2u);
}

// Steps whose reference scan the map does not describe (unmapped_scan.h) are left out like the
// erased region, but counted, and so are the `localized` ones among them.
TEST(LocalizeMetrics, AvailabilityLeavesOutUnmappedStepsAndCountsThem) {
  TrialResult t = trial({step(L, 0.1), step(S, 0), step(L, 0.1), step(S, 0), step(L, 0.1)});
  t.steps[1].ref_unmapped = t.steps[2].ref_unmapped = true;
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.avail_steps, 2u);
  EXPECT_EQ(m.avail_localized, 1u);
  EXPECT_EQ(m.unmapped_steps, 2u);
  EXPECT_EQ(m.unmapped_localized, 1u);
  // Steps where the map does not explain the scan at the reference are shown, not left out.
  t.steps[3].ref_off_map = t.steps[4].ref_off_map = true;
  const TrialMetrics o = trial_metrics(t, MetricBounds());
  EXPECT_EQ(o.avail_steps, 2u);
  EXPECT_EQ(o.off_map_steps, 2u);
  EXPECT_EQ(o.off_map_localized, 1u);
  // The first fix is not judged by it: an unmapped first step still starts the count.
  t.steps[0].ref_unmapped = true;
  EXPECT_TRUE(trial_metrics(t, MetricBounds()).first_fix);
}

TEST(LocalizeMetrics, FirstFixOutsideWindowOrWrong) {
  MetricBounds b;
  b.fix_within_steps = 3;
  TrialResult late = trial({step(S, 0), step(S, 0), step(A, 1), step(L, 0.1), step(L, 0.1), step(S, 0)});
  EXPECT_FALSE(trial_metrics(late, b).first_fix);
  EXPECT_TRUE(std::isnan(trial_metrics(late, b).m_to_fix));
  // Availability still counts after a late first `localized`.
  EXPECT_EQ(trial_metrics(late, b).avail_steps, 2u);
  EXPECT_EQ(trial_metrics(late, b).avail_localized, 1u);
  TrialResult wrong = trial({step(S, 0), step(L, 2.0), step(L, 0.1)});
  const TrialMetrics m = trial_metrics(wrong, b);
  EXPECT_TRUE(m.first_fix);
  EXPECT_FALSE(m.first_fix_success);
  // Heading beyond 5° is wrong too.
  TrialResult wrong_heading = trial({step(L, 0.1, 6.0)});
  EXPECT_FALSE(trial_metrics(wrong_heading, b).first_fix_success);
  EXPECT_EQ(trial_metrics(wrong_heading, b).integrity_failures, 1u);
}

// Metres to the first fix count a wrong fix, and a trial without one, as never fixed (+∞) instead of
// as a fast fix or not at all: the median of {1, 2, 3, wrong at 0, none} is the 3rd of 1 2 3 ∞ ∞ = 3
// (the old rule: median of {0, 1, 2, 3} = 1.5, flattering the system that fixed wrongly).
TEST(LocalizeMetrics, MetresToFixCountWrongAndMissingFixesAsNever) {
  const TrialResult at1 = trial({step(S, 0), step(L, 0.1), step(L, 0.1)});
  const TrialResult at2 = trial({step(S, 0), step(A, 3.0), step(L, 0.1)});
  const TrialResult at3 = trial({step(S, 0), step(S, 0), step(A, 1.0), step(L, 0.2)});
  const TrialResult wrong = trial({step(L, 4.0), step(L, 4.0)});
  const TrialResult none = trial({step(S, 0), step(A, 2.0), step(S, 0)});
  EXPECT_DOUBLE_EQ(summarize("d", "sys", {at1, at2, at3, wrong, none}, 0).m_to_fix_median, 3.0);
  EXPECT_DOUBLE_EQ(summarize("d", "sys", {at1, at2, at3, wrong}, 0).m_to_fix_median, 2.5);
  EXPECT_DOUBLE_EQ(summarize("d", "sys", {at1, at2, at3}, 0).m_to_fix_median, 2.0);
  // Half or more never fixed: the median is not reached (NaN), never a finite figure.
  EXPECT_TRUE(std::isnan(summarize("d", "sys", {at1, wrong, none}, 0).m_to_fix_median));
  EXPECT_TRUE(std::isnan(summarize("d", "sys", {at1, none}, 0).m_to_fix_median));
  EXPECT_TRUE(std::isnan(censored_median({})));
  EXPECT_DOUBLE_EQ(censored_median({5.0, 1.0, std::numeric_limits<double>::infinity()}), 5.0);
}

TEST(LocalizeMetrics, IntegrityFailuresAndReferenceExclusion) {
  TrialResult t = trial({step(L, 0.1), step(L, 0.7), step(L, 0.2, 7.0), step(A, 5.0), step(L, 0.9), step(L, 0.1)});
  t.steps[4].ref_ok = false;  // unreliable reference: not checked, counted as excluded
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.localized_steps, 4u);
  EXPECT_EQ(m.integrity_failures, 2u);
  EXPECT_EQ(m.excluded_ref_steps, 1u);
  // Dataset bound (mit-killian: 1 m): 0.7 m is no failure there.
  MetricBounds b;
  b.bound_m = 1.0;
  EXPECT_EQ(trial_metrics(t, b).integrity_failures, 1u);
}

TEST(LocalizeMetrics, ProtectionLevelExceedance) {
  // Only localized steps with a nonzero PL count; xy and heading bounds separately.
  TrialResult t = trial({step(L, 0.05, 0.5, 0.10f, 1.0f),   // inside
                         step(L, 0.15, 0.5, 0.10f, 1.0f),   // xy exceeded
                         step(L, 0.05, 2.0, 0.10f, 1.0f),   // heading exceeded
                         step(L, 0.30, 0.5, 0.0f, 0.0f),    // no PL: not counted
                         step(A, 9.0, 0.0, 0.10f, 1.0f)});  // not localized: not counted
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.pl_steps, 3u);
  EXPECT_EQ(m.pl_exceed, 2u);
  EXPECT_EQ(m.pl_exceed_xy, 1u);
  EXPECT_EQ(m.pl_exceed_theta, 1u);
  const SystemSummary s = summarize("d", "sys", {t}, 0);
  EXPECT_DOUBLE_EQ(s.pl_exceed_rate, 2.0 / 3.0);
}

TEST(LocalizeMetrics, EachCriterionCountsOnlyWhereItIsJudgedBeyond) {
  // Kept steps (the reference checks judged one criterion beyond): a criterion they cleared does not
  // count, the other does. A failure the map confirms is never dropped because the map clears the PL.
  TrialResult t = trial({step(L, 0.7, 0.5, 0.60f, 9.0f),   // failure confirmed, PL cleared (map pose 0.55 m off)
                         step(L, 0.7, 0.5, 0.30f, 1.0f),   // failure cleared by the map, PL exceedance confirmed
                         step(L, 0.7, 0.5, 0.30f, 1.0f)}); // both confirmed
  t.steps[0].pl_cleared = true;
  t.steps[1].integrity_cleared = true;
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.localized_steps, 3u);
  EXPECT_EQ(m.integrity_failures, 2u);
  EXPECT_EQ(m.pl_steps, 3u);
  EXPECT_EQ(m.pl_exceed, 2u);
  // Against the log reference alone every one of them is beyond both.
  EXPECT_EQ(m.integrity_failures_raw, 3u);
  EXPECT_EQ(m.pl_exceed_raw, 3u);
  EXPECT_FALSE(m.first_fix_success);
  t.steps[0].integrity_cleared = true;
  EXPECT_TRUE(trial_metrics(t, MetricBounds()).first_fix_success);
}

TEST(LocalizeMetrics, PlaceholderPoseNeverCounted) {
  // A localizer publishing `localized` must have a pose; `searching` steps carry NaN errors and must
  // neither count as failures nor enter the tracking error, even if the (placeholder) pose is 0,0.
  TrialResult t = trial({step(S, 0), step(L, 0.1), step(S, 0), step(L, 0.1)});
  for (auto& s : t.steps) EXPECT_EQ(std::isnan(s.err_m), s.status == S);
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_EQ(m.integrity_failures, 0u);
  EXPECT_EQ(m.track_err.size(), 2u);
  for (double e : m.track_err) EXPECT_TRUE(std::isfinite(e));
  // A `localized` step without a pose (should not happen) is excluded, never compared.
  TrialResult bad = trial({step(L, 0.1)});
  bad.steps[0].has_pose = false;
  bad.steps[0].err_m = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(trial_metrics(bad, MetricBounds()).localized_steps, 0u);
  EXPECT_EQ(trial_metrics(bad, MetricBounds()).excluded_ref_steps, 1u);
}

TEST(LocalizeMetrics, TrackingErrorOnlyLocalizedTracking) {
  TrialResult t = trial({step(L, 0.3, 0, 0, 0, LocalizationMode::kGlobal), step(L, 0.1), step(L, 0.2),
                         step(O, 0.4), step(L, 0.3)});
  const SystemSummary s = summarize("d", "sys", {t}, 0);
  EXPECT_DOUBLE_EQ(s.track_err_median_m, 0.2);
}

TEST(LocalizeMetrics, KidnapDelayAndRefix) {
  // Kidnap at index 3 (travelled 2.5 m at the jump): localized (wrong) for 2 steps, then searching,
  // then a correct fix at index 7.
  TrialResult t = trial({step(L, 0.1), step(L, 0.1), step(L, 0.1), step(L, 8.0), step(L, 8.0), step(S, 0),
                         step(A, 3.0), step(L, 0.1), step(L, 0.1)});
  t.kidnap_step = 3;
  t.kidnap_travelled = 2.5;
  const TrialMetrics m = trial_metrics(t, MetricBounds());
  EXPECT_TRUE(m.kidnapped);
  EXPECT_TRUE(m.kidnap_detected);
  EXPECT_DOUBLE_EQ(m.kidnap_delay_steps, 2.0);
  EXPECT_TRUE(m.kidnap_refix);
  EXPECT_DOUBLE_EQ(m.refix_m, 7.0 - 2.5);
  EXPECT_EQ(m.kidnap_integrity_failures, 2u);
  EXPECT_EQ(m.integrity_failures, 2u);
  // Availability stops at the kidnap.
  EXPECT_EQ(m.avail_steps, 2u);
  // Never detected, never re-fixed.
  TrialResult never = trial({step(L, 0.1), step(L, 6.0), step(L, 6.0)});
  never.kidnap_step = 1;
  const TrialMetrics n = trial_metrics(never, MetricBounds());
  EXPECT_FALSE(n.kidnap_detected);
  EXPECT_TRUE(std::isnan(n.kidnap_delay_steps));
  EXPECT_FALSE(n.kidnap_refix);
  // Re-fix window.
  MetricBounds b;
  b.refix_within_steps = 4;
  EXPECT_FALSE(trial_metrics(t, b).kidnap_refix);
  const SystemSummary s = summarize("d", "sys", {t, never}, 0);
  EXPECT_EQ(s.kidnaps, 2u);
  EXPECT_DOUBLE_EQ(s.kidnap_refix_success, 0.5);
  // The kidnap never detected nor re-fixed stays in the medians as "never": with one of two, the
  // median is not reached; with one of three, it is the others' figure.
  EXPECT_TRUE(std::isnan(s.kidnap_delay_median));
  EXPECT_TRUE(std::isnan(s.kidnap_refix_m_median));
  const SystemSummary s3 = summarize("d", "sys", {t, t, never}, 0);
  EXPECT_DOUBLE_EQ(s3.kidnap_delay_median, 2.0);
  EXPECT_DOUBLE_EQ(s3.kidnap_refix_m_median, 7.0 - 2.5);
}

// Records the odometry it is given; always "searching".
class RecordingLocalizer : public fw::Localizer {
 public:
  const char* name() const override { return "recorder"; }
  void reset() override { odom.clear(); }
  fw::Status step(const hal::LaserScan& scan, const hal::Odometry& o, hal::PoseEstimate* out) override {
    odom.push_back(fw::Se2d(o.x, o.y, o.theta));
    scans.push_back(scan.scan_id);
    *out = hal::PoseEstimate();
    return fw::Status::ok();
  }
  std::vector<fw::Se2d> odom;
  std::vector<std::uint32_t> scans;
};

// A straight-line log with a curve, 0.2 m between scans; odometry = reference offset by a far
// transform (any frame).
LoadedDataset line_dataset(std::size_t n) {
  LoadedDataset ds;
  ds.name = ds.key = "line";
  const fw::Se2d frame(100.0, -50.0, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    CarmenScan s;
    s.index = i;
    s.type = "FLASER";
    s.ipc_timestamp = 1000.0 + static_cast<double>(i);
    s.angle_min = -1.57f;
    s.angle_increment = 0.0174f;
    s.max_range = 80.0f;
    s.ranges.assign(180, 5.0f);
    const double th = 0.01 * static_cast<double>(i);
    const fw::Se2d ref(0.2 * static_cast<double>(i), 0.01 * static_cast<double>(i * i) * 0.01, th);
    s.pose = ref;
    s.odom = frame.compose(ref);
    ds.log.scans.push_back(s);
    ds.reference.push_back(ref);
    ds.odometry.push_back(s.odom);
  }
  double acc = 0;
  for (std::size_t i = 0; i < n; ++i) {
    if (i > 0) acc += std::hypot(ds.odometry[i].x - ds.odometry[i - 1].x, ds.odometry[i].y - ds.odometry[i - 1].y);
    ds.travelled.push_back(acc);
  }
  return ds;
}

TEST(LocalizeKidnap, OdometryContinuousAcrossTheJump) {
  const LoadedDataset ds = line_dataset(400);
  RecordingLocalizer loc;
  TrialOptions opt;
  opt.max_steps = 0;
  opt.kidnap_at_step = 20;
  opt.kidnap_to_scan = 250;
  opt.kidnap_steps_after = 30;
  const TrialResult t = run_trial(loc, ds, 10, opt);
  ASSERT_EQ(t.kidnap_step, 20u);
  ASSERT_EQ(t.steps.size(), 50u);
  ASSERT_EQ(loc.odom.size(), 50u);
  EXPECT_EQ(t.steps[19].segment, 0u);
  EXPECT_EQ(t.steps[20].segment, 1u);
  // Every increment fed across the run equals a true log increment: before the jump scan k-1 → k;
  // at the jump the increment from the jump target (scan 250, fed at the last pose) to the first step
  // after it; nowhere a jump.
  for (std::size_t k = 1; k < t.steps.size(); ++k) {
    const fw::Se2d fed = loc.odom[k - 1].between(loc.odom[k]);
    const std::size_t from = k == t.kidnap_step ? opt.kidnap_to_scan : t.steps[k - 1].scan;
    const fw::Se2d logd = ds.odometry[from].between(ds.odometry[t.steps[k].scan]);
    EXPECT_NEAR(fed.x, logd.x, 1e-4) << "step " << k;
    EXPECT_NEAR(fed.y, logd.y, 1e-4) << "step " << k;
    EXPECT_NEAR(fw::wrap_angle(fed.theta - logd.theta), 0.0, 1e-5) << "step " << k;
    EXPECT_LT(std::hypot(fed.x, fed.y), 0.5) << "odometry jump at step " << k;
  }
  EXPECT_GT(t.steps[20].scan, 250u);
  EXPECT_LT(t.steps[20].scan, 253u);
  // Metres keep counting across the jump (no jump in `travelled` either).
  EXPECT_NEAR(t.steps[20].travelled - t.kidnap_travelled, ds.travelled[t.steps[20].scan] - ds.travelled[250], 1e-9);
  // Searching: no pose, NaN error.
  EXPECT_TRUE(std::isnan(t.steps[0].err_m));
}

TEST(LocalizeKidnap, KidnapAfterFixTarget) {
  const LoadedDataset ds = line_dataset(200);
  RecordingLocalizer loc;  // never localized: falls back to kidnap_at_step
  TrialOptions opt;
  opt.max_steps = 0;
  opt.kidnap_after_fix_steps = 5;
  opt.kidnap_at_step = 12;
  opt.kidnap_steps_after = 3;
  std::size_t asked_from = 0;
  opt.kidnap_target = [&](std::size_t from) {
    asked_from = from;
    return std::size_t{150};
  };
  const TrialResult t = run_trial(loc, ds, 0, opt);
  EXPECT_EQ(t.kidnap_step, 12u);
  EXPECT_EQ(asked_from, t.steps[11].scan);
  EXPECT_EQ(t.steps.size(), 15u);
}

TEST(LocalizeOdometry, SynthesisedOdometryFollowsIncrements) {
  std::vector<fw::Se2d> ref;
  for (int i = 0; i < 500; ++i) ref.push_back(fw::Se2d(0.1 * i, 0.0, 0.002 * i));
  const std::vector<fw::Se2d> a = synthesize_odometry(ref, 3), b = synthesize_odometry(ref, 3),
                              c = synthesize_odometry(ref, 4);
  ASSERT_EQ(a.size(), ref.size());
  EXPECT_DOUBLE_EQ(a.back().x, b.back().x);  // seeded
  EXPECT_NE(a.back().x, c.back().x);
  double err_sum = 0;
  for (std::size_t i = 1; i < a.size(); ++i) {
    const fw::Se2d d = a[i - 1].between(a[i]), t = ref[i - 1].between(ref[i]);
    err_sum += std::hypot(d.x - t.x, d.y - t.y);
    EXPECT_LT(std::hypot(d.x - t.x, d.y - t.y), 0.1 * 0.05 * 6 + 0.01 * 0.002 * 6);  // within 6 σ
  }
  // Mean |n| of a 2-D Gaussian with σ = 0.05·0.1 + 0.01·0.002 is σ·√(π/2).
  EXPECT_NEAR(err_sum / 499.0, (0.005 + 0.00002) * std::sqrt(M_PI / 2.0), 0.0015);
}

// Path-based loader: errors name the file and the problem.
class PathLoader : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("mml_eval_loader_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    write("log.clf",
          "FLASER 3 1.0 1.0 1.0 0 0 0 0 0 0 100.0 host 0.0\n"
          "FLASER 3 1.0 1.0 1.0 0.5 0 0 0.5 0 0 101.0 host 1.0\n");
    write("poses.txt", "0 100.0 0.0 0 0 0\n1 101.0 1.0 0.5 0 0\n");
    write("bad_poses.txt", "0 100.0 0.0 zero 0 0\n");
    write("map.pgm", "P2\n2 2\n255\n254 254\n0 254\n");
    write("map.yaml", "image: map.pgm\nresolution: 0.05\norigin: [0.0, 0.0, 0.0]\nnegate: 0\noccupied_thresh: 0.65\n"
                      "free_thresh: 0.196\n");
    write("broken.yaml", "resolution: 0.05\n");
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  void write(const std::string& name, const std::string& text) { std::ofstream(dir_ / name) << text; }
  std::string p(const std::string& name) const { return (dir_ / name).string(); }
  std::string load(DatasetFiles f) {
    LoadedDataset ds;
    std::string err;
    EXPECT_FALSE(load_dataset_files(f, &ds, &err));
    return err;
  }
  std::filesystem::path dir_;
};

TEST_F(PathLoader, MissingFilesAreNamed) {
  DatasetFiles f{"x", p("nope.clf"), p("map.yaml"), p("poses.txt"), ""};
  EXPECT_NE(load(f).find("nope.clf: file not found"), std::string::npos) << load(f);
  f = {"x", p("log.clf"), p("map.yaml"), p("poses.txt"), p("none.relations")};
  EXPECT_NE(load(f).find("none.relations: file not found"), std::string::npos);
  f = {"x", p("log.clf"), "", p("poses.txt"), ""};
  EXPECT_NE(load(f).find("--map is required"), std::string::npos);
}

TEST_F(PathLoader, BadReferenceIsNamed) {
  DatasetFiles f{"x", p("log.clf"), p("map.yaml"), p("bad_poses.txt"), ""};
  const std::string e = load(f);
  EXPECT_NE(e.find("bad_poses.txt"), std::string::npos) << e;
  EXPECT_NE(e.find("flaser_index"), std::string::npos) << e;
  // A CARMEN reference with another scan count.
  write("ref.log", "FLASER 3 1.0 1.0 1.0 0 0 0 0 0 0 100.0 host 0.0\n");
  f.reference = p("ref.log");
  const std::string e2 = load(f);
  EXPECT_NE(e2.find("ref.log: CARMEN reference has 1 scans"), std::string::npos) << e2;
  // flaser_index beyond the log.
  write("far.txt", "7 100.0 0.0 0 0 0\n");
  f.reference = p("far.txt");
  EXPECT_NE(load(f).find("far.txt: first flaser_index 7 is beyond"), std::string::npos) << load(f);
}

TEST_F(PathLoader, BadMapIsNamed) {
  DatasetFiles f{"x", p("log.clf"), p("broken.yaml"), p("poses.txt"), ""};
  const std::string e = load(f);
  EXPECT_NE(e.find("broken.yaml"), std::string::npos) << e;
}

TEST_F(PathLoader, LogWithoutScansOrMotion) {
  write("empty.clf", "# nothing\n");
  DatasetFiles f{"x", p("empty.clf"), p("map.yaml"), p("poses.txt"), ""};
  EXPECT_NE(load(f).find("empty.clf: no laser scans"), std::string::npos) << load(f);
  write("still.clf",
        "FLASER 3 1.0 1.0 1.0 0 0 0 0 0 0 100.0 host 0.0\nFLASER 3 1.0 1.0 1.0 0 0 0 0 0 0 101.0 host 1.0\n");
  f.log = p("still.clf");
  EXPECT_NE(load(f).find("still.clf: the odometry never moves"), std::string::npos) << load(f);
}

TEST_F(PathLoader, ValidInputLoads) {
  DatasetFiles f{"my building", p("log.clf"), p("map.yaml"), p("poses.txt"), ""};
  LoadedDataset ds;
  std::string err;
  ASSERT_TRUE(load_dataset_files(f, &ds, &err)) << err;
  EXPECT_EQ(ds.key, "my_building");
  EXPECT_EQ(ds.reference.size(), 2u);
  EXPECT_NEAR(ds.travelled.back(), 0.5, 1e-9);
  EXPECT_NE(ds.ref_check_note.find("not checked"), std::string::npos);
}

}  // namespace
}  // namespace sim::mmleval
