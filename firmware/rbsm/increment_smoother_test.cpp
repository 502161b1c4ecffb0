#include "firmware/rbsm/increment_smoother.h"

#include <gtest/gtest.h>

#include <array>
#include <cstring>
#include <vector>

#include "firmware/rbsm/fusion_tour_test_util.h"
#include "tests/alloc_counter.h"

namespace fw {
namespace {

using testing::make_tour;
using testing::rms_error;
using testing::short_error;
using testing::Tour;

std::vector<FusionStep> filter_steps(const Tour& t) {
  IncrementFusion f;
  EXPECT_TRUE(f.init(IncrementFusionOptions{}).is_ok());
  std::vector<FusionStep> steps;
  for (std::size_t i = 0; i < t.truth.size(); ++i) {
    const Se2d u = i == 0 ? Se2d() : t.relative[i - 1].between(t.relative[i]);
    EXPECT_TRUE(f.update(t.absolute[i], i > 0, u).is_ok());
    steps.push_back(f.step());
  }
  return steps;
}

std::vector<Se2d> poses(const std::vector<FusionStep>& steps) {
  std::vector<Se2d> out;
  for (const FusionStep& s : steps) out.push_back(s.pose);
  return out;
}

TEST(IncrementSmootherTest, HearingTheLaterScansBeatsTheFilterEverywhere) {
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const Tour t = make_tour(seed);
    std::vector<FusionStep> steps = filter_steps(t);
    const std::vector<FusionStep> filtered_steps = steps;
    const std::vector<Se2d> filtered = poses(steps);
    ASSERT_TRUE(smooth_fusion_steps(steps.data(), steps.size()).is_ok());
    const std::vector<Se2d> smoothed = poses(steps);
    // Closer to the truth, on the whole and on the relative motion over 5 and 50 scans.
    EXPECT_LT(rms_error(smoothed, t.truth), 0.8 * rms_error(filtered, t.truth)) << "seed " << seed;
    EXPECT_LT(short_error(smoothed, t.truth, 5), 0.85 * short_error(filtered, t.truth, 5)) << "seed " << seed;
    EXPECT_LT(short_error(smoothed, t.truth, 50), 0.8 * short_error(filtered, t.truth, 50)) << "seed " << seed;
    // The last scan has no later one: it stays as filtered. Every smoothed covariance is tighter.
    EXPECT_EQ(std::memcmp(&smoothed.back(), &filtered.back(), sizeof(Se2d)), 0);
    for (std::size_t i = 0; i + 1 < steps.size(); ++i) {
      ASSERT_LE(steps[i].cov.trace(), filtered_steps[i].cov.trace() + 1e-15) << "scan " << i;
    }
  }
}

TEST(IncrementSmootherTest, AFixedLagWindowGetsMostOfTheGainWithoutHeap) {
  // Onboard: the last L steps in a fixed array, smoothed after each scan, the oldest one read out.
  constexpr std::size_t kLag = 40;
  const Tour t = make_tour(3);
  const std::vector<FusionStep> all = filter_steps(t);
  std::vector<FusionStep> batch = all;
  ASSERT_TRUE(smooth_fusion_steps(batch.data(), batch.size()).is_ok());
  std::array<FusionStep, kLag + 1> window;
  std::vector<Se2d> lagged(all.size());
  std::size_t allocations = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    const bool count = mmlfw_test::AllocCounter::available();
    if (count) mmlfw_test::AllocCounter::begin();
    const std::size_t n = std::min(i + 1, window.size());
    for (std::size_t j = 0; j < n; ++j) window[j] = all[i + 1 - n + j];  // a ring buffer's order
    ASSERT_TRUE(smooth_fusion_steps(window.data(), n).is_ok());
    if (count) allocations += static_cast<std::size_t>(mmlfw_test::AllocCounter::end());
    if (i + 1 >= window.size()) lagged[i - kLag] = window[0].pose;
  }
  EXPECT_EQ(allocations, 0u);
  // The scans that got a full window: as good as the batch smoother to a few per cent.
  const std::size_t m = all.size() - kLag;
  const std::vector<Se2d> truth(t.truth.begin(), t.truth.begin() + m);
  const std::vector<Se2d> lag(lagged.begin(), lagged.begin() + m);
  std::vector<Se2d> bat, fil;
  for (std::size_t i = 0; i < m; ++i) {
    bat.push_back(batch[i].pose);
    fil.push_back(all[i].pose);
  }
  EXPECT_LT(rms_error(lag, truth), 1.05 * rms_error(bat, truth));
  EXPECT_LT(rms_error(lag, truth), 0.85 * rms_error(fil, truth));
}

TEST(IncrementSmootherTest, StepsNotFromTheFilterAreAnErrorNamingTheStep) {
  std::vector<FusionStep> steps = filter_steps(make_tour(1));
  const Se2d before = steps[10].pose;
  steps[11].predicted_cov.setZero();
  const Status st = smooth_fusion_steps(steps.data(), steps.size());
  ASSERT_FALSE(st.is_ok());
  EXPECT_NE(std::string(st.message()).find("step 11"), std::string::npos) << st.message();
  EXPECT_EQ(std::memcmp(&steps[10].pose, &before, sizeof(Se2d)), 0);  // left as filtered
  EXPECT_TRUE(smooth_fusion_steps(steps.data(), 0).is_ok());
  EXPECT_TRUE(smooth_fusion_steps(steps.data(), 1).is_ok());
}

}  // namespace
}  // namespace fw
