#include "firmware/mml/interpretation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "firmware/base/rng.h"

namespace fw {
namespace mml {
namespace {

std::vector<PoseHypothesis> blob(float x, float y, float t, int n, float spread, float q, RandomStream* rng) {
  std::vector<PoseHypothesis> v;
  for (int i = 0; i < n; ++i) {
    PoseHypothesis h;
    h.x = x + spread * static_cast<float>(rng->gaussian());
    h.y = y + spread * static_cast<float>(rng->gaussian());
    h.theta = t + 0.5f * spread * static_cast<float>(rng->gaussian());
    h.quality = q;
    v.push_back(h);
  }
  return v;
}

InterpretResult run(Interpreter* it, const std::vector<PoseHypothesis>& h, Se2f delta, bool have_delta) {
  InterpretInput in;
  in.hypotheses = h.data();
  in.count = h.size();
  in.odom_delta = delta;
  in.have_odom_delta = have_delta;
  InterpretResult r;
  EXPECT_TRUE(it->interpret(in, &r).is_ok());
  return r;
}

TEST(MmlOptionsTest, DefaultsValid) { EXPECT_TRUE(MmlOptions().validate().is_ok()); }

TEST(MmlOptionsTest, MalformedRejectedNamingField) {
  MmlOptions o;
  o.alpha[2] = 0.5f;
  Status s = o.validate();
  EXPECT_FALSE(s.is_ok());
  EXPECT_NE(std::string(s.message()).find("alpha"), std::string::npos) << s.message();
  o = MmlOptions();
  o.xi_r2 = std::nanf("");
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("xi_r2"), std::string::npos) << s.message();
  o = MmlOptions();
  o.tau_m = 1000;
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("tau_m"), std::string::npos) << s.message();
  o = MmlOptions();
  o.omega_thres0 = 0.1f;
  s = o.validate();
  EXPECT_NE(std::string(s.message()).find("omega_thres0"), std::string::npos) << s.message();
  static Interpreter it;
  EXPECT_FALSE(it.init(o).is_ok());
}

TEST(InterpreterTest, FilterDropsFlippedAndWeak) {
  static Interpreter it;
  ASSERT_TRUE(it.init(MmlOptions()).is_ok());
  std::vector<PoseHypothesis> h(4);
  h[0].quality = 0.9f;
  h[1].quality = 0.9f; h[1].roll = 3.14159f;  // flipped frame (Eq. 5.3)
  h[2].quality = 0.5f;                        // below Ω_thres0 = 0.7
  h[3].quality = 0.9f; h[3].x = std::nanf("");
  const InterpretResult r = run(&it, h, Se2f(), false);
  EXPECT_EQ(r.hypotheses_in, 4u);
  EXPECT_EQ(r.hypotheses_valid, 1u);
}

TEST(InterpreterTest, ClustersSeparateAndRate) {
  static Interpreter it;
  ASSERT_TRUE(it.init(MmlOptions()).is_ok());
  RandomStream rng(3, 0);
  auto a = blob(0, 0, 0, 80, 0.02f, 0.9f, &rng);
  auto b = blob(5, 1, 1.0f, 10, 0.02f, 0.75f, &rng);
  auto c = blob(0, 0, 1.2f, 10, 0.02f, 0.75f, &rng);  // same place, rotated: split by θ
  a.insert(a.end(), b.begin(), b.end());
  a.insert(a.end(), c.begin(), c.end());
  const InterpretResult r = run(&it, a, Se2f(), false);
  EXPECT_EQ(r.cluster_count, 3u);
  EXPECT_NEAR(r.pose.x, 0.0f, 0.02f);
  EXPECT_NEAR(r.pose.theta, 0.0f, 0.03f);
  EXPECT_GT(r.best_rating, 0.5f);
  double sum = 0;
  for (std::size_t i = 0; i < it.cluster_count(); ++i) {
    const Cluster& cl = it.clusters()[i];
    sum += cl.rating;
    EXPECT_LE(cl.sxx, MmlOptions().sigma2_trans_max_m2);
    EXPECT_LE(cl.srr, 50.0f * (M_PI / 180) * (M_PI / 180));
  }
  EXPECT_NEAR(sum, 1.0, 1e-4);
}

TEST(InterpreterTest, CircularMeanAcrossPi) {
  const float a[2] = {3.1f, -3.1f};
  EXPECT_NEAR(std::fabs(Interpreter::circular_mean(a, 2)), static_cast<float>(M_PI), 1e-3);
}

// A unique, consistent cluster moving with the odometry ⇒ localized once σ_med has enough samples.
TEST(InterpreterTest, ConsistentClusterLocalizes) {
  static Interpreter it;
  MmlOptions o;
  ASSERT_TRUE(it.init(o).is_ok());
  RandomStream rng(5, 0);
  Se2f truth(2, 3, 0.3f);
  const Se2f step(0.3f, 0.0f, 0.05f);
  int first = -1;
  for (int t = 0; t < 20; ++t) {
    auto h = blob(truth.x, truth.y, truth.theta, 60, 0.02f, 0.9f, &rng);
    auto noise = blob(truth.x + 8, truth.y - 4, 2.0f, 2, 0.02f, 0.72f, &rng);
    h.insert(h.end(), noise.begin(), noise.end());
    const InterpretResult r = run(&it, h, step, t > 0);
    if (r.status == hal::LocalizationStatus::kLocalized && first < 0) first = t;
    if (first >= 0) {
      EXPECT_EQ(r.status, hal::LocalizationStatus::kLocalized) << t;
      EXPECT_NEAR(r.pose.x, truth.x, 0.05f);
      EXPECT_NEAR(r.pose.y, truth.y, 0.05f);
    }
    truth = truth.compose(step);
  }
  EXPECT_GE(first, static_cast<int>(o.med_min_samples));
  EXPECT_LE(first, 8);
}

// Two equally good places (symmetric corridor): r ≈ 0.5 each ⇒ never localized.
TEST(InterpreterTest, SymmetricStaysAmbiguous) {
  static Interpreter it;
  ASSERT_TRUE(it.init(MmlOptions()).is_ok());
  RandomStream rng(6, 0);
  Se2f a(2, 3, 0.0f), b(12, 3, 3.14159f);
  const Se2f step(0.3f, 0.0f, 0.0f);
  for (int t = 0; t < 30; ++t) {
    auto h = blob(a.x, a.y, a.theta, 40, 0.02f, 0.9f, &rng);
    auto h2 = blob(b.x, b.y, b.theta, 40, 0.02f, 0.9f, &rng);
    h.insert(h.end(), h2.begin(), h2.end());
    const InterpretResult r = run(&it, h, step, t > 0);
    EXPECT_EQ(r.status, hal::LocalizationStatus::kAmbiguous) << t;
    EXPECT_LT(r.best_rating, 0.8f);
    a = a.compose(step);
    b = b.compose(step);
  }
}

// A converged Bollinger threshold lets 1–2 hypotheses through per step. Pooled over the consistent
// steps in which the cluster is alone, they reach min_cluster_hypotheses and the pose localizes;
// without pooling one step never holds five members. Twin places alternating between steps (a
// single hypothesis each time, one twin or the other) never pool: each switch fails d².
TEST(InterpreterTest, PooledSupportLocalizesASparseButConsistentCluster) {
  for (const bool pool : {true, false}) {
    static Interpreter it;
    MmlOptions o;
    o.pool_cluster_support = pool;
    ASSERT_TRUE(it.init(o).is_ok());
    RandomStream rng(15, 0);
    Se2f truth(2, 3, 0.3f);
    const Se2f step(0.3f, 0.0f, 0.05f);
    int localized = 0;
    for (int t = 0; t < 20; ++t) {
      const auto h = blob(truth.x, truth.y, truth.theta, 1 + t % 2, 0.02f, 0.9f, &rng);
      const InterpretResult r = run(&it, h, step, t > 0);
      localized += r.status == hal::LocalizationStatus::kLocalized;
      if (r.status == hal::LocalizationStatus::kLocalized) {
        EXPECT_TRUE(pool);
        EXPECT_GE(r.pooled_support, o.min_cluster_hypotheses);
        EXPECT_NEAR(r.pose.x, truth.x, 0.05f);
      }
      truth = truth.compose(step);
    }
    if (pool) EXPECT_GT(localized, 10); else EXPECT_EQ(localized, 0);
  }
  static Interpreter twins;
  MmlOptions pooled;
  pooled.pool_cluster_support = true;
  ASSERT_TRUE(twins.init(pooled).is_ok());
  RandomStream rng(16, 0);
  Se2f a(2, 3, 0.0f), b(12, 3, 3.14159f);
  const Se2f step(0.3f, 0.0f, 0.0f);
  for (int t = 0; t < 30; ++t) {
    const Se2f& p = (t / 2) % 2 ? b : a;  // two steps in one twin, two in the other
    const auto h = blob(p.x, p.y, p.theta, 2, 0.02f, 0.9f, &rng);
    const InterpretResult r = run(&twins, h, step, t > 0);
    EXPECT_NE(r.status, hal::LocalizationStatus::kLocalized) << t;
    EXPECT_LT(r.pooled_support, 5u) << t;
    a = a.compose(step);
    b = b.compose(step);
  }
}

// keep_support_across_empty_steps: steps without any hypothesis (the adaptive threshold above
// everything) between consistent steps of one cluster keep its pooled support — the cluster
// localizes with the option and never without it. A gap is no free pass for a jump: twins that
// alternate across empty steps still fail d² (x_prev is carried by the odometry through the gap).
TEST(InterpreterTest, EmptyStepsKeepTheSupportOnlyWithTheOption) {
  for (const bool keep : {true, false}) {
    static Interpreter it;
    MmlOptions o;
    o.pool_cluster_support = true;
    o.keep_support_across_empty_steps = keep;
    ASSERT_TRUE(it.init(o).is_ok());
    RandomStream rng(17, 0);
    Se2f truth(2, 3, 0.3f);
    const Se2f step(0.3f, 0.0f, 0.05f);
    int localized = 0;
    for (int t = 0; t < 30; ++t) {
      const auto h = t % 2 ? std::vector<PoseHypothesis>() : blob(truth.x, truth.y, truth.theta, 2, 0.02f, 0.9f, &rng);
      const InterpretResult r = run(&it, h, step, t > 0);
      if (r.status == hal::LocalizationStatus::kLocalized && !r.soft) {
        ++localized;
        EXPECT_TRUE(keep);
        EXPECT_NEAR(r.pose.x, truth.x, 0.05f);
      }
      truth = truth.compose(step);
    }
    if (keep) EXPECT_GT(localized, 3); else EXPECT_EQ(localized, 0);
  }
  static Interpreter twins;
  MmlOptions o;
  o.pool_cluster_support = true;
  o.keep_support_across_empty_steps = true;
  ASSERT_TRUE(twins.init(o).is_ok());
  RandomStream rng(18, 0);
  Se2f a(2, 3, 0.0f), b(12, 3, 3.14159f);
  const Se2f step(0.3f, 0.0f, 0.0f);
  for (int t = 0; t < 40; ++t) {
    const Se2f& p = (t / 4) % 2 ? b : a;  // twin a, empty, twin a, empty, then b the same way
    const auto h = t % 2 ? std::vector<PoseHypothesis>() : blob(p.x, p.y, p.theta, 2, 0.02f, 0.9f, &rng);
    const InterpretResult r = run(&twins, h, step, t > 0);
    EXPECT_NE(r.status, hal::LocalizationStatus::kLocalized) << t;
    EXPECT_LT(r.pooled_support, 5u) << t;
    a = a.compose(step);
    b = b.compose(step);
  }
}

// keep_support_across_contested_steps: the true cluster consistent at every step, alone in every
// other one and joined by a one-off rival elsewhere (rated as high) in the others: the pool survives
// the contested steps only with the option, and `localized` comes only on a step where the cluster
// is alone. A twin that takes the lead in a contested step breaks d², which empties the pool.
TEST(InterpreterTest, ContestedStepsKeepTheSupportOnlyWithTheOption) {
  for (const bool keep : {true, false}) {
    static Interpreter it;
    MmlOptions o;
    o.pool_cluster_support = true;
    o.keep_support_across_contested_steps = keep;
    ASSERT_TRUE(it.init(o).is_ok());
    RandomStream rng(19, 0);
    Se2f truth(2, 3, 0.3f);
    const Se2f step(0.3f, 0.0f, 0.05f);
    int localized = 0;
    for (int t = 0; t < 30; ++t) {
      auto h = blob(truth.x, truth.y, truth.theta, 2, 0.02f, 0.9f, &rng);
      const bool contested = t % 2 == 1;
      if (contested) {  // one rival hypothesis at a new random place each time
        const auto r = blob(20.0f + 3.0f * static_cast<float>(t), -5.0f, 1.0f, 1, 0.0f, 0.9f, &rng);
        h.insert(h.end(), r.begin(), r.end());
      }
      const InterpretResult r = run(&it, h, step, t > 0);
      if (r.status == hal::LocalizationStatus::kLocalized && !r.soft) {
        ++localized;
        EXPECT_TRUE(keep);
        EXPECT_FALSE(contested) << t;
        EXPECT_NEAR(r.pose.x, truth.x, 0.05f);
      }
      truth = truth.compose(step);
    }
    if (keep) EXPECT_GT(localized, 3); else EXPECT_EQ(localized, 0);
  }
  static Interpreter twins;
  MmlOptions o;
  o.pool_cluster_support = true;
  o.keep_support_across_contested_steps = true;
  ASSERT_TRUE(twins.init(o).is_ok());
  RandomStream rng(20, 0);
  Se2f a(2, 3, 0.0f), b(12, 3, 3.14159f);
  const Se2f step(0.3f, 0.0f, 0.0f);
  for (int t = 0; t < 40; ++t) {
    // a alone, a with b (b ahead every other time), a alone, …: the lead changes, d² fails.
    std::vector<PoseHypothesis> h = blob(a.x, a.y, a.theta, 2, 0.02f, 0.9f, &rng);
    if (t % 2 == 1) {
      const auto r = blob(b.x, b.y, b.theta, (t / 2) % 2 ? 3 : 1, 0.02f, 0.9f, &rng);
      h.insert(h.end(), r.begin(), r.end());
    }
    const InterpretResult r = run(&twins, h, step, t > 0);
    EXPECT_LT(r.pooled_support, 5u) << t;
    a = a.compose(step);
    b = b.compose(step);
  }
}

// A single cluster that jumps (inconsistent with odometry) fails the Mahalanobis test.
TEST(InterpreterTest, JumpingClusterFailsMahalanobis) {
  static Interpreter it;
  ASSERT_TRUE(it.init(MmlOptions()).is_ok());
  RandomStream rng(7, 0);
  for (int t = 0; t < 20; ++t) {
    const float x = (t % 2 == 0) ? 0.0f : 6.0f;
    auto h = blob(x, 0, 0, 50, 0.02f, 0.9f, &rng);
    const InterpretResult r = run(&it, h, Se2f(0.1f, 0, 0), t > 0);
    EXPECT_NE(r.status, hal::LocalizationStatus::kLocalized) << t;
    if (t > 0) EXPECT_FALSE(r.c_mahalanobis);
  }
}

// After jumps, σ_med (a median) passes as soon as half of the τ_m window is consistent; with
// confirm_steps = 2 the first `localized` waits until d² and σ_med held in two consecutive steps.
int first_localized_after_jumps(std::uint32_t confirm_steps) {
  static Interpreter it;
  MmlOptions o;
  o.confirm_steps = confirm_steps;
  EXPECT_TRUE(it.init(o).is_ok());
  RandomStream rng(8, 0);
  Se2f truth(2, 3, 0.3f);
  const Se2f step(0.3f, 0.0f, 0.05f);
  for (int t = 0; t < 30; ++t) {
    const float jump = (t < 6 && t % 2 == 1) ? 6.0f : 0.0f;  // a wrong place every other step
    auto h = blob(truth.x + jump, truth.y, truth.theta, 60, 0.02f, 0.9f, &rng);
    const InterpretResult r = run(&it, h, step, t > 0);
    if (r.status == hal::LocalizationStatus::kLocalized) return t;
    truth = truth.compose(step);
  }
  return -1;
}

TEST(InterpreterTest, ConfirmStepsDelaysEntryAfterJumps) {
  const int first1 = first_localized_after_jumps(1);
  const int first2 = first_localized_after_jumps(2);
  ASSERT_GE(first1, 0);
  ASSERT_GE(first2, 0);
  EXPECT_GT(first2, first1);
}

TEST(InterpreterTest, BollingerWalksThresholdDownWithoutHypotheses) {
  static Interpreter it;
  MmlOptions o;
  ASSERT_TRUE(it.init(o).is_ok());
  float prev = it.omega_thres();
  for (int t = 0; t < 10; ++t) {
    const InterpretResult r = run(&it, {}, Se2f(), false);
    EXPECT_EQ(r.status, hal::LocalizationStatus::kSearching);
    EXPECT_LT(r.omega_thres_next, prev);  // the lower band is ≥ δ_l below the moving mean
    EXPECT_GE(r.omega_thres_next, o.omega_thres_min);
    prev = r.omega_thres_next;
  }
  EXPECT_LT(prev, o.omega_thres0 - 0.05f);
  // High-quality hypotheses push it back up, but never above mean − δ_l.
  RandomStream rng(8, 0);
  for (int t = 0; t < 30; ++t) {
    run(&it, blob(0, 0, 0, 20, 0.01f, 0.95f, &rng), Se2f(), false);
  }
  EXPECT_GT(it.omega_thres(), 0.8f);
  EXPECT_LE(it.omega_thres(), 0.95f - o.bollinger_delta_l + 1e-4f);
}

TEST(InterpreterTest, UnknownRegionOverridesLocalized) {
  static Interpreter it;
  ASSERT_TRUE(it.init(MmlOptions()).is_ok());
  RandomStream rng(9, 0);
  InterpretResult r;
  for (int t = 0; t < 12; ++t) r = run(&it, blob(0, 0, 0, 50, 0.02f, 0.9f, &rng), Se2f(), t > 0);
  EXPECT_EQ(r.status, hal::LocalizationStatus::kLocalized);
  it.report_unknown(0.8f, 10, &r);
  EXPECT_EQ(r.status, hal::LocalizationStatus::kLocalized);
  it.report_unknown(0.1f, 5, &r);  // fewer than τ_up observations: not decided yet
  EXPECT_EQ(r.status, hal::LocalizationStatus::kLocalized);
  it.report_unknown(0.1f, 10, &r);
  EXPECT_EQ(r.status, hal::LocalizationStatus::kOutsideMap);
  EXPECT_FALSE(it.localized_before());
}

TEST(InterpreterTest, Deterministic) {
  static Interpreter a, b;
  ASSERT_TRUE(a.init(MmlOptions()).is_ok());
  ASSERT_TRUE(b.init(MmlOptions()).is_ok());
  RandomStream r1(11, 0), r2(11, 0);
  for (int t = 0; t < 10; ++t) {
    auto h1 = blob(1, 2, 0.5f, 100, 0.3f, 0.85f, &r1);
    auto h2 = blob(1, 2, 0.5f, 100, 0.3f, 0.85f, &r2);
    const InterpretResult x = run(&a, h1, Se2f(0.1f, 0, 0), t > 0);
    const InterpretResult y = run(&b, h2, Se2f(0.1f, 0, 0), t > 0);
    EXPECT_EQ(x.cluster_count, y.cluster_count);
    EXPECT_EQ(x.pose.x, y.pose.x);
    EXPECT_EQ(x.status, y.status);
  }
}

}  // namespace
}  // namespace mml
}  // namespace fw
