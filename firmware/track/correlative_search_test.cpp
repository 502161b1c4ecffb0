#include "firmware/track/correlative_search.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/track/scan_alignment.h"
#include "firmware/track/track_test_util.h"

namespace fw {
namespace track {
namespace {

using testing::room;
using testing::room_map;
using testing::scan_at;

constexpr float kDeg = 0.0174532925f;

TEST(CorrelativeSearchTest, FindsThePoseWithinTheWindowWhereGaussNewtonFromTheSeedDoesNot) {
  RandomStream rng(7, 0);
  const GlobalMap& map = room_map().map;
  const Se2f truth(4.5f, 4.0f, 0.3f);
  const std::vector<Point2f> pts = scan_at(room(), truth, &rng);
  ASSERT_GT(pts.size(), 100u);
  CorrelativeSearchOptions o;
  CorrelativeWindow w;
  w.xy_m = 1.0f;
  w.theta_rad = 20.0f * kDeg;
  std::vector<Point2f> scratch(2 * 1081);
  int gn_wrong = 0;
  for (int k = 0; k < 8; ++k) {
    // Seeds 0.6–0.8 m and 12–15° off in different directions.
    const float a = static_cast<float>(k) * 0.785f;
    const float r = 0.6f + 0.025f * static_cast<float>(k);
    const float dth = (k % 2 ? 1.0f : -1.0f) * (12.0f + 0.4f * static_cast<float>(k)) * kDeg;
    const Se2f seed(truth.x + r * std::cos(a), truth.y + r * std::sin(a), truth.theta + dth);
    const CorrelativeResult cr = correlative_search(map, pts.data(), pts.size(), seed, w, o, scratch.data(), scratch.size());
    EXPECT_GT(cr.candidates, 1000u);
    EXPECT_GT(cr.score, cr.seed_score);
    const ScanAlignment fine = align_scan(map, pts.data(), pts.size(), cr.pose, ScanAlignOptions());
    EXPECT_LT(std::hypot(fine.pose.x - truth.x, fine.pose.y - truth.y), 0.03f) << "seed " << k;
    EXPECT_LT(std::fabs(wrap_angle(fine.pose.theta - truth.theta)), 0.5f * kDeg) << "seed " << k;
    const ScanAlignment gn = align_scan(map, pts.data(), pts.size(), seed, ScanAlignOptions());
    if (std::hypot(gn.pose.x - truth.x, gn.pose.y - truth.y) > 0.1f) ++gn_wrong;
  }
  EXPECT_GT(gn_wrong, 0) << "the seeds should be beyond Gauss-Newton's capture range for this test to mean anything";
}

TEST(CorrelativeSearchTest, BudgetCoarsensTheGridAndTheSeedWinsTies) {
  RandomStream rng(8, 0);
  const GlobalMap& map = room_map().map;
  const Se2f truth(1.5f, 3.0f, -0.4f);
  const std::vector<Point2f> pts = scan_at(room(), truth, &rng);
  CorrelativeSearchOptions o;
  o.max_candidates = 500;
  CorrelativeWindow w;
  w.xy_m = 1.0f;
  w.theta_rad = 20.0f * kDeg;
  std::vector<Point2f> scratch(2 * 1081);
  const CorrelativeResult cr = correlative_search(map, pts.data(), pts.size(), truth, w, o, scratch.data(), scratch.size());
  EXPECT_LE(cr.candidates, 500u);
  EXPECT_GT(cr.candidates, 50u);
  // At the truth nothing scores better: the seed is returned unchanged.
  EXPECT_EQ(cr.pose.x, truth.x);
  EXPECT_EQ(cr.pose.y, truth.y);
  EXPECT_EQ(cr.pose.theta, truth.theta);
  // A zero window evaluates the seed alone.
  const CorrelativeResult one = correlative_search(map, pts.data(), pts.size(), truth, CorrelativeWindow(), o,
                                                   scratch.data(), scratch.size());
  EXPECT_EQ(one.candidates, 1u);
}

TEST(CorrelativeSearchTest, BadOptionsAreRejected) {
  TrackOptions o;
  o.search.max_candidates = 0;
  const Status s = o.validate();
  ASSERT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("search.max_candidates"), std::string::npos) << s.message();
  o = TrackOptions();
  o.search.window_sigmas = -1.0f;
  EXPECT_FALSE(o.validate().is_ok());
}

}  // namespace
}  // namespace track
}  // namespace fw
