// Log replay through hal/sim on the real intel log (skipped when ../shared/data is absent).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include "sim/cli/sim_runner.h"
#include "sim/io/datasets.h"

namespace sim {
namespace {

// The odometry pass-through is always `searching`: the simulator scores none of its poses
// (StepRecord::err_m is NaN), so the pairing is checked on the raw estimate.
double raw_err_m(const StepRecord& s) { return std::hypot(s.estimate.x - s.truth.x, s.estimate.y - s.truth.y); }

TEST(SimRunner, ReplaysARealLogWithReference) {
  const Dataset* ds = find_dataset("intel");
  if (ds == nullptr || ds->raw_log.empty() || !std::filesystem::exists(data_path(ds->raw_log))) {
    GTEST_SKIP() << "intel log not found under MMLFW_DATA_DIR=" << data_dir();
  }
  SimConfig cfg;
  cfg.localizer = "odom";
  cfg.log_path = data_path(ds->raw_log);
  if (!ds->corrected_poses.empty()) cfg.reference_path = data_path(ds->corrected_poses);
  cfg.steps = 300;
  cfg.progress = false;
  cfg.localizer_options["anchor"] = cfg.reference_path.empty() ? "origin" : "truth";
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  EXPECT_EQ(r.steps.size(), 300u);
  EXPECT_EQ(r.summary.scans_dropped, 0u);
  if (!cfg.reference_path.empty()) {
    ASSERT_TRUE(r.steps.front().has_truth);
    EXPECT_TRUE(std::isnan(r.steps.front().err_m));
    EXPECT_LT(raw_err_m(r.steps.front()), 1e-3);
    // Raw odometry drifts, but over 300 scans of intel it stays within metres of the reference.
    EXPECT_LT(raw_err_m(r.steps.back()), 5.0);
  }
  // intel's time stamps step back now and then (631 times in the whole log, both ipc and logger
  // clocks): such scans are re-stamped after their predecessor and keep their own odometry.
  EXPECT_GT(r.summary.scans_restamped, 0u);
  EXPECT_EQ(r.summary.odom_rejected, 0u);
  for (size_t i = 1; i < r.steps.size(); ++i) EXPECT_GT(r.steps[i].t, r.steps[i - 1].t);
}

// --steps must not cut the log before the reference is chained: aces' first corrected pose lies
// beyond its first scans. (Log + reference given directly: --dataset would also build the global
// map when build/maps has no cached copy, which is slow.)
TEST(SimRunner, ShortDatasetRunKeepsTheReference) {
  const Dataset* ds = find_dataset("aces");
  if (ds == nullptr || !std::filesystem::exists(data_path(ds->raw_log))) {
    GTEST_SKIP() << "aces log not found under MMLFW_DATA_DIR=" << data_dir();
  }
  SimConfig cfg;
  cfg.localizer = "odom";
  cfg.log_path = data_path(ds->raw_log);
  cfg.reference_path = data_path(ds->corrected_poses);
  cfg.steps = 50;
  cfg.progress = false;
  cfg.localizer_options["anchor"] = "truth";
  SimResult r;
  std::string err;
  ASSERT_TRUE(run_simulation(cfg, &r, &err)) << err;
  ASSERT_EQ(r.steps.size(), 50u);
  EXPECT_TRUE(r.steps.front().has_truth);
  EXPECT_TRUE(r.steps.back().has_truth);
  EXPECT_LT(raw_err_m(r.steps.front()), 1e-3);  // anchored at the reference's first pose

}

}  // namespace
}  // namespace sim
