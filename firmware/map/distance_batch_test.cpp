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

namespace fw {
namespace {

// A 70 × 50-cell map (5 × 4 tiles, the last row and column partly outside the grid) at 5 cm with
// two walls, truncated at 0.3 m: the tiles far from both walls are not stored.
struct TestMap {
  DistanceFieldLayout layout;
  std::vector<std::uint32_t> slots;
  std::vector<std::uint16_t> cells;
  std::vector<float> table;
  GlobalMap map;

  TestMap() {
    const std::uint32_t w = 70, h = 50;
    const float res = 0.05f;
    std::vector<float> metres(w * h);
    for (std::uint32_t y = 0; y < h; ++y) {
      for (std::uint32_t x = 0; x < w; ++x) {
        // Distance to the wall y = 10 (cells 0..39) and to the wall x = 55 (all rows), exact per cell.
        const float dy = x < 40 ? std::fabs(static_cast<float>(y) - 10.0f) : 1e9f;
        const float dx = std::fabs(static_cast<float>(x) - 55.0f);
        metres[y * w + x] = std::fmin(dx, dy) * res;
      }
    }
    EXPECT_TRUE(plan_distance_field(metres.data(), w, h, res, 0.3f, &layout).is_ok());
    slots.assign(layout.slot_count(), 0);
    cells.assign(layout.cell_count(), 0);
    table.assign(layout.table_count(), 0.0f);
    map.geometry.resolution = res;
    map.geometry.origin_x = -1.3f;
    map.geometry.origin_y = 0.7f;
    map.geometry.width = w;
    map.geometry.height = h;
    map.distance = fill_distance_field(layout, metres.data(), slots.data(), cells.data(), table.data());
  }
};

bool same_bits(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

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
      ASSERT_TRUE(same_bits(got.d[i], d)) << i << ": " << got.d[i] << " vs " << d;
      ASSERT_TRUE(same_bits(got.gx[i], gx)) << i;
      ASSERT_TRUE(same_bits(got.gy[i], gy)) << i;
      ASSERT_TRUE(same_bits(got.jt[i], ref.jt[i])) << i;
      ASSERT_TRUE(same_bits(ref.jt[i], gx * (-s * px - c * py) + gy * (c * px - s * py))) << i;
    }
  }
}

TEST(DistanceBatchTest, EveryBuildGivesTheScalarSamplersBits) {
  const TestMap t;
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
  const TestMap t;
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
