#include "firmware/local_map/local_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace {

struct LocalMapFixture : ::testing::Test {
  std::vector<unsigned char> block = std::vector<unsigned char>(1 << 20);
  fw::StartupArena arena;
  fw::LocalMap map;
  void make(const fw::LocalMapOptions& o) {
    ASSERT_TRUE(arena.init(block.data(), block.size(), "test").is_ok());
    ASSERT_TRUE(map.init(o, arena).is_ok());
  }
};

TEST_F(LocalMapFixture, NewFragmentEveryNMetresWithPointsInItsFrame) {
  fw::LocalMapOptions o;
  o.fragment_length_m = 5.0f;
  o.point_capacity = 1000;
  make(o);
  // Drive along x in 1 m steps, heading +90°, adding one point 1 m to the left of the robot.
  for (int k = 0; k <= 12; ++k) {
    const fw::Se2f pose(static_cast<float>(k), 0.0f, 1.5707963f);
    ASSERT_TRUE(map.update_pose(pose).is_ok());
    const fw::Point2f w(static_cast<float>(k) - 1.0f, 0.0f);
    ASSERT_TRUE(map.add_points(&w, 1).is_ok());
  }
  // Fragments start at x = 0, 5, 10.
  ASSERT_EQ(map.num_fragments(), 3u);
  EXPECT_EQ(map.total_points(), 13u);
  const fw::FragmentView f1 = map.fragment(1);
  EXPECT_EQ(f1.id, 1u);
  EXPECT_NEAR(f1.frame.x, 5.0f, 1e-5f);
  ASSERT_EQ(f1.size(), 5u);
  // World point (4, 0) seen from frame (5, 0, 90°) is (0, 1) in the fragment frame.
  EXPECT_NEAR(f1[0](0), 0.0f, 1e-5f);
  EXPECT_NEAR(f1[0](1), 1.0f, 1e-5f);
  EXPECT_TRUE(map.drop_oldest());
  EXPECT_EQ(map.num_fragments(), 2u);
  EXPECT_EQ(map.total_points(), 8u);
  EXPECT_EQ(map.fragment(0).id, 1u);
}

TEST_F(LocalMapFixture, KeepLastMAndWrapAroundWithoutFragmentation) {
  fw::LocalMapOptions o;
  o.fragment_length_m = 1.0f;
  o.keep_last = 3;
  o.point_capacity = 100;
  make(o);
  std::vector<fw::Point2f> pts(30, fw::Point2f(1, 1));
  for (int k = 0; k < 19; ++k) {  // fragment 16 starts at ring index 80 and wraps
    ASSERT_TRUE(map.update_pose(fw::Se2f(static_cast<float>(k), 0, 0)).is_ok());
    ASSERT_TRUE(map.add_points(pts.data(), pts.size()).is_ok());
    ASSERT_LE(map.num_fragments(), 3u);
    ASSERT_LE(map.total_points(), 100u);
  }
  EXPECT_EQ(map.num_fragments(), 3u);
  EXPECT_EQ(map.fragment(2).id, 18u);
  // Some fragment must have wrapped across the ring end and still reads back whole.
  bool wrapped = false;
  for (size_t i = 0; i < map.num_fragments(); ++i) {
    const fw::FragmentView v = map.fragment(i);
    EXPECT_EQ(v.size(), 30u);
    if (v.second_count > 0) wrapped = true;
    EXPECT_NEAR(v[29](0), 1.0f - static_cast<float>(v.frame.x), 1e-5f);
  }
  EXPECT_TRUE(wrapped);
}

TEST_F(LocalMapFixture, FullIsAClearStatusWhenEvictionIsOff) {
  fw::LocalMapOptions o;
  o.point_capacity = 50;
  o.drop_oldest_when_full = false;
  make(o);
  std::vector<fw::Point2f> pts(40, fw::Point2f(0, 0));
  ASSERT_TRUE(map.update_pose(fw::Se2f()).is_ok());
  ASSERT_TRUE(map.add_points(pts.data(), pts.size()).is_ok());
  const fw::Status st = map.add_points(pts.data(), 20);
  EXPECT_EQ(st.code(), fw::Errc::kCapacityExceeded);
  EXPECT_NE(std::string(st.message()).find("40 of 50"), std::string::npos) << st.message();
  fw::LocalMapOptions bad;
  bad.fragment_length_m = -1;
  EXPECT_FALSE(bad.validate().is_ok());
  fw::LocalMap fresh;
  EXPECT_EQ(fresh.update_pose(fw::Se2f()).code(), fw::Errc::kNotInitialized);
}

// A fragment correction T_i moves its points (F_i ⊕ T_i ⊕ x) without touching how later points
// are stored (F_i, the scan matcher's frame); fragments are found by id until dropped.
TEST_F(LocalMapFixture, CorrectionMovesFragmentPointsAndIdsAreFound) {
  fw::LocalMapOptions o;
  o.fragment_length_m = 1.0f;
  o.keep_last = 2;
  o.point_capacity = 1000;
  make(o);
  ASSERT_TRUE(map.update_pose(fw::Se2f(0.0f, 0.0f, 0.0f)).is_ok());
  const fw::Point2f w(2.0f, 1.0f);
  ASSERT_TRUE(map.add_points(&w, 1).is_ok());
  ASSERT_TRUE(map.set_correction(0, fw::Se2f(0.1f, 0.0f, 0.0f)).is_ok());
  const fw::Point2f w2(3.0f, 1.0f);
  ASSERT_TRUE(map.add_points(&w2, 1).is_ok());  // added after the correction: corrected as well
  const fw::FragmentView v = map.fragment(0);
  EXPECT_NEAR(v.frame.transform_point(v[0]).x(), 2.1f, 1e-5f);
  EXPECT_NEAR(v.frame.transform_point(v[1]).x(), 3.1f, 1e-5f);
  EXPECT_NEAR(v.scan_matcher_frame.transform_point(v[1]).x(), 3.0f, 1e-5f);
  EXPECT_FALSE(map.set_correction(0, fw::Se2f(NAN, 0.0f, 0.0f)).is_ok());
  EXPECT_FALSE(map.set_correction(5, fw::Se2f()).is_ok());
  std::size_t idx = 99;
  EXPECT_TRUE(map.find_fragment(0, &idx));
  EXPECT_EQ(idx, 0u);
  for (int k = 1; k <= 3; ++k) ASSERT_TRUE(map.update_pose(fw::Se2f(1.5f * k, 0.0f, 0.0f)).is_ok());
  EXPECT_FALSE(map.find_fragment(0, &idx));  // dropped (keep_last = 2)
  EXPECT_TRUE(map.find_fragment(3, &idx));
  EXPECT_EQ(idx, 1u);
  EXPECT_FALSE(map.find_fragment(4, &idx));  // not opened yet
  EXPECT_EQ(map.fragment(1).correction.x, 0.0f);  // new fragments start uncorrected
}

}  // namespace
