// The unmapped-area rule (unmapped_scan.h) on a corridor whose map knows only its west half: a scan
// the map describes is not unmapped, one taken in the unknown half is, and the rule is judged at the
// pose it is given (the truth), not at an estimate.
#include "sim/eval/mml_eval/unmapped_scan.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "firmware/mml/mml_test_util.h"
#include "sim/eval/mml_eval/corridor_test_world.h"

namespace sim::mmleval {
namespace {

using testing::corridor;
using testing::GridWorld;
using testing::scan_at;

TEST(UnmappedScan, AScanTheMapDescribesIsNotUnmapped) {
  const GridWorld world = corridor(20.0f);
  const fw::mml::testing::OwnedGlobalMap full(world);
  const fw::Se2d truth(5.0, 2.0, 0.0);
  const UnmappedScan u = unmapped_scan(full.map, scan_at(world, truth.x, truth.y, truth.theta), truth);
  EXPECT_GT(u.points, 100u);
  EXPECT_EQ(u.unmapped, 0u);
  EXPECT_FALSE(in_unmapped_area(u));
}

TEST(UnmappedScan, ScanInTheUnknownHalfIsUnmappedAndOneLookingIntoItIsNot) {
  const GridWorld world = corridor(20.0f);
  const GridWorld half = corridor(10.0f);
  const fw::mml::testing::OwnedGlobalMap map(half);
  // Deep in the unknown half: every end-point on unknown cells far from the known walls.
  const fw::Se2d east(15.0, 2.0, 0.0);
  const UnmappedScan ue = unmapped_scan(map.map, scan_at(world, east.x, east.y, east.theta), east);
  EXPECT_GT(ue.fraction(), 0.9);
  EXPECT_TRUE(in_unmapped_area(ue));
  // In the known half looking east: the end-points beyond 10.3 m are unmapped, the rest are not,
  // and most of the scan is still described (the tracker's test asks for more than half).
  const fw::Se2d west(6.0, 2.0, 0.0);
  const UnmappedScan uw = unmapped_scan(map.map, scan_at(world, west.x, west.y, west.theta), west);
  EXPECT_GT(uw.unmapped, 0u);
  EXPECT_LT(uw.fraction(), 0.5);
  EXPECT_FALSE(in_unmapped_area(uw));
}

TEST(UnmappedScan, InvalidBeamsAreNotCountedAndAnEmptyScanIsNotUnmapped) {
  const GridWorld world = corridor(20.0f);
  const GridWorld half = corridor(10.0f);
  const fw::mml::testing::OwnedGlobalMap map(half);
  CarmenScan s = scan_at(world, 15.0, 2.0, 0.0);
  const std::size_t valid = unmapped_scan(map.map, s, fw::Se2d(15.0, 2.0, 0.0)).points;
  s.ranges[0] = std::numeric_limits<float>::quiet_NaN();
  s.ranges[1] = -1.0f;
  s.ranges[2] = s.max_range;  // no return
  EXPECT_EQ(unmapped_scan(map.map, s, fw::Se2d(15.0, 2.0, 0.0)).points, valid - 3);
  for (float& r : s.ranges) r = std::numeric_limits<float>::quiet_NaN();
  const UnmappedScan none = unmapped_scan(map.map, s, fw::Se2d(15.0, 2.0, 0.0));
  EXPECT_EQ(none.points, 0u);
  EXPECT_FALSE(in_unmapped_area(none));
}

// A reference far from where the scan was taken: the map is known there but explains little of it
// (reference_off_map); at the truth, or where the map is unknown, it is not "off the map".
TEST(UnmappedScan, AReferenceTheMapDoesNotExplainIsOffTheMap) {
  const GridWorld world = corridor(20.0f);
  const fw::mml::testing::OwnedGlobalMap full(world);
  const CarmenScan s = scan_at(world, 5.0, 2.0, 0.0);
  const UnmappedScan at_truth = unmapped_scan(full.map, s, fw::Se2d(5.0, 2.0, 0.0));
  EXPECT_GT(at_truth.explained_fraction(), 0.95);
  EXPECT_FALSE(reference_off_map(at_truth));
  const UnmappedScan turned = unmapped_scan(full.map, s, fw::Se2d(5.0, 2.0, 0.6));  // 34° off
  EXPECT_LT(turned.explained_fraction(), 0.5);
  EXPECT_TRUE(reference_off_map(turned));
  const GridWorld half = corridor(10.0f);
  const fw::mml::testing::OwnedGlobalMap map(half);
  const UnmappedScan unknown = unmapped_scan(map.map, scan_at(world, 15.0, 2.0, 0.0), fw::Se2d(15.0, 2.0, 0.0));
  EXPECT_TRUE(in_unmapped_area(unknown));
  EXPECT_FALSE(reference_off_map(unknown));  // unmapped, not contradicted
}

}  // namespace
}  // namespace sim::mmleval
