// Every build of the batch sampler (distance_batch.h) gives DistanceSampler's bits: on the grid, off
// it, across tile borders, in tiles that are not stored, at NaN, for batches of every length.
#include "firmware/map/distance_batch.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/map/distance_field.h"
#include "firmware/map/distance_sample.h"
#include "firmware/map/two_wall_test_map.h"

namespace fw {
namespace {

void expect_batches_equal(const GlobalMap& map, const std::vector<Point2f>& pts, const Se2f& pose, float clip) {
  const float c = std::cos(pose.theta), s = std::sin(pose.theta);
  const DistanceSampler<float> sample(map);
  for (const DistanceBatchBuild build : {DistanceBatchBuild::kBest, DistanceBatchBuild::kPortable}) {
    DistanceBatch ref, got;
    sample_distance_batch(map, pts.data(), pts.size(), pose.x, pose.y, c, s, clip, &ref, DistanceBatchBuild::kScalar);
    sample_distance_batch(map, pts.data(), pts.size(), pose.x, pose.y, c, s, clip, &got, build);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const float px = pts[i].x(), py = pts[i].y();
      float d = 0, gx = 0, gy = 0;
      const bool on = sample(pose.x + c * px - s * py, pose.y + s * px + c * py, &d, &gx, &gy);
      // The scalar build is DistanceSampler itself.
      ASSERT_EQ(ref.use[i], on && !(d > clip) ? 1 : 0) << i;
      ASSERT_EQ(got.use[i], ref.use[i]) << "build " << static_cast<int>(build) << " point " << i;
      if (!on) continue;  // off the grid the values are documented as meaningless
      ASSERT_TRUE(same_float_bits(got.d[i], d)) << i << ": " << got.d[i] << " vs " << d;
      ASSERT_TRUE(same_float_bits(got.gx[i], gx)) << i;
      ASSERT_TRUE(same_float_bits(got.gy[i], gy)) << i;
      ASSERT_TRUE(same_float_bits(got.jt[i], ref.jt[i])) << i;
      ASSERT_TRUE(same_float_bits(ref.jt[i], gx * (-s * px - c * py) + gy * (c * px - s * py))) << i;
    }
  }
}

TEST(DistanceBatchTest, EveryBuildGivesTheScalarSamplersBits) {
  const TwoWallTestMap t;
  ASSERT_GT(t.map.distance.stored_tiles, 0u);
  ASSERT_LT(t.map.distance.stored_tiles, t.map.distance.tiles_x * t.map.distance.tiles_y);  // some not stored
  RandomStream rng(7, 0);
  std::size_t on_grid = 0, used = 0, border = 0;
  for (int trial = 0; trial < 200; ++trial) {
    // Every batch length 1..64, points spread a bit beyond the grid on every side.
    const std::size_t n = 1 + static_cast<std::size_t>(trial) % kDistanceBatch;
    std::vector<Point2f> pts(n);
    for (auto& p : pts) {  // one draw per statement: argument order is unspecified (y first, as x86-64 GCC did)
      const float y = static_cast<float>(rng.uniform(-2.0, 2.0));
      p = Point2f(static_cast<float>(rng.uniform(-2.5, 2.5)), y);
    }
    const float th = static_cast<float>(rng.uniform(-3.1, 3.1));
    const float py = static_cast<float>(rng.uniform(1.2, 2.0));
    const Se2f pose(static_cast<float>(rng.uniform(-0.5, 1.5)), py, th);
    expect_batches_equal(t.map, pts, pose, 0.15f);
    if (HasFatalFailure()) return;
    const float c = std::cos(pose.theta), s = std::sin(pose.theta);
    DistanceBatch b;
    sample_distance_batch(t.map, pts.data(), n, pose.x, pose.y, c, s, 0.15f, &b);
    for (std::size_t i = 0; i < n; ++i) {
      used += b.use[i];
      const float fx = (pose.x + c * pts[i].x() - s * pts[i].y() - t.map.geometry.origin_x) / 0.05f - 0.5f;
      const float fy = (pose.y + s * pts[i].x() + c * pts[i].y() - t.map.geometry.origin_y) / 0.05f - 0.5f;
      if (fx >= 0 && fy >= 0 && fx < 69 && fy < 49) {
        ++on_grid;
        if ((static_cast<int>(fx) & 15) == 15 || (static_cast<int>(fy) & 15) == 15) ++border;
      }
    }
  }
  // The cases the builds must agree on all occurred.
  EXPECT_GT(on_grid, 1000u);
  EXPECT_GT(used, 200u);
  EXPECT_GT(border, 50u);
}

TEST(DistanceBatchTest, NanAndInfinitePointsAreOffTheGrid) {
  const TwoWallTestMap t;
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  const std::vector<Point2f> pts = {Point2f(nan, 0.0f), Point2f(0.0f, nan), Point2f(inf, 0.1f), Point2f(-inf, 0.1f),
                                    Point2f(0.2f, 0.1f)};
  for (const DistanceBatchBuild build :
       {DistanceBatchBuild::kBest, DistanceBatchBuild::kPortable, DistanceBatchBuild::kScalar}) {
    DistanceBatch b;
    sample_distance_batch(t.map, pts.data(), pts.size(), 0.5f, 1.5f, 1.0f, 0.0f, 10.0f, &b, build);
    for (int i = 0; i < 4; ++i) EXPECT_EQ(b.use[i], 0) << "build " << static_cast<int>(build) << " point " << i;
    EXPECT_EQ(b.use[4], 1);
  }
  expect_batches_equal(t.map, pts, Se2f(0.5f, 1.5f, 0.0f), 10.0f);
}

}  // namespace
}  // namespace fw
