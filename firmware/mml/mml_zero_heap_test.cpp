// Zero heap after init across full MML, MCL and hand-off runs (the platform's allocation counter),
// plus the hand-off behaviour on a synthetic world.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "firmware/baselines/mcl/global_map_view.h"
#include "firmware/mml/handoff_localizer.h"
#include "firmware/mml/mml_localizer.h"
#include "firmware/mml/mml_test_util.h"
#include "tests/alloc_counter.h"

namespace fw {
namespace mml {
namespace {

using mmlfw_test::AllocCounter;
using testing::GridWorld;
using testing::OwnedGlobalMap;

struct Inputs {
  std::vector<hal::LaserScan> scans;
  std::vector<hal::Odometry> odom;
  std::vector<Se2f> truth;
};

Inputs make_inputs(const GridWorld& g, const std::vector<Se2f>& path) {
  Inputs in;
  in.scans.resize(path.size());
  in.odom.resize(path.size());
  in.truth = path;
  RandomStream rng(9, 1);
  Se2f odom;
  for (std::size_t i = 0; i < path.size(); ++i) {
    if (i > 0) {
      Se2f d = path[i - 1].between(path[i]);
      d.x *= 1.0f + 0.02f * static_cast<float>(rng.gaussian());
      d.theta += 0.002f * static_cast<float>(rng.gaussian());
      odom = odom.compose(d);
    }
    mcl::testing::simulate_scan(g.view(), path[i].x, path[i].y, path[i].theta, &in.scans[i]);
    in.scans[i].scan_id = static_cast<std::uint32_t>(i);
    in.scans[i].timestamp_ns = i * 100000000ull;
    in.odom[i].timestamp_ns = in.scans[i].timestamp_ns;
    in.odom[i].x = odom.x;
    in.odom[i].y = odom.y;
    in.odom[i].theta = odom.theta;
  }
  return in;
}

MmlLocalizerConfig small_config() {
  MmlLocalizerConfig c = default_mml_config();
  c.mml.matching_iterations = 20000;
  c.mml.table_triples = 400000;
  c.mml.min_local_map_points = 100;
  return c;
}

mcl::MclOptions tracking_options() {
  mcl::MclOptions o;
  o.num_particles = 500;
  o.model = mcl::SensorModel::kLikelihoodField;
  o.num_beams = 60;
  o.lf_sigma_m = 0.08f;
  o.alpha1 = o.alpha3 = 0.05f;
  o.alpha2 = o.alpha4 = 0.02f;
  o.resample_neff_ratio = 0.5f;
  return o;
}

struct Stack {
  StartupArena arena;
  WorkerPool pool;
  std::unique_ptr<MmlLocalizer> mml = std::make_unique<MmlLocalizer>();
  std::unique_ptr<mcl::MclLocalizer> mcl = std::make_unique<mcl::MclLocalizer>();
  std::unique_ptr<mcl::MclLocalizer> mcl_global = std::make_unique<mcl::MclLocalizer>();
  HandoffLocalizer handoff;
  Status init(const GlobalMap& map) {
    WorkerPoolOptions po;
    po.num_workers = 2;
    po.pin = false;
    FW_RETURN_IF_ERROR(pool.start(po));
    FW_RETURN_IF_ERROR(arena.init_mapped(192u << 20, false, "mml-test"));
    FW_RETURN_IF_ERROR(mml->init(small_config(), map, nullptr, 0, arena, &pool));
    FW_RETURN_IF_ERROR(mcl->init(tracking_options(), mcl::map_view_from_global(map), &pool));
    mcl::MclOptions g;
    g.num_particles = 20000;
    FW_RETURN_IF_ERROR(mcl_global->init(g, mcl::map_view_from_global(map), &pool));
    FW_RETURN_IF_ERROR(handoff.init(HandoffOptions(), mml.get(), mcl.get()));
    arena.seal();
    return Status::ok();
  }
};

TEST(MmlZeroHeapTest, MmlMclAndHandoffStepsAllocateNothing) {
  if (!AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  Stack s;
  ASSERT_TRUE(s.init(gm.map).is_ok());
  const Inputs in = make_inputs(g, testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}}, 0.1f));
  hal::PoseEstimate est;
  int mml_localized = 0, mcl_localized = 0, tracking = 0;
  AllocCounter::begin();
  for (std::size_t i = 0; i < in.scans.size(); ++i) {
    if (!s.mml->step(in.scans[i], in.odom[i], &est).is_ok()) break;
    mml_localized += est.status == hal::LocalizationStatus::kLocalized;
    if (!s.mcl_global->step(in.scans[i], in.odom[i], &est).is_ok()) break;
    mcl_localized += est.status == hal::LocalizationStatus::kLocalized;
    if (!s.handoff.step(in.scans[i], in.odom[i], &est).is_ok()) break;
    tracking += est.mode == hal::LocalizationMode::kTracking;
  }
  const long allocs = AllocCounter::end();
  EXPECT_EQ(allocs, 0) << "heap allocations after init";
  // The run must have exercised every stage (not a vacuous zero).
  EXPECT_GT(mml_localized, 10);
  EXPECT_GT(mcl_localized, 10);
  EXPECT_GT(tracking, 10);
  EXPECT_GT(s.mml->last().hypotheses_valid, 0u);
}

// The same with local map correction (Eq. 5.23–5.27) and reduction (Eq. 5.28–5.30) both on: their
// storage comes from the arena in init(), nothing from the heap per step.
TEST(MmlZeroHeapTest, CorrectionAndReductionAllocateNothing) {
  if (!AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(192u << 20, false, "mml-options-test").is_ok());
  auto mml = std::make_unique<MmlLocalizer>();
  MmlLocalizerConfig c = small_config();
  c.mml.correct_local_map = true;
  c.mml.reduce_observations = true;
  c.mml.reduction_max_observations = 4;  // small ring: eviction is exercised too
  const Status st = mml->init(c, gm.map, nullptr, 0, arena, nullptr);
  ASSERT_TRUE(st.is_ok()) << st.message();
  arena.seal();
  const Inputs in = make_inputs(g, testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}}, 0.1f));
  hal::PoseEstimate est;
  int localized = 0;
  AllocCounter::begin();
  for (std::size_t i = 0; i < in.scans.size(); ++i) {
    if (!mml->step(in.scans[i], in.odom[i], &est).is_ok()) break;
    localized += est.status == hal::LocalizationStatus::kLocalized;
  }
  const long allocs = AllocCounter::end();
  EXPECT_EQ(allocs, 0) << "heap allocations after init";
  EXPECT_GT(localized, 10);
  EXPECT_GT(mml->corrections_applied(), 0u);
  EXPECT_GT(mml->observations_accepted(), 0u);
}

// Hand-off: MML localizes, MCL tracks with small error; a kidnap (teleport) collapses the
// likelihood, MML takes over again and re-localizes at the new place.
TEST(HandoffTest, TracksAndRecoversFromKidnap) {
  static GridWorld g = mcl::testing::unique_room();
  static OwnedGlobalMap gm(g);
  Stack s;
  ASSERT_TRUE(s.init(gm.map).is_ok());
  auto path = testing::waypoint_path({{1.5f, 1.5f}, {1.5f, 6.5f}, {4.5f, 6.5f}, {4.5f, 2.0f}}, 0.1f);
  const std::size_t kidnap_at = path.size();
  const auto second = testing::waypoint_path({{10.5f, 6.5f}, {10.5f, 3.0f}, {8.0f, 3.2f}, {7.5f, 6.5f}}, 0.1f);
  path.insert(path.end(), second.begin(), second.end());
  Inputs in = make_inputs(g, path);
  // The odometry does not see the teleport.
  for (std::size_t i = kidnap_at; i < in.odom.size(); ++i) {
    const Se2f d = path[i - 1].between(path[i]);
    const Se2f prev(in.odom[i - 1].x, in.odom[i - 1].y, in.odom[i - 1].theta);
    const Se2f cur = prev.compose(i == kidnap_at ? Se2f(0.1f, 0, 0) : d);
    in.odom[i].x = cur.x; in.odom[i].y = cur.y; in.odom[i].theta = cur.theta;
  }
  hal::PoseEstimate est;
  std::vector<float> errs;
  int tracking_after_kidnap = 0;
  bool wrong_after_recovery = false;
  for (std::size_t i = 0; i < in.scans.size(); ++i) {
    ASSERT_TRUE(s.handoff.step(in.scans[i], in.odom[i], &est).is_ok());
    const float err = std::hypot(est.x - path[i].x, est.y - path[i].y);
    if (est.mode == hal::LocalizationMode::kTracking && i < kidnap_at) errs.push_back(err);
    if (i > kidnap_at + 40 && est.mode == hal::LocalizationMode::kTracking) {
      ++tracking_after_kidnap;
      if (err > 0.3f) wrong_after_recovery = true;
    }
  }
  ASSERT_GT(errs.size(), 20u);
  std::sort(errs.begin(), errs.end());
  EXPECT_LT(errs[errs.size() / 2], 0.05f) << "median tracking error";
  EXPECT_GE(s.handoff.fallbacks(), 1u) << "kidnap not detected";
  EXPECT_GE(s.handoff.handoffs(), 2u);
  EXPECT_GT(tracking_after_kidnap, 5);
  EXPECT_FALSE(wrong_after_recovery);
}

}  // namespace
}  // namespace mml
}  // namespace fw
