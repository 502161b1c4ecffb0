// The evaluation's second reference (reference_map_check.h) on a synthetic corridor with known poses:
// a right reference is kept, a reference whose heading is off is corrected in heading only — the
// corridor's flat direction never moves it.
#include "sim/eval/mml_eval/reference_map_check.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/mml/mml_test_util.h"
#include "sim/eval/mml_eval/corridor_test_world.h"

namespace sim::mmleval {
namespace {

using testing::corridor;
using testing::GridWorld;
using testing::scan_at;

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

TEST(JudgingRule, BeyondTheReferencePlusItsBoundAndNotClearedByTheMap) {
  JudgedError e;
  e.ref_m = 0.60;
  e.ref_ang = 1.0;
  // Beyond 0.5 m, no bound, no map pose: beyond.
  EXPECT_TRUE(beyond_reference(e, 0.5, 5.0));
  EXPECT_TRUE(judged_beyond(e, 0.5, 5.0));
  // The reference's own bound widens the limit: 0.60 m is within 0.5 + 0.15.
  e.bound_m = 0.15;
  EXPECT_FALSE(beyond_reference(e, 0.5, 5.0));
  EXPECT_FALSE(judged_beyond(e, 0.5, 5.0));
  e.bound_m = 0.0;
  // The map's pose explains the scan better and the estimate is within the limit of it: cleared.
  e.map_improves = true;
  e.map_m = 0.20;
  e.map_ang = 0.5;
  EXPECT_TRUE(beyond_reference(e, 0.5, 5.0));
  EXPECT_FALSE(judged_beyond(e, 0.5, 5.0));
  // … beyond it there too: judged beyond. A map pose that does not improve is never read.
  e.map_m = 0.55;
  EXPECT_TRUE(judged_beyond(e, 0.5, 5.0));
  e.map_improves = false;
  e.map_m = 0.0;
  EXPECT_TRUE(judged_beyond(e, 0.5, 5.0));
  // A limit component ≤ 0 is no limit (a pose without a heading bound), and the bound does not
  // create one.
  e.ref_m = 0.1;
  e.ref_ang = 30.0;
  e.bound_ang = 2.0;
  EXPECT_FALSE(judged_beyond(e, 0.5, 0.0));
  EXPECT_TRUE(judged_beyond(e, 0.5, 5.0));
}

}  // namespace
}  // namespace sim::mmleval
