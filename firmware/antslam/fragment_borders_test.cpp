#include "firmware/antslam/fragment_borders.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

namespace fw::antslam {
namespace {

// The walls of a 2 m wide corridor along x from 0 to 10 m (points every 5 cm).
std::vector<Point2f> corridor_points() {
  std::vector<Point2f> p;
  for (int i = 0; i <= 200; ++i) {
    p.emplace_back(0.05f * i, 1.0f);
    p.emplace_back(0.05f * i, -1.0f);
  }
  return p;
}

TEST(FragmentBordersTest, SignedAreaTellsLeftFromRight) {  // Eq. 3.8
  EXPECT_GT(signed_area(0, 0, 1, 0, 0.5, 1), 0.0);
  EXPECT_LT(signed_area(0, 0, 1, 0, 0.5, -1), 0.0);
  EXPECT_EQ(signed_area(0, 0, 1, 0, 2, 0), 0.0);
}

TEST(FragmentBordersTest, BorderCrossesTheCorridorAtTheRobotAndKeepsTheFragmentToItsRight) {
  const std::vector<Point2f> p = corridor_points();
  const Se2d robot(6.0, 0.1, 0.05);  // heading along +x, slightly turned
  Border b;
  ASSERT_TRUE(select_border(p.data(), p.size(), robot, BorderOptions{}, &b));
  // b1 on the left wall, b2 on the right wall, both near the robot's x (Eq. 3.6: short and orthogonal).
  EXPECT_FLOAT_EQ(static_cast<float>(b.y1), 1.0f);
  EXPECT_FLOAT_EQ(static_cast<float>(b.y2), -1.0f);
  EXPECT_NEAR(b.x1, 6.0, 0.3);
  EXPECT_NEAR(b.x2, 6.0, 0.3);
  // The part already travelled (behind the robot) is right of b1 → b2; the part ahead is left.
  EXPECT_TRUE(right_of_borders(&b, 1, 3.0, 0.0));
  EXPECT_FALSE(right_of_borders(&b, 1, 8.0, 0.0));
  // The fragment entered gets the reversed border: ahead is its side.
  const Border r = b.reversed();
  EXPECT_TRUE(right_of_borders(&r, 1, 8.0, 0.0));
  EXPECT_FALSE(right_of_borders(&r, 1, 3.0, 0.0));
}

TEST(FragmentBordersTest, DistanceWeightPrefersTheNearWallOverAFarOrthogonalPoint) {
  // Left: the corridor wall 1 m away but 40° off the orthogonal, and a point 9 m away exactly
  // orthogonal. With α = 0.5 the near point wins; with α = 0 (orthogonality only) the far one.
  std::vector<Point2f> p = {{0.84f, 1.0f}, {0.0f, 9.0f}, {0.0f, -1.0f}};
  Border b;
  ASSERT_TRUE(select_border(p.data(), p.size(), Se2d(0, 0, 0), BorderOptions{}, &b));
  EXPECT_FLOAT_EQ(static_cast<float>(b.y1), 1.0f);
  BorderOptions orth;
  orth.alpha = 0.0;
  ASSERT_TRUE(select_border(p.data(), p.size(), Se2d(0, 0, 0), orth, &b));
  EXPECT_FLOAT_EQ(static_cast<float>(b.y1), 9.0f);
}

TEST(FragmentBordersTest, NoBorderInOpenSpaceOnOneSide) {
  std::vector<Point2f> p = {{1.0f, 1.0f}, {2.0f, 1.0f}};  // nothing to the right
  Border b{9, 9, 9, 9};
  EXPECT_FALSE(select_border(p.data(), p.size(), Se2d(0, 0, 0), BorderOptions{}, &b));
  EXPECT_EQ(b.x1, 9.0);  // untouched
  EXPECT_FALSE(select_border(p.data(), 0, Se2d(0, 0, 0), BorderOptions{}, &b));
}

TEST(FragmentBordersTest, GrahamScanMatchesABruteForceHullOnRandomClouds) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Point2f> p(200);
    for (auto& q : p) {  // one draw per statement (argument order is unspecified)
      const float y = u(rng);
      q = Point2f(u(rng), y);
    }
    std::vector<Point2f> scratch(p.size()), hull(p.size());
    const std::size_t m = convex_hull(p.data(), p.size(), scratch.data(), hull.data(), hull.size());
    ASSERT_GE(m, 3u);
    // Counter-clockwise and convex; every point inside; every vertex is an input point.
    for (std::size_t i = 0; i < m; ++i) {
      const Point2f& a = hull[i];
      const Point2f& b = hull[(i + 1) % m];
      const Point2f& c = hull[(i + 2) % m];
      EXPECT_GT(signed_area(a(0), a(1), b(0), b(1), c(0), c(1)), 0.0);
    }
    for (const auto& q : p) EXPECT_TRUE(inside_convex_hull(hull.data(), m, q(0), q(1)));
    // Brute force: a point is a hull vertex iff some line through it has all others on one side;
    // the count of extreme points in 64 directions is a lower bound the hull must contain.
    for (int k = 0; k < 64; ++k) {
      const float c = std::cos(0.0981747704f * k), s = std::sin(0.0981747704f * k);
      std::size_t best = 0;
      for (std::size_t j = 1; j < p.size(); ++j) {
        if (c * p[j](0) + s * p[j](1) > c * p[best](0) + s * p[best](1)) best = j;
      }
      bool found = false;
      for (std::size_t i = 0; i < m; ++i) found = found || hull[i] == p[best];
      EXPECT_TRUE(found) << "extreme point in direction " << k << " missing from the hull";
    }
    EXPECT_FALSE(inside_convex_hull(hull.data(), m, 6.0, 0.0));
  }
}

TEST(FragmentBordersTest, HullRefusesDegenerateInputAndTooSmallStorage) {
  std::vector<Point2f> line = {{0, 0}, {1, 1}, {2, 2}, {3, 3}};
  std::vector<Point2f> scratch(8), hull(8);
  EXPECT_EQ(convex_hull(line.data(), line.size(), scratch.data(), hull.data(), hull.size()), 0u);
  std::vector<Point2f> square = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0.5f}, {NAN, 0.0f}};
  EXPECT_EQ(convex_hull(square.data(), square.size(), scratch.data(), hull.data(), hull.size()), 4u);
  EXPECT_EQ(convex_hull(square.data(), square.size(), scratch.data(), hull.data(), 3), 0u);
}

TEST(FragmentBordersTest, MembershipNeedsTheBordersAndTheHull) {  // Fig. 3.4
  // An L-shaped fragment: the corridor of the first test plus a side corridor going up at x = 10.
  std::vector<Point2f> p = corridor_points();
  std::vector<Point2f> scratch(p.size()), hull(p.size());
  const std::size_t m = convex_hull(p.data(), p.size(), scratch.data(), hull.data(), hull.size());
  ASSERT_EQ(m, 4u);
  Border b;
  ASSERT_TRUE(select_border(p.data(), p.size(), Se2d(6.0, 0.0, 0.0), BorderOptions{}, &b));
  EXPECT_TRUE(inside_fragment(&b, 1, hull.data(), m, 2.0, 0.0));   // behind the border, in the hull
  EXPECT_FALSE(inside_fragment(&b, 1, hull.data(), m, 8.0, 0.0));  // ahead of the border
  EXPECT_FALSE(inside_fragment(&b, 1, hull.data(), m, 2.0, 5.0));  // right of the border but outside the hull
  EXPECT_FALSE(inside_fragment(&b, 1, hull.data(), 0, 2.0, 0.0));  // no hull: never inside
}

TEST(FragmentBordersTest, BorderTransformsIntoTheNextFragmentsFrame) {
  const Border b{1.0, 1.0, 1.0, -1.0};  // crossing a corridor along x at x = 1
  // The next fragment starts where the robot crosses it, turned by 0.3 rad.
  const Se2d next(1.0, 0.0, 0.3);
  const Border t = b.reversed().transformed(next.inverse());
  const Eigen::Vector2d p1 = next.inverse().transform_point(Eigen::Vector2d(1.0, -1.0));
  EXPECT_NEAR(t.x1, p1.x(), 1e-12);
  EXPECT_NEAR(t.y1, p1.y(), 1e-12);
  EXPECT_NEAR(t.length(), 2.0, 1e-12);
  // Ahead of the new origin is the new fragment's side, behind it the old one's.
  EXPECT_TRUE(right_of_borders(&t, 1, 0.5, 0.0));
  EXPECT_FALSE(right_of_borders(&t, 1, -0.5, 0.0));
}

}  // namespace
}  // namespace fw::antslam
