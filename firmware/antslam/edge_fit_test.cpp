// Eq. 3.9 edge covariances (edge_fit.h): the data decide the shape of Σ.
#include "firmware/antslam/edge_fit.h"
#include "firmware/antslam/field_test_util.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace fw::antslam {
namespace {

using field_test::Field;
using field_test::wall;

// The scene: the model's points seen from `pose` (moved into the pose's frame).
std::vector<Point2f> seen_from(const std::vector<Point2f>& model, const Se2d& pose) {
  std::vector<Point2f> s;
  const Se2d inv = pose.inverse();
  const double c = std::cos(inv.theta), sn = std::sin(inv.theta);
  for (const Point2f& p : model) {
    s.emplace_back(static_cast<float>(inv.x + c * p(0) - sn * p(1)), static_cast<float>(inv.y + sn * p(0) + c * p(1)));
  }
  return s;
}

TEST(EdgeFit, CorridorIsOpenAlongItsAxisAndPinnedAcross) {
  std::vector<Point2f> model;
  wall(-10.0f, -1.0f, 10.0f, -1.0f, &model);  // a 20 m corridor, 2 m wide, along x
  wall(-10.0f, 1.0f, 10.0f, 1.0f, &model);
  Field f(model);
  const Se2d pose(0.3, 0.1, 0.05);
  // The scene: 6 m of both walls around the robot (a scan in the corridor).
  std::vector<Point2f> part;
  wall(-3.0f, -1.0f, 3.0f, -1.0f, &part);
  wall(-3.0f, 1.0f, 3.0f, 1.0f, &part);
  const std::vector<Point2f> scene = seen_from(part, pose);
  EdgeFit fit;
  ASSERT_TRUE(fit_edge(f.field, scene.data(), scene.size(), pose, EdgeFitOptions(), &fit));
  const double sx = std::sqrt(fit.cov(0, 0)), sy = std::sqrt(fit.cov(1, 1));
  EXPECT_GT(sx, 0.10) << "along the corridor the walls say nothing";
  EXPECT_LT(sy, 0.03) << "across it they pin the pose";
  EXPECT_GT(sx, 5.0 * sy);
  EXPECT_NEAR(fit.weighted_mean.y, pose.y, 0.01);
  EXPECT_NEAR(fit.weighted_mean.theta, pose.theta, 0.005);
}

TEST(EdgeFit, RoomWithCornersPinsEveryAxisAndFewerCellsWidenIt) {
  std::vector<Point2f> model;
  wall(-3.0f, -2.0f, 3.0f, -2.0f, &model);
  wall(3.0f, -2.0f, 3.0f, 2.0f, &model);
  wall(3.0f, 2.0f, -3.0f, 2.0f, &model);
  wall(-3.0f, 2.0f, -3.0f, -2.0f, &model);
  Field f(model);
  const Se2d pose(-0.4, 0.2, -0.3);
  const std::vector<Point2f> scene = seen_from(model, pose);
  EdgeFit room;
  ASSERT_TRUE(fit_edge(f.field, scene.data(), scene.size(), pose, EdgeFitOptions(), &room));
  EXPECT_LT(std::sqrt(room.cov(0, 0)), 0.03);
  EXPECT_LT(std::sqrt(room.cov(1, 1)), 0.03);
  EXPECT_LT(std::sqrt(room.cov(2, 2)), 0.01);
  EXPECT_LT(room.step_xy_m, EdgeFitOptions().step_xy_m) << "a sharp fit is resolved by a finer grid";
  EXPECT_NEAR(room.weighted_mean.x, pose.x, 0.01);
  EXPECT_NEAR(room.weighted_mean.y, pose.y, 0.01);
  // The same walls counted in 4 m cells are fewer independent observations: a wider Σ.
  EdgeFitOptions coarse;
  coarse.correlation_m = 4.0;
  EdgeFit few;
  ASSERT_TRUE(fit_edge(f.field, scene.data(), scene.size(), pose, coarse, &few));
  EXPECT_LT(few.independent, room.independent);
  EXPECT_GT(few.cov(0, 0), room.cov(0, 0));
  EXPECT_GT(few.cov(2, 2), room.cov(2, 2));
}

TEST(EdgeFit, RefusesWhatItCannotFit) {
  std::vector<Point2f> model;
  wall(-3.0f, -2.0f, 3.0f, -2.0f, &model);
  Field no_distance(model, /*keep_distance=*/false);
  EdgeFit fit;
  EXPECT_FALSE(fit_edge(no_distance.field, model.data(), model.size(), Se2d(), EdgeFitOptions(), &fit));
  Field f(model);
  EXPECT_FALSE(fit_edge(f.field, model.data(), 2, Se2d(), EdgeFitOptions(), &fit)) << "two points";
  const std::vector<Point2f> nan_pts(10, Point2f(NAN, 0.0f));
  EXPECT_FALSE(fit_edge(f.field, nan_pts.data(), nan_pts.size(), Se2d(), EdgeFitOptions(), &fit));
  EdgeFitOptions bad;
  bad.grid_half = 5;
  EXPECT_FALSE(bad.validate().is_ok());
  EXPECT_FALSE(fit_edge(f.field, model.data(), model.size(), Se2d(), bad, &fit));
  bad = EdgeFitOptions();
  bad.sigma_m = 0.0;
  EXPECT_FALSE(bad.validate().is_ok());
}

}  // namespace
}  // namespace fw::antslam
