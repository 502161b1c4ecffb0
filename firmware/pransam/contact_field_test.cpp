// The contact field without its float distance field (keep_distance = false, what MML uses: issue
// 14) stamps the same contact bytes the EDT path computes, in 2-D and 3-D, and a match that needs
// the distance field is refused with a status instead of reading memory that was never allocated.
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

TEST(ContactFieldTest, MatchNeedingTheDistanceFieldIsRefusedWithoutIt) {
  MatcherOptions o;
  o.num_workers = 2;  // online matching: one worker per relation table
  o.max_scene_points = 64;
  o.max_model_points = 1024;
  o.field.max_cells = 200 * 200;
  o.field.max_axis = 256;
  o.field.keep_distance = false;
  o.collect_capacity = 64;
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(std::size_t(32) << 20, false, "contact test").is_ok());
  Matcher<2> m;
  ASSERT_TRUE(m.init(o, arena, nullptr).is_ok());
  std::vector<Point<2>> model;
  for (int i = 0; i < 100; ++i) {
    model.emplace_back(0.05f * i, 0.0f);
    model.emplace_back(0.0f, 0.05f * i);
    model.emplace_back(5.0f, 0.03f * i);
  }
  ASSERT_TRUE(m.set_model(model.data(), model.size(), "L").is_ok());
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

}  // namespace
}  // namespace fw::pransam
