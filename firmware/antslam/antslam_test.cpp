// AntSLAM end to end on a synthetic ring corridor with a known answer: the robot drives two laps,
// the front end's poses drift (heading bias and scale error), the scans are exact. AntSLAM must
// close loops with pRANSAM and bring the trajectory closer to the truth, with either optimiser,
// deterministically per seed.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "firmware/antslam/antslam.h"
#include "firmware/rbsm/synthetic_world_test_util.h"
#include "tests/alloc_counter.h"

namespace fw::antslam {
namespace {

using rbsm_test::Segment;

std::vector<Segment> ring_world() {
  std::vector<Segment> w = rbsm_test::box(0, 0, 16, 16);
  const auto inner = rbsm_test::box(3, 3, 13, 13);
  w.insert(w.end(), inner.begin(), inner.end());
  // Recesses and pillars so that no stretch of the corridor looks like another.
  const std::vector<Segment> extra = {{4, 0.0f, 4, 0.8f},   {6, 0.0f, 6, 0.5f},   {9, 3, 9, 2.2f},
                                      {16, 5, 15.2f, 5},    {13, 9, 13.6f, 9},    {15.4f, 12, 16, 12.5f},
                                      {11, 16, 11, 15.0f},  {7, 13, 7, 13.7f},    {0, 10, 0.9f, 10.4f},
                                      {3, 6, 2.3f, 6.3f},   {1.0f, 2.0f, 1.3f, 2.0f}, {14, 1.0f, 14.3f, 1.3f}};
  w.insert(w.end(), extra.begin(), extra.end());
  return w;
}

struct RingRun {
  std::vector<Se2d> truth, frontend;
  std::vector<std::vector<Point2f>> scans;
};

// Two laps of the corridor's centre line, a scan every 0.1 m.
RingRun make_run() {
  RingRun r;
  const auto world = ring_world();
  const double corners[5][2] = {{1.5, 1.5}, {14.5, 1.5}, {14.5, 14.5}, {1.5, 14.5}, {1.5, 1.5}};
  for (int lap = 0; lap < 2; ++lap) {
    for (int s = 0; s < 4; ++s) {
      const double x0 = corners[s][0], y0 = corners[s][1], x1 = corners[s + 1][0], y1 = corners[s + 1][1];
      const double th = std::atan2(y1 - y0, x1 - x0);
      const int n = static_cast<int>(std::hypot(x1 - x0, y1 - y0) / 0.1);
      for (int i = 0; i < n; ++i) {
        const double a = static_cast<double>(i) / n;
        r.truth.emplace_back(x0 + a * (x1 - x0), y0 + a * (y1 - y0), th);
      }
    }
  }
  // Front end: true increments with a heading bias of 0.15°/m and 1 % too long.
  r.frontend.push_back(r.truth[0]);
  for (std::size_t i = 1; i < r.truth.size(); ++i) {
    Se2d u = r.truth[i - 1].between(r.truth[i]);
    const double d = std::hypot(u.x, u.y);
    u = Se2d(u.x * 1.01, u.y * 1.01, wrap_angle(u.theta + d * 0.15 * M_PI / 180));
    r.frontend.push_back(r.frontend.back().compose(u));
  }
  for (const Se2d& p : r.truth) r.scans.push_back(rbsm_test::cast_scan(world, p.cast<float>(), 181, 8.0f));
  return r;
}

double mean_error(const std::vector<Se2d>& a, const std::vector<Se2d>& b) {
  double s = 0;
  for (std::size_t i = 0; i < a.size(); ++i) s += std::hypot(a[i].x - b[i].x, a[i].y - b[i].y);
  return s / static_cast<double>(a.size());
}

AntSlamOptions test_options(LoopOptimizer opt) {
  AntSlamOptions o = default_antslam_options();
  o.max_scans = 2000;
  o.max_fragments = 64;
  o.max_closures = 64;
  o.max_loop_steps = 64;
  o.var_theta_per_m = 0.01 * 0.01;
  o.aco.iterations = 1500;
  o.optimizer = opt;
  return o;
}

// One AntSLAM run over the ring. The arena is sealed after init and, where the allocation counter
// works (not under sanitizers), every heap allocation in add_scan/finish is counted: no assertion
// inside that region, since a failing one would allocate its message.
struct SlamRun {
  std::vector<Se2d> poses;
  std::uint32_t loops = 0;
  long allocations = -1;  // -1: not counted
  AntSlamStats stats;
  std::uint32_t fragments = 0;
  bool states_ok = true;  // every fragment but the active one is TRAVERSAL with a hull and a border
};

SlamRun run_slam(const RingRun& r, const AntSlamOptions& o) {
  SlamRun run;
  std::vector<unsigned char> block(AntSlam::required_arena_bytes(o));
  StartupArena arena;
  EXPECT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
  auto slam = std::make_unique<AntSlam>();
  const Status st = slam->init(o, arena);
  EXPECT_TRUE(st.is_ok()) << st.message();
  arena.seal();
  const bool count = mmlfw_test::AllocCounter::available();
  if (count) mmlfw_test::AllocCounter::begin();
  Status first_error;
  for (std::size_t i = 0; i < r.truth.size(); ++i) {
    const Status s = slam->add_scan(r.frontend[i], r.scans[i].data(), r.scans[i].size());
    if (!s.is_ok() && first_error.is_ok()) first_error = s;
  }
  const Status fin = slam->finish();
  if (count) run.allocations = mmlfw_test::AllocCounter::end();
  EXPECT_TRUE(first_error.is_ok()) << first_error.message();
  EXPECT_TRUE(fin.is_ok()) << fin.message();
  for (std::uint32_t i = 0; i < slam->num_scans(); ++i) run.poses.push_back(slam->scan_pose(i));
  run.loops = slam->stats().loops;
  run.stats = slam->stats();
  run.fragments = slam->num_fragments();
  for (std::uint32_t f = 0; o.traversal && f < slam->num_fragments(); ++f) {
    std::uint32_t nb = 0, nh = 0;
    slam->fragment_borders(f, &nb);
    slam->fragment_hull(f, &nh);
    const bool ended = slam->traversing() || f != slam->active_fragment();
    if (ended && (slam->fragment_state(f) != AntSlam::FragmentState::kTraversal || nh < 3 || nb < 1)) {
      run.states_ok = false;
    }
  }
  return run;
}

// The ring and one run of it per optimiser, made once per process and shared by the tests below
// (a whole run costs 2 s here, ~35 s under qemu-aarch64, ~45 s under ASan): the ring test judges
// them, the heap test reads their allocation counts, the same-seed test compares the ant-colony run
// with a second, fresh one.
const RingRun& ring() {
  static const RingRun r = make_run();
  return r;
}
const SlamRun& ring_run(LoopOptimizer opt) {
  static const SlamRun aco = run_slam(ring(), test_options(LoopOptimizer::kAntColony));
  static const SlamRun lm = run_slam(ring(), test_options(LoopOptimizer::kLevenbergMarquardt));
  return opt == LoopOptimizer::kAntColony ? aco : lm;
}

TEST(AntSlamTest, ClosesTheRingAndBeatsTheDriftingFrontEnd) {
  const RingRun& r = ring();
  const double e_front = mean_error(r.frontend, r.truth);
  ASSERT_GT(e_front, 0.5);  // the drift is real
  for (LoopOptimizer opt : {LoopOptimizer::kAntColony, LoopOptimizer::kLevenbergMarquardt}) {
    const SlamRun& run = ring_run(opt);
    ASSERT_EQ(run.poses.size(), r.truth.size());
    const double e = mean_error(run.poses, r.truth);
    std::printf("%s: front end %.3f m, AntSLAM %.3f m, %u loops\n",
                opt == LoopOptimizer::kAntColony ? "ACO" : "LM", e_front, e, run.loops);
    EXPECT_GT(run.loops, 0u);
    EXPECT_LT(e, 0.6 * e_front);
  }
}

// The final refinement (graph_refine.h, on by default): at finish() the whole graph's cost falls
// and the ring stays corrected. Not "closer to the truth than the frozen loops": this ring's front
// end errs only systematically (1 % long, 0.15°/m), which no edge covariance models, and the
// least-squares frames of such edges sit 1.5 cm further from the truth than Alg. 3's (0.121 vs
// 0.104–0.107 m, printed); on the logs' relations it was the other way round on four of five
// (README, AntSLAM section). Alg. 3's own closures (no isolation test), so that on and off
// differ by the refinement alone.
void expect_final_refinement_lowers_the_cost(LoopOptimizer opt) {
  const RingRun& r = ring();
  AntSlamOptions o = test_options(opt);
  o.gate_isolation = false;
  const SlamRun on = run_slam(r, o);
  o.final_refinement = false;
  const SlamRun off = run_slam(r, o);
  const double e_on = mean_error(on.poses, r.truth), e_off = mean_error(off.poses, r.truth);
  std::printf("%s: final refinement W %.2f -> %.2f (%u steps), error %.4f m (off %.4f m)\n",
              opt == LoopOptimizer::kAntColony ? "ACO" : "LM", on.stats.graph_initial_cost,
              on.stats.graph_final_cost, on.stats.graph_iterations, e_on, e_off);
  EXPECT_GT(on.loops, 0u);
  EXPECT_EQ(off.stats.graph_iterations, 0u);
  EXPECT_GT(on.stats.graph_iterations, 0u);
  EXPECT_LT(on.stats.graph_final_cost, 0.8 * on.stats.graph_initial_cost);
  EXPECT_LT(e_on, 0.2 * mean_error(r.frontend, r.truth));
}

// One case per optimiser (two whole runs each), so that the emulated and sanitized builds can run
// the ant colony's alone (toolchain/project.cmake): the refinement after LM is the same code.
TEST(AntSlamTest, FinalRefinementLowersTheWholeGraphsCost) {
  expect_final_refinement_lowers_the_cost(LoopOptimizer::kAntColony);
}
TEST(AntSlamTest, FinalRefinementAfterLmLowersTheWholeGraphsCost) {
  expect_final_refinement_lowers_the_cost(LoopOptimizer::kLevenbergMarquardt);
}

TEST(AntSlamTest, SameSeedSamePoses) {
  const SlamRun& a = ring_run(LoopOptimizer::kAntColony);
  const SlamRun b = run_slam(ring(), test_options(LoopOptimizer::kAntColony));
  ASSERT_EQ(a.poses.size(), b.poses.size());
  EXPECT_EQ(a.loops, b.loops);
  for (std::size_t i = 0; i < a.poses.size(); ++i) {
    ASSERT_EQ(a.poses[i].x, b.poses[i].x);
    ASSERT_EQ(a.poses[i].theta, b.poses[i].theta);
  }
}

TEST(AntSlamTest, NoHeapAfterInit) {
  if (!mmlfw_test::AllocCounter::available()) GTEST_SKIP() << "allocation counter unavailable under sanitizers";
  for (LoopOptimizer opt : {LoopOptimizer::kAntColony, LoopOptimizer::kLevenbergMarquardt}) {
    const SlamRun& run = ring_run(opt);
    EXPECT_GT(run.loops, 0u);
    EXPECT_EQ(run.allocations, 0) << "add_scan/finish allocated (loop closing, pRANSAM, optimiser)";
  }
}

// Sec. 3.4: with borders and EXPLORE → TRAVERSAL the second lap, once the first closure puts the
// robot back into the first lap's fragments, is traversed (tracked, not mapped): far fewer
// fragments, the trajectory still corrected, no heap.
TEST(AntSlamTest, SecondLapTraversesTheFirstLapsFragments) {
  AntSlamOptions o = test_options(LoopOptimizer::kLevenbergMarquardt);
  o.traversal = true;
  const SlamRun& off = ring_run(LoopOptimizer::kLevenbergMarquardt);
  const SlamRun on = run_slam(ring(), o);
  const RingRun& r = ring();
  ASSERT_EQ(on.poses.size(), r.truth.size());
  const double e_front = mean_error(r.frontend, r.truth), e = mean_error(on.poses, r.truth);
  std::printf("traversal: %u fragments (off: %u), %u loops, %u entries, %u of %zu scans traversed, %u borders; "
              "error %.3f m (front end %.3f, off %.3f)\n",
              on.fragments, off.fragments, on.loops, on.stats.traversals, on.stats.traversal_scans, r.truth.size(),
              on.stats.borders, e, e_front, mean_error(off.poses, r.truth));
  EXPECT_GT(on.loops, 0u);
  EXPECT_GT(on.stats.traversals, 0u);
  EXPECT_GT(on.stats.traversal_scans, r.truth.size() / 4);  // most of the second lap
  EXPECT_LT(on.fragments, off.fragments);
  EXPECT_TRUE(on.states_ok);
  EXPECT_LT(e, 0.6 * e_front);
  if (on.allocations >= 0) EXPECT_EQ(on.allocations, 0);
  // Tracking in the traversed fragment (fits on its field): the exact scans here re-anchor the
  // drifting front end (on the CARMEN logs it is mixed: README).
  o.traversal_tracking = true;
  const SlamRun tracked = run_slam(ring(), o);
  const double et = mean_error(tracked.poses, r.truth);
  std::printf("traversal with tracking: %u fits, error %.3f m\n", tracked.stats.traversal_fits, et);
  EXPECT_GT(tracked.stats.traversal_fits, 0u);
  EXPECT_LT(et, e);
  AntSlamOptions bad = o;
  bad.max_hull_points = 2;
  EXPECT_FALSE(bad.validate().is_ok());
}

// Eq. 3.4 w.r.t. every fragment: the pose in an older fragment, compounded along the fragment
// sequence on demand, equals the pose and covariance propagated scan by scan from that fragment's frame.
TEST(AntSlamTest, PoseInEveryFragmentMatchesPropagationFromItsFrame) {
  AntSlamOptions o = default_antslam_options();
  o.max_scans = 400;
  o.max_fragments = 8;
  o.max_closures = 4;
  o.max_loop_steps = 8;
  o.edge_model = EdgeModel::kMotionModel;  // no points: the Eq. 3.4 covariance on every edge
  std::vector<unsigned char> block(AntSlam::required_arena_bytes(o));
  StartupArena arena;
  ASSERT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
  auto slam = std::make_unique<AntSlam>();
  ASSERT_TRUE(slam->init(o, arena).is_ok());
  // 13 m along a gentle curve: fragments 0, 1, 2. Direct propagation from F_0 (the first pose).
  std::vector<Se2d> poses;
  for (int i = 0; i <= 130; ++i) poses.emplace_back(0.1 * i, 0.002 * i * i * 0.01, 0.004 * i);
  Se2d x;
  Mat3 cov = Mat3::Zero();
  for (std::size_t i = 0; i < poses.size(); ++i) {
    ASSERT_TRUE(slam->add_scan(poses[i], nullptr, 0).is_ok());
    if (i == 0) continue;
    const Se2d u = poses[i - 1].between(poses[i]);
    const double d = std::hypot(u.x, u.y);
    Mat3 g = Mat3::Zero();
    g(0, 0) = g(1, 1) = o.var_xy_per_m * d;
    g(2, 2) = o.var_theta_per_m * d + o.var_theta_per_rad * std::fabs(u.theta);
    const Mat3 jx = x.jacobian_compose_first(u), ju = x.jacobian_compose_second();
    cov = jx * cov * jx.transpose() + ju * g * ju.transpose();
    x = x.compose(u);
  }
  ASSERT_EQ(slam->num_fragments(), 3u);
  Se2d p;
  Mat3 c;
  ASSERT_TRUE(slam->pose_in_fragment(0, &p, &c));
  const Se2d truth = poses[0].between(poses.back());
  EXPECT_NEAR(p.x, truth.x, 1e-9);
  EXPECT_NEAR(p.y, truth.y, 1e-9);
  EXPECT_NEAR(p.theta, truth.theta, 1e-9);
  for (int r = 0; r < 3; ++r) {
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c(r, k), cov(r, k), 1e-6 + 1e-3 * std::fabs(cov(r, k))) << r << "," << k;
  }
  // Nearer fragments know the pose better; the active one is the tracked pose itself.
  Se2d p1, p2;
  Mat3 c1, c2;
  ASSERT_TRUE(slam->pose_in_fragment(1, &p1, &c1));
  ASSERT_TRUE(slam->pose_in_fragment(2, &p2, &c2));
  EXPECT_GT(c.trace(), c1.trace());
  EXPECT_GT(c1.trace(), c2.trace());
  EXPECT_FALSE(slam->pose_in_fragment(3, &p, &c));
}

TEST(AntSlamTest, RejectsBadOptionsAndFullCapacity) {
  AntSlamOptions o = default_antslam_options();
  o.fragment_length_m = 0;
  EXPECT_FALSE(o.validate().is_ok());
  o = default_antslam_options();
  o.max_scans = 3;
  o.max_fragments = 4;
  o.max_closures = 2;
  o.max_loop_steps = 4;
  std::vector<unsigned char> block(AntSlam::required_arena_bytes(o));
  StartupArena arena;
  ASSERT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
  auto slam = std::make_unique<AntSlam>();
  ASSERT_TRUE(slam->init(o, arena).is_ok());
  for (int i = 0; i < 3; ++i) EXPECT_TRUE(slam->add_scan(Se2d(0.1 * i, 0, 0), nullptr, 0).is_ok());
  const Status st = slam->add_scan(Se2d(1, 0, 0), nullptr, 0);
  EXPECT_EQ(st.code(), Errc::kCapacityExceeded);
  EXPECT_FALSE(slam->add_scan(Se2d(NAN, 0, 0), nullptr, 0).is_ok());
}

}  // namespace
}  // namespace fw::antslam
