// Unit tests of the two local map options of MML: the gradient-descent correction (Eq. 5.23–5.27,
// App. D) and the observation reduction rule (Eq. 5.28–5.30), plus their option validation.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "firmware/mml/local_map_correction.h"
#include "firmware/mml/mml_options.h"
#include "firmware/mml/mml_test_util.h"
#include "firmware/mml/observation_reduction.h"

namespace fw {
namespace mml {
namespace {

using testing::GridWorld;
using testing::OwnedGlobalMap;

// A fragment seen from F: the map's wall points within 4 m of F's origin, in F's frame (the true
// fragment shape; H_best = identity).
struct FragmentFixture {
  GridWorld g = mcl::testing::unique_room();
  OwnedGlobalMap gm{g};
  Se2f frame{4.0f, 3.0f, 0.3f};
  std::vector<Point2f> pts;
  FragmentFixture() {
    const Se2f inv = frame.inverse();
    for (const Point2f& p : gm.points) {
      if (std::hypot(p.x() - frame.x, p.y() - frame.y) < 4.0f) pts.push_back(inv.transform_point(p));
    }
  }
};

// Pose error of map_from_fragment ⊕ T(δ) against the true frame.
double pose_error(const Se2f& a, const Se2f& truth) {
  const Se2f d = truth.between(a);
  return std::hypot(d.x, d.y) + 3.0 * std::fabs(d.theta);  // 3 m lever ~ a typical point
}

TEST(LocalMapCorrectionTest, DisplacedFragmentIsPulledBack) {
  FragmentFixture fx;
  ASSERT_GT(fx.pts.size(), 200u);
  // The local map put the fragment 8 cm / −5 cm / 1.1° off: map_from_fragment = F ⊕ D.
  const Se2f displaced = fx.frame.compose(Se2f(0.08f, -0.05f, 0.02f));
  CorrectionParams p;  // MmlOptions defaults: 20 iterations, α(0) = 0.05, clip 0.3 m
  const CorrectionResult r = correct_fragment(fx.gm.map, displaced, fx.pts.data(), fx.pts.size(), p);
  ASSERT_TRUE(r.applied);
  const double before = pose_error(displaced, fx.frame);
  const double after = pose_error(displaced.compose(r.delta), fx.frame);
  std::printf("e %.5f -> %.5f m², pose error %.4f -> %.4f, %u evaluations\n", r.e_before, r.e_after, before, after,
              r.iterations);
  // Stated factors: the mean squared distance shrinks at least 10×, the pose error at least 4×.
  EXPECT_LT(r.e_after, r.e_before / 10.0);
  EXPECT_LT(after, before / 4.0);
  EXPECT_LE(r.iterations, p.iterations + 1);
}

TEST(LocalMapCorrectionTest, AlignedFragmentStaysPut) {
  FragmentFixture fx;
  const CorrectionResult r = correct_fragment(fx.gm.map, fx.frame, fx.pts.data(), fx.pts.size(), CorrectionParams());
  // Already on the map: any step found is tiny (bilinear field minimum within a cell).
  EXPECT_LT(std::hypot(r.delta.x, r.delta.y), 0.02f);
  EXPECT_LT(std::fabs(r.delta.theta), 0.005f);
}

TEST(LocalMapCorrectionTest, CorrectionBeyondBoundIsRejected) {
  FragmentFixture fx;
  const Se2f displaced = fx.frame.compose(Se2f(0.15f, 0.0f, 0.0f));
  CorrectionParams p;
  p.max_shift_m = 0.05f;  // the needed 15 cm exceed the bound
  const CorrectionResult r = correct_fragment(fx.gm.map, displaced, fx.pts.data(), fx.pts.size(), p);
  EXPECT_FALSE(r.applied);
  EXPECT_EQ(r.delta.x, 0.0f);
  EXPECT_EQ(r.delta.theta, 0.0f);
}

// ∇e of App. D (Eq. D.2–D.3 with d·∇d from the distance field) against central differences of e.
TEST(LocalMapCorrectionTest, GradientMatchesFiniteDifferences) {
  FragmentFixture fx;
  const Se2f displaced = fx.frame.compose(Se2f(0.08f, -0.05f, 0.02f));
  const double deltas[3][3] = {{0.03, -0.02, 0.01}, {0.0, 0.0, 0.0}, {-0.05, 0.04, -0.015}};
  for (const auto& delta : deltas) {
    double g[3];
    correction_error(fx.gm.map, displaced, fx.pts.data(), fx.pts.size(), 0.3f, delta, g, nullptr);
    const double h[3] = {1e-6, 1e-6, 1e-7};
    double norm = 0.0, diff = 0.0;
    for (int k = 0; k < 3; ++k) {
      double dp[3] = {delta[0], delta[1], delta[2]}, dm[3] = {delta[0], delta[1], delta[2]};
      dp[k] += h[k];
      dm[k] -= h[k];
      const double ep = correction_error(fx.gm.map, displaced, fx.pts.data(), fx.pts.size(), 0.3f, dp, nullptr, nullptr);
      const double em = correction_error(fx.gm.map, displaced, fx.pts.data(), fx.pts.size(), 0.3f, dm, nullptr, nullptr);
      const double fd = (ep - em) / (2.0 * h[k]);
      std::printf("δ (%.3f %.3f %.3f) ∂e/∂δ%d analytic %.6f finite %.6f\n", delta[0], delta[1], delta[2], k, g[k], fd);
      norm += g[k] * g[k];
      diff += (g[k] - fd) * (g[k] - fd);
      EXPECT_NEAR(g[k], fd, 0.005 * std::fabs(fd) + 1e-5) << "component " << k;
    }
    EXPECT_GT(norm, 1e-6);  // a real slope, not a flat spot
  }
}

// Eq. 5.30 with Δ_0 = 2, Δ_max = 4, |C|_max = 20.
TEST(ReductionRuleTest, DeltaIsPiecewiseLinear) {
  const ReductionRule r(2.0f, 4.0f, 20);
  EXPECT_EQ(r.delta(0), 2.0f);
  EXPECT_EQ(r.delta(5), 2.0f);   // ⌊2.5⌋
  EXPECT_EQ(r.delta(10), 3.0f);  // ⌊3.0⌋
  EXPECT_EQ(r.delta(19), 3.0f);  // ⌊3.9⌋
  EXPECT_EQ(r.delta(20), 4.0f);  // ≥ |C|_max: Δ_max
  EXPECT_EQ(r.delta(500), 4.0f);
}

// A hand-made f(t): linear decrease, collapse at t = 4, slow decrease, collapse at t = 9, then a
// small wiggle at t = 12 whose jump (2) does not exceed Δ(1) = 2.
TEST(ReductionRuleTest, AcceptsObservationsAtCollapses) {
  const std::vector<std::uint32_t> f = {30, 28, 26, 24, 8, 8, 7, 6, 5, 2, 2, 2, 1, 1};
  // f'' = –, –, 0, 0, −14, 16, −1, 0, 0, −2, 3, 0, −1, 1
  ReductionRule r(2.0f, 4.0f, 20);
  std::vector<int> accepted;  // observation index t−1
  for (std::size_t t = 0; t < f.size(); ++t)
    if (r.push(f[t])) accepted.push_back(static_cast<int>(t) - 1);
  EXPECT_EQ(accepted, (std::vector<int>{4, 9}));
}

// Same crossing shape, once with few and once with many clusters: the jump 3 passes Δ(5) = 2 but
// not Δ(50) = Δ_max = 4 (noisy crossings of a large f are ignored, Eq. 5.30).
TEST(ReductionRuleTest, ThresholdGrowsWithClusterCount) {
  ReductionRule few(2.0f, 4.0f, 20), many(2.0f, 4.0f, 20);
  bool few_acc = false, many_acc = false;
  for (std::uint32_t v : {6u, 5u, 5u, 4u, 5u}) few_acc = few.push(v) || few_acc;       // f'' = 1, −1, 2
  for (std::uint32_t v : {51u, 50u, 50u, 49u, 50u}) many_acc = many.push(v) || many_acc;
  EXPECT_TRUE(few_acc);
  EXPECT_FALSE(many_acc);
  few.reset();
  EXPECT_FALSE(few.push(5));  // no history after reset
}

// f = 1, 1, 0, 1 satisfies Eq. 5.29 (f'' = −1, 2; jump 3 > Δ(1) = 2) but the "collapse" is a step
// without any cluster: not accepted (extension, see observation_reduction.h).
TEST(ReductionRuleTest, CollapseToNoClusterIsNotInformation) {
  ReductionRule r(2.0f, 4.0f, 20);
  bool acc = false;
  for (std::uint32_t v : {1u, 1u, 1u, 0u, 1u}) acc = r.push(v) || acc;
  EXPECT_FALSE(acc);
  ReductionRule r2(2.0f, 4.0f, 20);
  acc = false;
  for (std::uint32_t v : {2u, 2u, 2u, 1u, 2u}) acc = r2.push(v) || acc;  // same shape, one cluster left
  EXPECT_TRUE(acc);
}

std::string check(const MmlOptions& o) {
  const Status s = o.validate();
  return s.is_ok() ? std::string() : std::string(s.message());
}

TEST(LocalMapOptionsTest, BothOptionsValidate) {
  MmlOptions o;
  o.correct_local_map = true;
  o.reduce_observations = true;
  EXPECT_EQ(check(o), "");
}

TEST(LocalMapOptionsTest, BadValuesNameTheField) {
  struct Case {
    const char* field;
    void (*edit)(MmlOptions*);
  };
  const Case cases[] = {
      {"correction_step", [](MmlOptions* o) { o->correction_step = 0.0f; }},
      {"correction_step", [](MmlOptions* o) { o->correction_step = 2.0f; }},
      {"correction_fragments", [](MmlOptions* o) { o->correction_fragments = 0; }},
      {"correction_fragments", [](MmlOptions* o) { o->correction_fragments = 1000; }},
      {"correction_points", [](MmlOptions* o) { o->correction_points = 100000; }},
      {"correction_min_points", [](MmlOptions* o) { o->correction_min_points = 400; }},
      {"correction_clip_m", [](MmlOptions* o) { o->correction_clip_m = std::nanf(""); }},
      {"correction_max_shift_m", [](MmlOptions* o) { o->correction_max_shift_m = -1.0f; }},
      {"correction_max_rotation_rad", [](MmlOptions* o) { o->correction_max_rotation_rad = 0.0f; }},
      {"correction_iterations", [](MmlOptions* o) { o->correction_iterations = 50000; }},
      {"reduction_min_jump", [](MmlOptions* o) { o->reduction_min_jump = -1.0f; }},
      {"reduction_delta_max", [](MmlOptions* o) { o->reduction_delta_max = 1.0f; }},
      {"reduction_clusters_max", [](MmlOptions* o) { o->reduction_clusters_max = 0; }},
      {"reduction_observation_points", [](MmlOptions* o) { o->reduction_observation_points = 2; }},
      {"reduction_max_observations", [](MmlOptions* o) { o->reduction_max_observations = 100000; }},
  };
  for (const Case& c : cases) {
    MmlOptions o;
    o.correct_local_map = true;
    o.reduce_observations = true;
    c.edit(&o);
    const std::string m = check(o);
    EXPECT_NE(m.find(std::string("MmlOptions.") + c.field), std::string::npos) << c.field << ": '" << m << "'";
  }
}

}  // namespace
}  // namespace mml
}  // namespace fw
