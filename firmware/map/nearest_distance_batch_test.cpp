// Every build of the nearest-cell batch (nearest_distance_batch.h) gives GlobalMap::distance_at's
// bits: on the grid, off it on every side, on cell and tile borders, in tiles that are not stored, at
// NaN and infinities, for batches of every length.
#include "firmware/map/nearest_distance_batch.h"

#include <gtest/gtest.h>

#include <cstring>
#include <limits>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/map/two_wall_test_map.h"

namespace fw {
namespace {

// Returns how many of the points fell on the grid (for the coverage checks).
std::size_t expect_builds_equal(const GlobalMap& map, const std::vector<Point2f>& pts, float tx, float ty) {
  std::size_t on = 0;
  for (const DistanceBatchBuild build :
       {DistanceBatchBuild::kBest, DistanceBatchBuild::kPortable, DistanceBatchBuild::kScalar}) {
    float d[kDistanceBatch];
    nearest_distance_batch(map, pts.data(), pts.size(), tx, ty, 1e9f, d, build);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const float want = map.distance_at(tx + pts[i].x(), ty + pts[i].y(), 1e9f);
      EXPECT_TRUE(same_float_bits(d[i], want)) << "build " << static_cast<int>(build) << " point " << i << ": " << d[i]
                                         << " vs " << want;
      if (build == DistanceBatchBuild::kScalar && want < 1e9f) ++on;
    }
  }
  return on;
}

TEST(NearestDistanceBatchTest, EveryBuildGivesDistanceAtsBits) {
  const TwoWallTestMap t;
  RandomStream rng(11, 0);
  std::size_t on_grid = 0, total = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const std::size_t n = 1 + static_cast<std::size_t>(trial) % kDistanceBatch;
    std::vector<Point2f> pts(n);
    for (auto& p : pts) {  // one draw per statement: argument order is unspecified
      const float y = static_cast<float>(rng.uniform(-1.5, 1.5));
      p = Point2f(static_cast<float>(rng.uniform(-2.5, 2.5)), y);
    }
    const float tx = static_cast<float>(rng.uniform(-0.5, 1.5));
    const float ty = static_cast<float>(rng.uniform(1.0, 2.0));
    on_grid += expect_builds_equal(t.map, pts, tx, ty);
    total += n;
    if (HasFailure()) return;
  }
  // Both sides of the grid's edge occurred (the map spans x −1.3..2.2, y 0.7..3.2).
  EXPECT_GT(on_grid, total / 4);
  EXPECT_LT(on_grid, total - total / 4);
}

TEST(NearestDistanceBatchTest, CellBordersAndGridEdgesRoundAsDistanceAt) {
  const TwoWallTestMap t;
  const GlobalMap& m = t.map;
  // Points exactly on cell borders, a float step either side, and on the grid's four edges.
  std::vector<Point2f> pts;
  for (int k = -1; k <= 71; k += 9) {
    const float bx = m.geometry.origin_x + static_cast<float>(k) * m.geometry.resolution;
    for (const float x : {std::nextafter(bx, -10.0f), bx, std::nextafter(bx, 10.0f)}) {
      pts.emplace_back(x, m.geometry.origin_y + 0.52f);
      pts.emplace_back(0.1f, m.geometry.origin_y + static_cast<float>(k % 51) * m.geometry.resolution);
    }
  }
  ASSERT_LE(pts.size(), kDistanceBatch);
  expect_builds_equal(m, pts, 0.0f, 0.0f);
}

TEST(NearestDistanceBatchTest, NanAndInfinitePointsAreOffTheGrid) {
  const TwoWallTestMap t;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<Point2f> pts = {Point2f(nan, 0.0f), Point2f(0.0f, nan), Point2f(inf, 0.1f), Point2f(-inf, 0.1f),
                                    Point2f(0.1f, -inf), Point2f(0.2f, 0.1f)};
  for (const DistanceBatchBuild build :
       {DistanceBatchBuild::kBest, DistanceBatchBuild::kPortable, DistanceBatchBuild::kScalar}) {
    float d[kDistanceBatch];
    nearest_distance_batch(t.map, pts.data(), pts.size(), 0.5f, 1.5f, -7.0f, d, build);
    for (int i = 0; i < 5; ++i) EXPECT_EQ(d[i], -7.0f) << "build " << static_cast<int>(build) << " point " << i;
    EXPECT_GE(d[5], 0.0f);
  }
}

}  // namespace
}  // namespace fw
