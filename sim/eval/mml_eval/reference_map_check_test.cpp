// The evaluation's second reference (reference_map_check.h) on a synthetic corridor with known poses:
// a right reference is kept, a reference whose heading is off is corrected in heading only — the
// corridor's flat direction never moves it.
#include "sim/eval/mml_eval/reference_map_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/baselines/mcl/mcl_test_world.h"
#include "firmware/mml/mml_test_util.h"

namespace sim::mmleval {
namespace {

using fw::mcl::testing::GridWorld;

// 20 × 4 m: a 2 m wide corridor with no feature along it, closed far beyond the laser's 8 m.
GridWorld corridor() {
  GridWorld g;
  g.w = 400;
  g.h = 80;
  g.occ.assign(g.w * g.h, 0);
  g.box(0.2f, 1.0f, 19.8f, 3.0f);
  g.finish();
  return g;
}

CarmenScan scan_at(const GridWorld& g, double x, double y, double th) {
  static hal::LaserScan s;
  fw::mcl::testing::simulate_scan(g.view(), static_cast<float>(x), static_cast<float>(y), static_cast<float>(th), &s);
  return carmen_scan_of(s);
}

TEST(ReferenceMapCheck, KeepsAReferenceTheMapAgreesWith) {
  const GridWorld g = corridor();
  const fw::mml::testing::OwnedGlobalMap m(g);
  const fw::Se2d truth(10.0, 2.0, 0.1);
  const ReferenceMapFit f = check_reference_against_map(m.map, scan_at(g, truth.x, truth.y, truth.theta), truth);
  EXPECT_FALSE(f.improves);
  EXPECT_EQ(f.best.x, truth.x);
  EXPECT_EQ(f.best.theta, truth.theta);
}

TEST(ReferenceMapCheck, CorrectsTheHeadingWithoutSlidingAlongTheCorridor) {
  const GridWorld g = corridor();
  const fw::mml::testing::OwnedGlobalMap m(g);
  const fw::Se2d truth(10.0, 2.0, 0.1);
  const double off = 6.0 * M_PI / 180.0;
  const fw::Se2d reference(truth.x, truth.y, truth.theta + off);  // the heading alone is wrong
  const ReferenceMapFit f = check_reference_against_map(m.map, scan_at(g, truth.x, truth.y, truth.theta), reference);
  ASSERT_TRUE(f.improves);
  // Inliers within 10 cm: headings within about 1° of the truth explain the same end-points of walls
  // ≤ 8 m away, and the one nearest the reference is kept.
  EXPECT_LT(std::fabs(fw::wrap_angle(f.best.theta - truth.theta)), 1.5 * M_PI / 180.0);
  EXPECT_LT(std::fabs(f.best.y - truth.y), 0.03);
  // Every position along the corridor explains the scan equally: the map gives no reason to move
  // the reference along it (before ties went to the nearest pose, the first of them in scan order
  // was 0.4 m away at the window's edge).
  EXPECT_LT(std::fabs(f.best.x - reference.x), 0.03);
}

}  // namespace
}  // namespace sim::mmleval
