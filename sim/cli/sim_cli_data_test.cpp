// Log replay through hal/sim on the real intel log (skipped when ../shared/data is absent).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>

#include <unistd.h>

#include <fstream>
#include <sstream>

#include "sim/cli/sim_runner.h"
#include "sim/io/carmen_log.h"
#include "sim/io/datasets.h"
#include "sim/io/ros_map.h"
#include "sim/map/map_image_writer.h"
#include "sim/map/occupancy_builder.h"

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

// Issue 12 item 4: --start, --kidnap-at and --odom-noise with a log (intel, first 600 scans).
bool intel_or_skip(SimConfig* cfg) {
  const Dataset* ds = find_dataset("intel");
  if (ds == nullptr || !std::filesystem::exists(data_path(ds->raw_log))) return false;
  cfg->localizer = "odom";
  cfg->log_path = data_path(ds->raw_log);
  cfg->reference_path = data_path(ds->corrected_poses);
  cfg->progress = false;
  cfg->localizer_options["anchor"] = "truth";
  return true;
}

TEST(SimRunner, LogStartKidnapAndOdometryNoise) {
  SimConfig base;
  if (!intel_or_skip(&base)) GTEST_SKIP() << "intel log not found under MMLFW_DATA_DIR=" << data_dir();
  base.steps = 400;
  SimResult whole, from;
  std::string err;
  ASSERT_TRUE(run_simulation(base, &whole, &err)) << err;
  SimConfig start = base;
  start.log_start = 200;
  start.steps = 100;
  ASSERT_TRUE(run_simulation(start, &from, &err)) << err;
  ASSERT_EQ(from.steps.size(), 100u);
  // Step 0 of the replay from scan 200 is scan 200 (same ground truth), and time starts at 0.
  EXPECT_DOUBLE_EQ(from.steps[0].truth.x, whole.steps[200].truth.x);
  EXPECT_DOUBLE_EQ(from.steps[50].truth.y, whole.steps[250].truth.y);
  EXPECT_EQ(from.steps[0].t, 0.0);

  SimConfig kid = base;
  kid.log_kidnap_at = 150;
  SimResult k;
  ASSERT_TRUE(run_simulation(kid, &k, &err)) << err;
  ASSERT_GT(k.steps.size(), 200u);
  EXPECT_EQ(k.summary.kidnap_step, 150);
  EXPECT_TRUE(k.steps[150].kidnapped);
  EXPECT_GE(std::hypot(k.steps[150].truth.x - k.steps[149].truth.x, k.steps[150].truth.y - k.steps[149].truth.y),
            kLogKidnapMinJumpM);
  // The odometry sees nothing: its step across the carry is an ordinary one.
  EXPECT_LT(std::hypot(k.steps[150].odom.x - k.steps[149].odom.x, k.steps[150].odom.y - k.steps[149].odom.y), 0.5);
  for (size_t i = 1; i < k.steps.size(); ++i) EXPECT_GT(k.steps[i].t, k.steps[i - 1].t);

  SimConfig noisy = base;
  noisy.log_odom_noise = true;
  noisy.log_odom_sigma_m = 0.01;
  noisy.log_odom_sigma_deg = 1.0;
  SimResult n1, n2;
  ASSERT_TRUE(run_simulation(noisy, &n1, &err)) << err;
  ASSERT_TRUE(run_simulation(noisy, &n2, &err)) << err;
  ASSERT_EQ(n1.steps.size(), whole.steps.size());
  const auto& a = n1.steps.back().odom;
  const auto& b = whole.steps.back().odom;
  EXPECT_GT(std::hypot(a.x - b.x, a.y - b.y), 0.05);  // the noise reached the odometry
  EXPECT_EQ(a.x, n2.steps.back().odom.x);             // and is the seed's
}

// --map takes a compiled map image as well as a ROS YAML: the same map either way.
TEST(SimRunner, LogWithAMapImage) {
  SimConfig cfg;
  if (!intel_or_skip(&cfg)) GTEST_SKIP() << "intel log not found under MMLFW_DATA_DIR=" << data_dir();
  const Dataset* ds = find_dataset("intel");
  CarmenLog cor;
  std::string err;
  ASSERT_TRUE(read_carmen_log(data_path(ds->corrected_log), CarmenReadOptions{}, &cor, &err)) << err;
  std::vector<PosedScan> scans;
  for (const CarmenScan& s : cor.scans) {
    scans.push_back({s.pose, s.angle_min, s.angle_increment, s.max_range, s.ranges.data(), s.ranges.size()});
  }
  OccupancyGrid grid;
  OccupancyBuildStats st;
  ASSERT_TRUE(build_occupancy_grid(scans, OccupancyBuildOptions{}, &grid, &st, &err)) << err;
  const std::string dir = std::filesystem::temp_directory_path().string() + "/mml_sim_image_" + std::to_string(getpid());
  std::filesystem::create_directories(dir);
  const RosMap ros = grid_to_ros_map(grid, "m.pgm");
  std::vector<std::uint8_t> image;
  ASSERT_TRUE(write_ros_map(dir + "/m.yaml", ros, &err)) << err;
  ASSERT_TRUE(compile_map_image(ros, &image, &err)) << err;
  ASSERT_TRUE(write_file_bytes(dir + "/m.mmap", image, &err)) << err;
  cfg.steps = 60;
  cfg.out_dir = dir + "/yaml";
  cfg.pictures = false;
  cfg.wall_timing = false;
  cfg.map_yaml = dir + "/m.yaml";
  SimResult from_yaml, from_image;
  ASSERT_TRUE(run_simulation(cfg, &from_yaml, &err)) << err;
  cfg.map_yaml = dir + "/m.mmap";
  cfg.out_dir = dir + "/mmap";
  ASSERT_TRUE(run_simulation(cfg, &from_image, &err)) << err;
  std::stringstream a, b;
  a << std::ifstream(dir + "/yaml/steps.csv").rdbuf();
  b << std::ifstream(dir + "/mmap/steps.csv").rdbuf();
  EXPECT_EQ(a.str(), b.str());
  std::stringstream pa, pb;
  pa << std::ifstream(dir + "/yaml/map.pgm", std::ios::binary).rdbuf();
  pb << std::ifstream(dir + "/mmap/map.pgm", std::ios::binary).rdbuf();
  EXPECT_EQ(pa.str(), pb.str());  // the host grid recovered from the image is the YAML's
  // A broken image is an error naming it.
  image.resize(image.size() / 2);
  ASSERT_TRUE(write_file_bytes(dir + "/bad.mmap", image, &err)) << err;
  cfg.map_yaml = dir + "/bad.mmap";
  EXPECT_FALSE(run_simulation(cfg, &from_image, &err));
  EXPECT_NE(err.find("bad.mmap"), std::string::npos) << err;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace sim
