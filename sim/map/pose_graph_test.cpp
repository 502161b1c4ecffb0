#include "sim/map/pose_graph.h"

#include <gtest/gtest.h>

#include <cmath>


namespace sim {
namespace {

// A 40-pose loop around a 10 x 10 m square with exact relative measurements (consecutive links
// and a loop closure) starting from a badly drifted initial guess: the optimizer must recover the
// true poses (node 0 fixed).
TEST(PoseGraphTest, RecoversLoopFromDriftedInitialGuess) {
  std::vector<fw::Se2d> truth;
  for (int side = 0; side < 4; ++side) {
    for (int k = 0; k < 10; ++k) {
      const double th = side * M_PI / 2;
      fw::Se2d start = side == 0 ? fw::Se2d(0, 0, 0) : side == 1 ? fw::Se2d(10, 0, 0) : side == 2 ? fw::Se2d(10, 10, 0) : fw::Se2d(0, 10, 0);
      truth.push_back(fw::Se2d(start.x + std::cos(th) * k, start.y + std::sin(th) * k, fw::wrap_angle(th)));
    }
  }
  std::vector<PoseGraphEdge> edges;
  const std::size_t n = truth.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    PoseGraphEdge e;
    e.i = i;
    e.j = i + 1;
    e.z = truth[i].between(truth[i + 1]);
    edges.push_back(e);
  }
  PoseGraphEdge loop;
  loop.i = n - 1;
  loop.j = 0;
  loop.z = truth[n - 1].between(truth[0]);
  edges.push_back(loop);
  // Drifted guess: chain the links with a heading bias of 1.5 deg per step.
  std::vector<fw::Se2d> x(n);
  x[0] = truth[0];
  for (std::size_t i = 0; i + 1 < n; ++i) {
    fw::Se2d step = edges[i].z;
    step.theta += 0.026;
    x[i + 1] = x[i].compose(step);
  }
  PoseGraphResult r;
  std::string err;
  ASSERT_TRUE(optimize_pose_graph(&x, edges, PoseGraphOptions{}, &r, &err)) << err;
  EXPECT_GT(r.initial_chi2, 1.0);
  EXPECT_LT(r.final_chi2, 1e-12);
  for (std::size_t i = 0; i < n; ++i) {
    EXPECT_NEAR(x[i].x, truth[i].x, 1e-6) << i;
    EXPECT_NEAR(x[i].y, truth[i].y, 1e-6) << i;
    EXPECT_NEAR(fw::wrap_angle(x[i].theta - truth[i].theta), 0.0, 1e-7) << i;
  }
}

TEST(PoseGraphTest, NoisyLoopClosureSpreadsError) {
  // Straight 20-pose line, links say 1 m each, a closure says node 19 is 19.2 m from node 0:
  // least squares spreads the 0.2 m over the 20 equally weighted constraints (each 1.01 m).
  const std::size_t n = 20;
  std::vector<PoseGraphEdge> edges;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    PoseGraphEdge e;
    e.i = i;
    e.j = i + 1;
    e.z = fw::Se2d(1.0, 0, 0);
    edges.push_back(e);
  }
  PoseGraphEdge c;
  c.i = 0;
  c.j = n - 1;
  c.z = fw::Se2d(19.2, 0, 0);
  edges.push_back(c);
  std::vector<fw::Se2d> x(n);
  for (std::size_t i = 0; i < n; ++i) x[i] = fw::Se2d(static_cast<double>(i), 0, 0);
  PoseGraphResult r;
  std::string err;
  ASSERT_TRUE(optimize_pose_graph(&x, edges, PoseGraphOptions{}, &r, &err)) << err;
  EXPECT_NEAR(x[n - 1].x, 19.0 + 0.2 * 19.0 / 20.0, 1e-6);
  EXPECT_NEAR(x[1].x, 1.01, 1e-6);
}

TEST(PoseGraphTest, BadGraphsAreErrors) {
  std::vector<fw::Se2d> x(3);
  std::string err;
  EXPECT_FALSE(optimize_pose_graph(&x, {}, PoseGraphOptions{}, nullptr, &err));
  PoseGraphEdge e;
  e.i = 0;
  e.j = 5;
  EXPECT_FALSE(optimize_pose_graph(&x, {e}, PoseGraphOptions{}, nullptr, &err));
  EXPECT_NE(err.find("bad node index"), std::string::npos) << err;
  e.j = 1;
  e.z.x = std::nan("");
  EXPECT_FALSE(optimize_pose_graph(&x, {e}, PoseGraphOptions{}, nullptr, &err));
  EXPECT_NE(err.find("not finite"), std::string::npos) << err;
}

}  // namespace
}  // namespace sim
