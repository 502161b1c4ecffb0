#include "firmware/rbsm/endpoint_grid.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

struct GridFixture : ::testing::Test {
  std::vector<unsigned char> block;
  fw::StartupArena arena;
  fw::EndpointGrid grid;
  void make(const fw::EndpointGridOptions& o) {
    block.assign(fw::EndpointGrid::required_bytes(o) + 256, 0);
    ASSERT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
    ASSERT_TRUE(grid.init(o, arena).is_ok());
  }
};

TEST_F(GridFixture, LikelihoodFollowsEq29) {
  fw::EndpointGridOptions o;
  o.size_log2 = 6;
  make(o);
  grid.center_on(0, 0);
  float cx, cy;
  ASSERT_TRUE(grid.insert(0.01f, 0.02f, &cx, &cy));
  EXPECT_NEAR(cx, 0.025f, 1e-6f);
  EXPECT_NEAR(cy, 0.025f, 1e-6f);
  EXPECT_FALSE(grid.insert(0.03f, 0.04f));  // same cell
  EXPECT_EQ(grid.occupied_count(), 1u);
  // Sub-cell centre 1/8 cell from the cell centre: d² = 2·(1/8)² → 255·exp(−1/32).
  EXPECT_NEAR(grid.likelihood(0.02f, 0.02f), 255.0 * std::exp(-2.0 / 64), 1.0);
  // One cell to the right, first sub-cell: d = (5/8, 1/8) cells.
  EXPECT_NEAR(grid.likelihood(0.051f, 0.026f), 255.0 * std::exp(-(25.0 + 1.0) / 64), 1.0);
  // Two cells away: beyond ξ = √2.
  EXPECT_EQ(grid.likelihood(0.125f, 0.025f), 0);
  float nx, ny, d2;
  ASSERT_TRUE(grid.nearest_occupied(0.2f, 0.03f, 0.3f, &nx, &ny, &d2));
  EXPECT_NEAR(nx, 0.025f, 1e-6f);
  EXPECT_NEAR(d2, 0.175f * 0.175f + 0.005f * 0.005f, 1e-5f);
  EXPECT_FALSE(grid.nearest_occupied(0.5f, 0.0f, 0.3f, &nx, &ny, &d2));
  grid.clear();
  EXPECT_EQ(grid.occupied_count(), 0u);
  EXPECT_EQ(grid.likelihood(0.02f, 0.02f), 0);
  EXPECT_EQ(grid.likelihood(0.051f, 0.026f), 0);
}

TEST_F(GridFixture, ScrollingDropsCellsThatLeaveTheWindow) {
  fw::EndpointGridOptions o;
  o.size_log2 = 6;  // 64 cells = 3.2 m
  make(o);
  grid.center_on(0, 0);
  ASSERT_TRUE(grid.insert(-1.0f, 0.0f));
  ASSERT_TRUE(grid.insert(1.0f, 0.0f));
  EXPECT_FALSE(grid.insert(5.0f, 0.0f));  // outside the window
  EXPECT_FALSE(grid.follow(0.5f, 0.0f));  // within the re-centre margin
  EXPECT_TRUE(grid.follow(2.0f, 0.0f));   // moves: window [0.4, 3.6)
  EXPECT_FALSE(grid.occupied(-1.0f, 0.0f));
  EXPECT_EQ(grid.likelihood(-1.0f, 0.0f), 0);
  EXPECT_TRUE(grid.occupied(1.0f, 0.0f));
  EXPECT_GT(grid.likelihood(1.026f, 0.026f), 200);
  EXPECT_EQ(grid.occupied_count(), 1u);
  // The storage of the dropped cell is reused by the new area without ghosts.
  EXPECT_FALSE(grid.occupied(-1.0f + 3.2f, 0.0f));
  EXPECT_EQ(grid.likelihood(-1.0f + 3.2f, 0.0f), 0);
  ASSERT_TRUE(grid.insert(3.0f, 0.1f));
  EXPECT_GT(grid.likelihood(3.026f, 0.126f), 200);
}

// clear() returns the window to its state after init(): a grid that scrolled and was cleared
// behaves exactly like a fresh one (RBSM's reset() relies on it; a window left where the previous
// run scrolled it made runs after a reset differ from the first).
TEST_F(GridFixture, ClearForgetsTheScrolledWindow) {
  fw::EndpointGridOptions o;
  o.size_log2 = 6;  // 64 cells = 3.2 m, re-centred 0.8 m off-centre
  make(o);
  ASSERT_TRUE(grid.insert(0.0f, 0.0f));  // centres the window on the first point
  const std::int32_t fresh_x = grid.origin_cx(), fresh_y = grid.origin_cy();
  EXPECT_TRUE(grid.follow(1.0f, 0.5f));  // 20 cells off-centre > 16: window moves by (20, 10)
  ASSERT_TRUE(grid.insert(1.1f, 0.5f));
  grid.clear();
  EXPECT_EQ(grid.occupied_count(), 0u);
  // Within the re-centring margin of the scrolled window: only a fresh window lands back on 0.
  ASSERT_TRUE(grid.insert(0.0f, 0.0f));
  EXPECT_EQ(grid.origin_cx(), fresh_x);
  EXPECT_EQ(grid.origin_cy(), fresh_y);
  EXPECT_FALSE(grid.occupied(1.1f, 0.5f));
  EXPECT_EQ(grid.likelihood(1.126f, 0.526f), 0);
  EXPECT_GT(grid.likelihood(0.026f, 0.026f), 200);
}

// clear() zeroes only what the points touched when that is a small part of the window (whole 4 KiB
// lookup pages, occupancy rows): afterwards every byte of the grid's storage must be zero again, as
// after init(), also when the window scrolled and the points wrap around the toroidal storage.
TEST_F(GridFixture, ClearOfAPartlyUsedWindowZeroesEveryByte) {
  fw::EndpointGridOptions o;
  o.size_log2 = 8;  // 256 cells = 12.8 m; lookup 1024 x 1024 sub-cells = 16 x 16 pages
  make(o);
  for (int trial = 0; trial < 3; ++trial) {
    const float ox = -3.1f + 2.7f * static_cast<float>(trial), oy = 1.3f - 1.9f * static_cast<float>(trial);
    grid.center_on(ox, oy);
    for (int i = 0; i < 200; ++i) {  // a ring of radius 2.4 m: the dirty box ~ 96 x 96 cells < half the window
      const float a = 0.0314f * static_cast<float>(i);
      grid.insert(ox + 2.4f * std::cos(a), oy + 2.4f * std::sin(a));
    }
    if (trial == 2) {  // scroll so the box straddles the storage's wrap-around
      grid.follow(ox + 4.0f, oy - 3.0f);
      for (int i = 0; i < 50; ++i) grid.insert(ox + 4.0f + 0.05f * static_cast<float>(i), oy - 3.0f);
    }
    ASSERT_GT(grid.occupied_count(), 0u);
    grid.clear();
    EXPECT_EQ(grid.occupied_count(), 0u);
    std::size_t nonzero = 0;
    for (unsigned char b : block) nonzero += b != 0;
    EXPECT_EQ(nonzero, 0u) << "trial " << trial;
  }
}

TEST(EndpointGridOptionsTest, RejectsBadValues) {
  fw::EndpointGridOptions o;
  o.resolution = 0;
  EXPECT_EQ(o.validate().code(), fw::Errc::kInvalidArgument);
  o = {};
  o.xi_cells = 2.0f;
  EXPECT_NE(std::string(o.validate().message()).find("xi"), std::string::npos);
  o = {};
  o.size_log2 = 20;
  EXPECT_FALSE(o.validate().is_ok());
  o = {};
  EXPECT_TRUE(o.validate().is_ok());
}

}  // namespace

// Anytime re-centre (issue 14): moving the window a few cells per follow() ends in exactly the
// grid (occupancy and likelihood) of the one-step re-centre when the robot stands still.
TEST(EndpointGridRecentreTest, SpreadRecentreEqualsOneStep) {
  auto build = [](std::uint32_t step_cells, std::vector<unsigned char>* block, fw::StartupArena* arena,
                  fw::EndpointGrid* grid) {
    fw::EndpointGridOptions o;
    o.size_log2 = 6;  // 64 cells = 3.2 m, re-centred 16 cells off-centre
    o.recenter_step_cells = step_cells;
    block->assign(fw::EndpointGrid::required_bytes(o) + 256, 0);
    ASSERT_TRUE(arena->init(block->data(), block->size(), "test").is_ok());
    ASSERT_TRUE(grid->init(o, *arena).is_ok());
    grid->center_on(0, 0);
    for (int i = 0; i < 400; ++i) {  // points all over the window, some near its edges
      const float a = 0.37f * static_cast<float>(i);
      grid->insert(1.5f * std::cos(a) * (0.2f + 0.002f * i), 1.5f * std::sin(1.3f * a) * (0.2f + 0.002f * i));
    }
  };
  std::vector<unsigned char> b1, b2;
  fw::StartupArena a1, a2;
  fw::EndpointGrid once, spread;
  build(0, &b1, &a1, &once);
  build(3, &b2, &a2, &spread);
  EXPECT_TRUE(once.follow(1.0f, -0.9f));  // 20 / 18 cells off-centre
  int moves = 0;
  while (spread.follow(1.0f, -0.9f)) {
    ++moves;
    ASSERT_LT(moves, 100);
  }
  EXPECT_EQ(moves, 7) << "20 cells at 3 per step";
  EXPECT_EQ(spread.origin_cx(), once.origin_cx());
  EXPECT_EQ(spread.origin_cy(), once.origin_cy());
  EXPECT_EQ(spread.occupied_count(), once.occupied_count());
  for (float y = -3.5f; y < 3.5f; y += 0.0125f) {
    for (float x = -3.5f; x < 3.5f; x += 0.0125f) {
      ASSERT_EQ(spread.occupied(x, y), once.occupied(x, y)) << x << " " << y;
      ASSERT_EQ(spread.likelihood(x, y), once.likelihood(x, y)) << x << " " << y;
    }
  }
}
