// Real-log test of AntSLAM (issue 12): the first 3000 scans of intel (two laps of the lab, loops
// closed by pRANSAM) must beat raw odometry on the relations metric, with both optimisers, and the
// same seed must give the same poses. Skips with a message when the data set is absent
// (MMLFW_DATA_DIR, ../shared/data by default).
#include <gtest/gtest.h>

#include <fstream>
#include <string>
#include <vector>

#include "sim/io/reference_trajectory.h"
#include "sim/slam/slam_pipeline.h"

namespace {

constexpr std::size_t kScans = 3000;

struct IntelPrefix {
  sim::CarmenLog log;
  std::vector<sim::Relation> rel;
  std::string skip;
};

const IntelPrefix& intel() {
  static IntelPrefix p = [] {
    IntelPrefix r;
    sim::EvalDataset d;
    std::string err;
    if (!sim::find_eval_dataset("intel", &d, &err)) {
      r.skip = err;
      return r;
    }
    if (!std::ifstream(d.raw_log).good()) {
      r.skip = "intel log not found at " + d.raw_log + " (set MMLFW_DATA_DIR)";
      return r;
    }
    if (!sim::read_carmen_log(d.raw_log, {}, &r.log, &err) || !sim::read_relations(d.relations, &r.rel, &err)) {
      r.skip = "cannot read intel: " + err;
    }
    return r;
  }();
  return p;
}

TEST(SlamDataTest, AntSlamBeatsRawOdometryOnAnIntelPrefix) {
  const IntelPrefix& p = intel();
  if (!p.skip.empty()) GTEST_SKIP() << p.skip;
  sim::SlamConfig cfg;
  cfg.max_scans = kScans;
  cfg.slam.aco.iterations = 2000;
  sim::SlamRun run;
  std::string err;
  ASSERT_TRUE(sim::run_slam(p.log, cfg, &run, &err)) << err;
  ASSERT_EQ(run.poses.size(), kScans);
  EXPECT_GT(run.stats.loops, 0u) << "no loop closed on two laps of the lab";
  std::vector<fw::Se2d> odom;
  for (std::size_t i = 0; i < kScans; ++i) odom.push_back(p.log.scans[i].odom);
  const auto m_odom = sim::evaluate_relations(p.rel, sim::make_trajectory(p.log, odom));
  const auto m_slam = sim::evaluate_relations(p.rel, sim::make_trajectory(p.log, run.poses));
  ASSERT_GT(m_slam.used, 100u);
  std::printf("intel[0, %zu): odometry %.4f m, AntSLAM (ACO) %.4f m / %.3f deg, %u loops\n", kScans,
              m_odom.trans_mean, m_slam.trans_mean, m_slam.rot_mean_deg, run.stats.loops);
  EXPECT_LT(m_slam.trans_mean, 0.5 * m_odom.trans_mean);
  EXPECT_LT(m_slam.rot_mean_deg, m_odom.rot_mean_deg);

  // LM on the same front end, and determinism of the back end (same seed, 2 workers).
  cfg.slam.optimizer = fw::antslam::LoopOptimizer::kLevenbergMarquardt;
  sim::SlamRun lm;
  ASSERT_TRUE(sim::run_slam_backend(p.log, run.frontend, cfg, &lm, &err)) << err;
  const auto m_lm = sim::evaluate_relations(p.rel, sim::make_trajectory(p.log, lm.poses));
  std::printf("intel[0, %zu): AntSLAM (LM) %.4f m\n", kScans, m_lm.trans_mean);
  EXPECT_LT(m_lm.trans_mean, 0.5 * m_odom.trans_mean);

  cfg.slam.optimizer = fw::antslam::LoopOptimizer::kAntColony;
  cfg.workers = 2;
  sim::SlamRun again;
  ASSERT_TRUE(sim::run_slam_backend(p.log, run.frontend, cfg, &again, &err)) << err;
  ASSERT_EQ(again.poses.size(), run.poses.size());
  for (std::size_t i = 0; i < run.poses.size(); ++i) {
    ASSERT_EQ(again.poses[i].x, run.poses[i].x) << "scan " << i;
    ASSERT_EQ(again.poses[i].theta, run.poses[i].theta) << "scan " << i;
  }
}

}  // namespace
