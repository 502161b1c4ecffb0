// The reference's motion while the wheels report rest: only rest pairs count, the figure is the
// reference's own motion between them, and a moving robot with a faithful reference gives nothing.
#include "sim/eval/mml_eval/reference_rest_scatter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace sim::mmleval {
namespace {

TEST(ReferenceRestScatter, MeasuresTheReferenceJitterOnlyWhereTheWheelsStandStill) {
  std::vector<fw::Se2d> odo, ref;
  // 100 scans driving 0.1 m per scan along a heading of 30°: the reference follows the odometry
  // exactly, except for a 0.2 m / 3° jump that is no rest pair (the wheels moved) and must not count.
  fw::Se2d p(1.0, 2.0, 0.5236);
  for (int i = 0; i < 100; ++i) {
    odo.push_back(p);
    ref.push_back(i == 50 ? p.compose(fw::Se2d(0.2, 0.0, 0.0524)) : p);
    p = p.compose(fw::Se2d(0.1, 0.0, 0.0));
  }
  RestScatter s = reference_rest_scatter(ref, odo);
  EXPECT_EQ(s.pairs, 0u);
  EXPECT_TRUE(std::isnan(s.m_p99));
  // Then 101 scans at rest: the reference alternates 4 cm / 1° off, every other scan; one pair 10 cm.
  const fw::Se2d rest = p;
  for (int i = 0; i <= 100; ++i) {
    odo.push_back(rest);
    fw::Se2d r = rest;
    if (i % 2 == 1) r = rest.compose(fw::Se2d(0.0, 0.04, 0.01745));
    if (i == 100) r = rest.compose(fw::Se2d(0.10, 0.0, 0.0));
    ref.push_back(r);
  }
  s = reference_rest_scatter(ref, odo);
  EXPECT_EQ(s.pairs, 100u);  // the 100 pairs inside the rest episode; the pair entering it moved
  EXPECT_NEAR(s.m_p50, 0.04, 1e-3);
  EXPECT_NEAR(s.rad_p50, 0.01745, 1e-4);
  // The 10 cm pair is the largest of 100: p99 (interpolated, as every figure of the evaluation)
  // moves only 0.7 mm off 4 cm; a loose rest rule lets the driving pairs in.
  EXPECT_NEAR(s.m_p99, 0.04, 1e-3);
  RestScatterOptions loose;
  loose.rest_m = 0.5;
  loose.rest_rad = 0.1;
  const RestScatter l = reference_rest_scatter(ref, odo, loose);
  EXPECT_EQ(l.pairs, 200u);
}

TEST(ReferenceRestScatter, FaithfulReferenceAtRestScattersNothing) {
  std::vector<fw::Se2d> odo(20, fw::Se2d(3.0, -1.0, 2.0)), ref(20, fw::Se2d(-7.0, 4.0, -0.3));
  const RestScatter s = reference_rest_scatter(ref, odo);
  EXPECT_EQ(s.pairs, 19u);
  EXPECT_NEAR(s.m_p99, 0.0, 1e-12);
  EXPECT_NEAR(s.rad_p99, 0.0, 1e-12);
}

}  // namespace
}  // namespace sim::mmleval
