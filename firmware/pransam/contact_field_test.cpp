// The contact field without its float distance field (keep_distance = false, what MML uses: issue
// 14) stamps the same contact bytes the EDT path computes, in 2-D and 3-D, and a match that needs
// the distance field is refused with a status instead of reading memory that was never allocated,
// unless the caller gives the refinement a distance of its own (as MML gives the global map's).
#include "firmware/pransam/contact_field.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/rng.h"
#include "firmware/pransam/matcher.h"

namespace fw::pransam {
namespace {

template <int D>
void expect_same_bytes(float res, float eh, float es, int n_points, float extent, std::uint64_t seed) {
  RandomStream rng(seed, 0);
  std::vector<Point<D>> pts;
  for (int i = 0; i < n_points; ++i) {
    Point<D> p;
    for (int a = 0; a < D; ++a) p(a) = rng.uniform(0.0f, extent);
    pts.push_back(p);
  }
  ContactFieldOptions o;
  o.resolution = res;
  o.eps_hard = eh;
  o.eps_soft = es;
  o.max_cells = std::size_t(1) << 20;
  o.max_axis = 1024;
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(std::size_t(16) << 20, false, "contact test").is_ok());
  ContactField<D> with, without;
  ASSERT_TRUE(with.init(o, arena).is_ok());
  o.keep_distance = false;
  const std::size_t before = arena.used();
  ASSERT_TRUE(without.init(o, arena).is_ok());
  EXPECT_EQ(arena.used() - before, ContactField<D>::arena_bytes(o));  // one byte per cell, no scratch
  EXPECT_EQ(ContactField<D>::arena_bytes(o), o.max_cells);
  EXPECT_TRUE(with.has_distance());
  EXPECT_FALSE(without.has_distance());
  EXPECT_TRUE(std::isinf(without.distance(pts[0])));
  float d = 0.0f;
  Point<D> g;
  EXPECT_FALSE(without.distance_gradient(pts[0], &d, &g));
  ASSERT_TRUE(with.build(pts.data(), pts.size(), "with").is_ok());
  ASSERT_TRUE(without.build(pts.data(), pts.size(), "without").is_ok());
  ASSERT_EQ(with.cells(), without.cells());
  // Every cell centre: the stamped byte equals the EDT byte (hard, fuzzy and zero cells all occur).
  std::size_t counts[3] = {0, 0, 0};
  std::size_t idx[D] = {};
  for (std::size_t i = 0; i < with.cells(); ++i) {
    std::size_t rest = i;
    for (int a = D - 1; a >= 0; --a) {
      idx[a] = rest % with.dim(a);
      rest /= with.dim(a);
    }
    Point<D> c;
    for (int a = 0; a < D; ++a) c(a) = with.origin()(a) + (static_cast<float>(idx[a]) + 0.5f) * res;
    const std::uint8_t a = with.contact(c), b = without.contact(c);
    ASSERT_EQ(a, b) << "cell " << i;
    ++counts[a == 255 ? 0 : a > 0 ? 1 : 2];
  }
  EXPECT_GT(counts[0], 0u);
  EXPECT_GT(counts[1], 0u);
  EXPECT_GT(counts[2], 0u);
}

TEST(ContactFieldTest, StampedBytesEqualTheEdtBytes2D) { expect_same_bytes<2>(0.05f, 0.10f, 0.20f, 300, 6.0f, 1); }
TEST(ContactFieldTest, StampedBytesEqualTheEdtBytes2DCoarse) { expect_same_bytes<2>(0.1f, 0.2f, 0.4f, 200, 9.0f, 2); }
TEST(ContactFieldTest, StampedBytesEqualTheEdtBytes3D) { expect_same_bytes<3>(0.05f, 0.10f, 0.20f, 150, 1.5f, 3); }

// A matcher without the float distance field (as MML's), its model an L and a wall at x = 5.
class NoDistanceMatcherTest : public ::testing::Test {
 protected:
  void SetUp() override {
    MatcherOptions o;
    o.num_workers = 2;  // online matching: one worker per relation table
    o.max_scene_points = 512;
    o.max_model_points = 1024;
    o.field.max_cells = 200 * 200;
    o.field.max_axis = 256;
    o.field.keep_distance = false;
    o.collect_capacity = 64;
    ASSERT_TRUE(arena.init_mapped(std::size_t(32) << 20, false, "contact test").is_ok());
    ASSERT_TRUE(m.init(o, arena, nullptr).is_ok());
    for (int i = 0; i < 100; ++i) {
      model.emplace_back(0.05f * i, 0.0f);
      model.emplace_back(0.0f, 0.05f * i);
      model.emplace_back(5.0f, 0.03f * i);
    }
    ASSERT_TRUE(m.set_model(model.data(), model.size(), "L").is_ok());
  }
  StartupArena arena;
  Matcher<2> m;
  std::vector<Point<2>> model;
};

TEST_F(NoDistanceMatcherTest, MatchNeedingTheDistanceFieldIsRefusedWithoutIt) {
  MatchParams p;
  p.max_iterations = 100;
  MatchResult<2> r;
  p.refine_iterations = 3;
  Status st = m.match(model.data(), 50, p, &r);
  EXPECT_FALSE(st.is_ok());
  EXPECT_NE(std::string(st.message()).find("keep_distance"), std::string::npos) << st.message();
  p.refine_iterations = 0;
  p.scene_origin_is_sensor = true;
  EXPECT_FALSE(m.match(model.data(), 50, p, &r).is_ok());
  p.scene_origin_is_sensor = false;
  st = m.match(model.data(), 50, p, &r);
  EXPECT_TRUE(st.is_ok()) << st.message();
}

// The fixture's L and wall as segments: the distance to the nearest, and its
// gradient (what the global map's distance field gives MML; Matcher::set_refine_distance).
struct SegmentDistance {
  mutable std::uint64_t calls = 0;
  static bool sample(const void* ctx, const Point<2>& p, float* d, Point<2>* g) {
    const SegmentDistance& self = *static_cast<const SegmentDistance*>(ctx);
    ++self.calls;
    const Point<2> a[3] = {Point<2>(0, 0), Point<2>(0, 0), Point<2>(5, 0)};
    const Point<2> b[3] = {Point<2>(4.95f, 0), Point<2>(0, 4.95f), Point<2>(5, 2.97f)};
    float best = 1e9f;
    for (int k = 0; k < 3; ++k) {
      const Point<2> ab = b[k] - a[k];
      const float t = std::fmin(1.0f, std::fmax(0.0f, (p - a[k]).dot(ab) / ab.squaredNorm()));
      const Point<2> diff = p - (a[k] + t * ab);
      const float dist = diff.norm();
      if (dist < best) {
        best = dist;
        *g = dist > 1e-6f ? Point<2>(diff / dist) : Point<2>(0, 0);
      }
    }
    *d = best;
    return true;
  }
};

TEST_F(NoDistanceMatcherTest, RefinementUsesAnExternalDistance) {
  SegmentDistance dist;
  m.set_refine_distance(&SegmentDistance::sample, &dist);
  // The scene: the model seen from a pose 0.3 m / 10° away, every other point.
  const float c = std::cos(0.17f), s = std::sin(0.17f);
  std::vector<Point<2>> scene;
  for (std::size_t i = 0; i < model.size(); i += 2) {
    const Point<2> q = model[i] - Point<2>(0.3f, -0.2f);
    scene.emplace_back(c * q(0) + s * q(1), -s * q(0) + c * q(1));
  }
  MatchParams p;
  p.seed = 5;
  p.max_iterations = 4000;
  p.omega_thres = 0.9f;
  p.refine_iterations = 3;
  p.refine_min_quality = 0.3f;
  p.refine_max_points = 16;
  MatchResult<2> r;
  const Status st = m.match(scene.data(), scene.size(), p, &r);
  ASSERT_TRUE(st.is_ok()) << st.message();
  ASSERT_TRUE(r.found) << r.best.quality;
  EXPECT_GT(r.stats.refined, 0u);
  EXPECT_GT(dist.calls, 0u) << "the refinement did not sample the external distance";
  // refine_max_points: a stride of ceil(150 / 16) = 10 leaves 15 points per Gauss–Newton step.
  EXPECT_LE(dist.calls, r.stats.refined * p.refine_iterations * 15u);
  // The scene maps back onto the model: h = the pose the scene was seen from.
  const Point<2> t = r.best.translation;
  const float th = std::atan2(r.best.rotation(1, 0), r.best.rotation(0, 0));
  EXPECT_NEAR(t(0), 0.3f, 0.02f);
  EXPECT_NEAR(t(1), -0.2f, 0.02f);
  EXPECT_NEAR(th, 0.17f, 0.01f);
  // refine_max_hypotheses: each of the two workers refines at most its share, ceil(5 / 2) = 3.
  p.collect_all = true;  // every draw is rated: many refinements
  p.omega_thres = 0.6f;
  ASSERT_TRUE(m.match(scene.data(), scene.size(), p, &r).is_ok());
  const std::uint64_t uncapped = r.stats.refined;
  ASSERT_GT(uncapped, 6u) << "the cap below would not bind";
  p.refine_max_hypotheses = 5;
  ASSERT_TRUE(m.match(scene.data(), scene.size(), p, &r).is_ok());
  EXPECT_GT(r.stats.refined, 0u);
  EXPECT_LE(r.stats.refined, 6u);
}

}  // namespace
}  // namespace fw::pransam
