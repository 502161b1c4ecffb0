// ACO (Eq. 3.13–3.14) and LM on a small synthetic loop with a known answer: 12 fragments on a
// circle, every adjacent edge measured with a bias (drift) so that the chain misses the start, and
// a precise closure measurement. Both optimisers must pull the loop shut and lower W. And the
// sampled options of an edge (Eq. 3.10) are the same for one seed on every target.
#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <cstdio>
#include <vector>

#include "firmware/antslam/ant_colony.h"
#include "firmware/antslam/loop_lm.h"

namespace fw::antslam {
namespace {

struct SyntheticLoop {
  static constexpr std::uint32_t kEdges = 12;
  static constexpr std::uint32_t kOptions = 40;
  std::vector<SampledEdge> edges = std::vector<SampledEdge>(kEdges);
  std::vector<Se2d> options = std::vector<Se2d>(kEdges * kOptions);
  std::vector<double> costs = std::vector<double>(kEdges * kOptions);
  std::vector<LoopStep> steps = std::vector<LoopStep>(kEdges);
  std::vector<Se2d> truth = std::vector<Se2d>(kEdges);
  LoopProblem problem;

  explicit SyntheticLoop(bool reverse_some) {
    RandomStream rng(7, 0);
    const double r = 10.0, step = 2 * M_PI / kEdges;
    for (std::uint32_t i = 0; i < kEdges; ++i) {
      const Se2d a(r * std::cos(i * step), r * std::sin(i * step), i * step + M_PI / 2);
      const Se2d b(r * std::cos((i + 1) * step), r * std::sin((i + 1) * step), (i + 1) * step + M_PI / 2);
      truth[i] = a.between(b);
      // Drift: every measured edge turns 1.5° too far and is 3 % too long.
      const Se2d mean(truth[i].x * 1.03, truth[i].y * 1.03, wrap_angle(truth[i].theta + 1.5 * M_PI / 180));
      Mat3 cov = Mat3::Zero();
      cov.diagonal() << 0.05 * 0.05, 0.05 * 0.05, std::pow(1.5 * M_PI / 180, 2);
      const bool flip = reverse_some && (i % 3 == 1);
      const Se2d stored = flip ? mean.inverse() : mean;
      // A reversed edge stores the inverse; its covariance is close enough for a test.
      EXPECT_TRUE(init_sampled_edge(flip ? i + 1 : i, flip ? i : i + 1, stored, cov, &options[i * kOptions],
                                    &costs[i * kOptions], kOptions, rng, &edges[i])
                      .is_ok());
      steps[i] = LoopStep{&edges[i], !flip};
    }
    problem.steps = steps.data();
    problem.num_steps = kEdges;
    problem.closure_mean = Se2d();  // back at the start: F_n = F_0
    problem.closure_info = Mat3::Zero();
    problem.closure_info.diagonal() << 1 / (0.02 * 0.02), 1 / (0.02 * 0.02), 1 / std::pow(0.5 * M_PI / 180, 2);
  }
  std::vector<Se2d> means() const {
    std::vector<Se2d> v;
    for (const auto& e : edges) v.push_back(e.mean);
    return v;
  }
  Se2d chain(const std::vector<Se2d>& v) const {
    Se2d x;
    for (std::uint32_t i = 0; i < kEdges; ++i) x = x.compose(step_transform(steps[i], v[i]));
    return x;
  }
};

double closure_gap(const Se2d& x) { return std::hypot(x.x, x.y); }

struct ArenaBlock {
  std::vector<unsigned char> bytes = std::vector<unsigned char>(1 << 20);
  StartupArena arena;
  ArenaBlock() { EXPECT_TRUE(arena.init(bytes.data(), bytes.size(), "test").is_ok()); }
};

TEST(AntColonyTest, ClosesASyntheticLoopAndLowersTheCost) {
  for (bool reverse : {false, true}) {
    SyntheticLoop loop(reverse);
    const double gap0 = closure_gap(loop.chain(loop.means()));
    ASSERT_GT(gap0, 1.0);  // the drift really opens the loop
    ArenaBlock block;
    AntColony aco;
    AntColonyOptions o;
    o.iterations = 2000;
    ASSERT_TRUE(aco.init(o, 64, SyntheticLoop::kOptions, block.arena).is_ok());
    std::vector<Se2d> values(SyntheticLoop::kEdges);
    AntColonyReport rep;
    ASSERT_TRUE(aco.solve(loop.problem, 0, values.data(), &rep).is_ok());
    EXPECT_LT(rep.best_cost, 0.2 * rep.initial_cost);
    EXPECT_NEAR(loop_cost(loop.problem, values.data()), rep.best_cost, 1e-9 * rep.best_cost);
    EXPECT_LT(closure_gap(loop.chain(values)), 0.3 * gap0) << "reverse " << reverse;
    // The answer, for scripts/check_cross_target.py (host against aarch64): the sampled edges
    // (Eq. 3.10) and the colony's choices must be the same on every target.
    for (std::uint32_t i = 0; i < SyntheticLoop::kEdges; ++i) {
      std::printf("trace aco %d %u %a %a %a\n", reverse ? 1 : 0, i, values[i].x, values[i].y, values[i].theta);
    }
  }
}

TEST(AntColonyTest, SameSeedSameAnswerWithAndWithoutWorkers) {
  SyntheticLoop loop(true);
  std::vector<Se2d> a(SyntheticLoop::kEdges), b(SyntheticLoop::kEdges);
  AntColonyOptions o;
  o.iterations = 300;
  {
    ArenaBlock block;
    AntColony aco;
    ASSERT_TRUE(aco.init(o, 64, SyntheticLoop::kOptions, block.arena).is_ok());
    ASSERT_TRUE(aco.solve(loop.problem, 3, a.data(), nullptr).is_ok());
  }
  {
    ArenaBlock block;
    WorkerPool pool;
    WorkerPoolOptions po;
    po.num_workers = 2;
    po.pin = false;
    ASSERT_TRUE(pool.start(po).is_ok());
    AntColony aco;
    ASSERT_TRUE(aco.init(o, 64, SyntheticLoop::kOptions, block.arena, &pool).is_ok());
    ASSERT_TRUE(aco.solve(loop.problem, 3, b.data(), nullptr).is_ok());
    pool.stop();
  }
  for (std::uint32_t i = 0; i < SyntheticLoop::kEdges; ++i) {
    EXPECT_EQ(a[i].x, b[i].x);
    EXPECT_EQ(a[i].theta, b[i].theta);
  }
}

TEST(AntColonyTest, FrozenEdgesKeepTheirValue) {
  SyntheticLoop loop(false);
  loop.edges[4].frozen = true;
  loop.edges[4].value = loop.truth[4];
  ArenaBlock block;
  AntColony aco;
  AntColonyOptions o;
  o.iterations = 200;
  ASSERT_TRUE(aco.init(o, 64, SyntheticLoop::kOptions, block.arena).is_ok());
  std::vector<Se2d> values(SyntheticLoop::kEdges);
  ASSERT_TRUE(aco.solve(loop.problem, 0, values.data(), nullptr).is_ok());
  EXPECT_EQ(values[4].x, loop.truth[4].x);
  EXPECT_EQ(values[4].theta, loop.truth[4].theta);
}

TEST(AntColonyTest, RejectsBadOptions) {
  AntColonyOptions o;
  o.ants = 0;
  EXPECT_FALSE(o.validate().is_ok());
  o = AntColonyOptions{};
  o.tau_min = 2.0;
  EXPECT_FALSE(o.validate().is_ok());
}

TEST(LoopLmTest, ClosesASyntheticLoopNearTheTruth) {
  for (bool reverse : {false, true}) {
    SyntheticLoop loop(reverse);
    ArenaBlock block;
    LoopLm lm;
    ASSERT_TRUE(lm.init(LoopLmOptions{}, 64, block.arena).is_ok());
    std::vector<Se2d> values = loop.means();
    const double gap0 = closure_gap(loop.chain(values));
    LoopLmReport rep;
    ASSERT_TRUE(lm.solve(loop.problem, values.data(), &rep).is_ok());
    EXPECT_LT(rep.final_cost, 0.05 * rep.initial_cost);
    EXPECT_LT(closure_gap(loop.chain(values)), 0.05 * gap0) << "reverse " << reverse;
    // The closed loop is closer to the truth than the drifting measurements (mean edge error).
    double err0 = 0, err1 = 0;
    for (std::uint32_t i = 0; i < SyntheticLoop::kEdges; ++i) {
      const Se2d t = reverse && i % 3 == 1 ? loop.truth[i].inverse() : loop.truth[i];
      err0 += std::fabs(wrap_angle(loop.edges[i].mean.theta - t.theta));
      err1 += std::fabs(wrap_angle(values[i].theta - t.theta));
    }
    EXPECT_LT(err1, 0.5 * err0);
  }
}

TEST(LoopLmTest, NothingToDoWhenTheLoopIsAlreadyShut) {
  SyntheticLoop loop(false);
  for (auto& e : loop.edges) {
    e.mean = loop.truth[&e - &loop.edges[0]];
  }
  ArenaBlock block;
  LoopLm lm;
  ASSERT_TRUE(lm.init(LoopLmOptions{}, 64, block.arena).is_ok());
  std::vector<Se2d> values = loop.means();
  LoopLmReport rep;
  ASSERT_TRUE(lm.solve(loop.problem, values.data(), &rep).is_ok());
  EXPECT_LT(rep.initial_cost, 1e-6);
  for (std::uint32_t i = 0; i < SyntheticLoop::kEdges; ++i) EXPECT_NEAR(values[i].x, loop.truth[i].x, 1e-6);
}

// The options of an edge are a function of the seed alone, on every compiler and target: each
// option k > 0 is μ + L·(x, y, z) with z, y, x drawn in that order (Eq. 3.10). A constructor taking
// three draws as arguments left their order to the compiler (x86-64 GCC drew z first, aarch64 GCC
// x first), so the same seed gave different edges, and loop corrections, on the robot's computer.
TEST(SampledEdgeTest, OptionsFollowTheDrawOrderOnEveryTarget) {
  Mat3 cov;
  cov << 0.04, 0.01, 0.002, 0.01, 0.09, -0.003, 0.002, -0.003, 0.0025;
  const Se2d mean(1.0, -2.0, 0.3);
  constexpr std::uint32_t kCount = 5;
  Se2d options[kCount];
  double costs[kCount];
  SampledEdge edge;
  RandomStream rng(2012, 7);
  ASSERT_TRUE(init_sampled_edge(0, 1, mean, cov, options, costs, kCount, rng, &edge).is_ok());
  const Mat3 l = cov.llt().matrixL();
  RandomStream replay(2012, 7);
  for (std::uint32_t k = 1; k < kCount; ++k) {
    const double gz = replay.gaussian();
    const double gy = replay.gaussian();
    const double gx = replay.gaussian();
    const Vec3 t = Vec3(mean.x, mean.y, mean.theta) + l * Vec3(gx, gy, gz);
    EXPECT_NEAR(options[k].x, t(0), 1e-12) << k;
    EXPECT_NEAR(options[k].y, t(1), 1e-12) << k;
    EXPECT_NEAR(options[k].theta, wrap_angle(t(2)), 1e-12) << k;
  }
}

}  // namespace
}  // namespace fw::antslam
