#include "firmware/track/odometry_noise_estimate.h"

#include <gtest/gtest.h>

#include <cmath>

#include "firmware/base/rng.h"

namespace fw {
namespace track {
namespace {

OdometryNoiseEstimate make(std::uint32_t window = 64, float max_scale = 1.0f) {
  OdometryNoiseEstimate e;
  e.configure(window, 16, 0.1f, max_scale, 1e-3f);
  return e;
}

// Wheels whose errors are `s` × the model's σ, model variance v per increment (translation: per axis).
void feed(OdometryNoiseEstimate* e, RandomStream* rng, float s, int n) {
  for (int i = 0; i < n; ++i) {
    const float v = 0.01f * (1.0f + static_cast<float>(i % 5));
    const float x = s * std::sqrt(v) * static_cast<float>(rng->gaussian()), y = s * std::sqrt(v) * static_cast<float>(rng->gaussian());
    const float t = s * std::sqrt(v) * static_cast<float>(rng->gaussian());
    e->add_translation(x * x + y * y, v);
    e->add_rotation(t * t, v);
  }
}

TEST(OdometryNoiseEstimateTest, ChiSquareLowerQuantileMatchesTables) {
  // χ² lower 1e-3 quantiles (tables): k = 10 → 1.479, 32 → 12.81, 100 → 61.92. Wilson–Hilferty
  // errs low at small k (1.38 at 10), which only makes the bound wider (the safe side).
  EXPECT_LE(chi2_lower_quantile(10.0f, -3.0902f), 1.479f);
  EXPECT_GT(chi2_lower_quantile(10.0f, -3.0902f), 1.3f);
  EXPECT_NEAR(chi2_lower_quantile(32.0f, -3.0902f), 12.81f, 0.2f);
  EXPECT_NEAR(chi2_lower_quantile(100.0f, -3.0902f), 61.92f, 0.3f);
}

TEST(OdometryNoiseEstimateTest, ScaleIsOneUntilEnoughSamplesThenBoundsTheTrueScaleFromAbove) {
  OdometryNoiseEstimate e = make();
  RandomStream rng(3, 0);
  feed(&e, &rng, 0.25f, 15);
  EXPECT_EQ(e.scale().trans, 1.0f);  // 15 < min_samples: the configured model
  EXPECT_EQ(e.scale().rot, 1.0f);
  feed(&e, &rng, 0.25f, 200);
  EXPECT_EQ(e.scale().trans_samples, 64u);
  // An upper bound: above the true 0.25, but well below the configured model.
  EXPECT_GT(e.scale().trans, 0.25f);
  EXPECT_LT(e.scale().trans, 0.40f);
  EXPECT_GT(e.scale().rot, 0.25f);
  EXPECT_LT(e.scale().rot, 0.45f);
}

TEST(OdometryNoiseEstimateTest, NeverLooserThanMaxScaleNorTighterThanMinScale) {
  RandomStream rng(5, 0);
  OdometryNoiseEstimate worse = make();
  feed(&worse, &rng, 2.0f, 100);
  EXPECT_EQ(worse.scale().trans, 1.0f);  // max_scale 1: the configured model is the ceiling
  OdometryNoiseEstimate open = make(64, 4.0f);
  feed(&open, &rng, 2.0f, 100);
  EXPECT_GT(open.scale().trans, 2.0f);  // wheels worse than configured: the model widens
  EXPECT_LE(open.scale().trans, 4.0f);
  OdometryNoiseEstimate perfect = make();
  feed(&perfect, &rng, 0.0f, 100);
  EXPECT_EQ(perfect.scale().trans, 0.1f);
  EXPECT_EQ(perfect.scale().rot, 0.1f);
}

TEST(OdometryNoiseEstimateTest, OffClearAndAWindowThatForgets) {
  RandomStream rng(7, 0);
  OdometryNoiseEstimate off = make(0);
  feed(&off, &rng, 0.1f, 100);
  EXPECT_EQ(off.scale().trans, 1.0f);
  EXPECT_EQ(off.scale().trans_samples, 0u);
  OdometryNoiseEstimate e = make(32);
  feed(&e, &rng, 0.1f, 100);
  EXPECT_LT(e.scale().trans, 0.3f);
  feed(&e, &rng, 1.0f, 32);  // the wheels got worse: the last 32 increments are all that count
  EXPECT_GT(e.scale().trans, 0.9f);
  e.clear();
  EXPECT_EQ(e.scale().trans, 1.0f);
  EXPECT_EQ(e.scale().trans_samples, 0u);
  e.add_translation(std::nanf(""), 1.0f);  // a non-finite sample is dropped
  EXPECT_EQ(e.scale().trans_samples, 0u);
}

}  // namespace
}  // namespace track
}  // namespace fw
