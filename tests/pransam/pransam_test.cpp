#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <vector>

#include "firmware/base/arena.h"
#include "firmware/base/worker_pool.h"
#include "firmware/pransam/matcher.h"
#include "firmware/pransam/relation_table_io.h"
#include "sim/eval/pransam_scenes.h"

namespace fw::pransam {
namespace {

using sim::pransam_scenes::P2;
using sim::pransam_scenes::P3;
constexpr float kPi = 3.14159265f;

float angle_diff(float a, float b) { return std::fabs(wrap_angle(a - b)); }

// ---------------------------------------------------------------- keying, frames, hypotheses

TEST(RelationKeyTest, CanonicalOrderMakesAllDrawOrdersShareOneSlot) {
  const P2 pts[3] = {P2(0, 0), P2(3, 0), P2(0.5f, 2)};
  const TripleFilter f{10.0f, 0.1f, 0.0f};
  const int perms[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  std::uint32_t first_slot = 0;
  Triple first;
  for (int p = 0; p < 6; ++p) {
    Triple t;
    for (int k = 0; k < 3; ++k) t.v[k] = static_cast<std::uint32_t>(perms[p][k]);
    std::uint32_t slot = 0;
    ASSERT_EQ(key_triple<2>(pts, f, &t, &slot), KeyResult::kOk);
    if (p == 0) { first_slot = slot; first = t; }
    EXPECT_EQ(slot, first_slot);
    for (int k = 0; k < 3; ++k) EXPECT_EQ(t.v[k], first.v[k]);
  }
  // v0 is opposite the shortest side.
  const float s0 = (pts[first.v[1]] - pts[first.v[2]]).norm();
  EXPECT_LE(s0, (pts[first.v[0]] - pts[first.v[2]]).norm());
  EXPECT_LE(s0, (pts[first.v[0]] - pts[first.v[1]]).norm());
}

TEST(RelationKeyTest, RejectsCollinearTooLargeAndNaN) {
  const TripleFilter f{5.0f, 0.1f, 0.0f};
  std::uint32_t slot;
  const P2 line[3] = {P2(0, 0), P2(1, 0.01f), P2(2, 0)};
  Triple t;
  t.v[0] = 0; t.v[1] = 1; t.v[2] = 2;
  EXPECT_EQ(key_triple<2>(line, f, &t, &slot), KeyResult::kCollinear);
  const P2 big[3] = {P2(0, 0), P2(6, 0), P2(0, 3)};
  EXPECT_EQ(key_triple<2>(big, f, &t, &slot), KeyResult::kTooLarge);
  const P2 nan[3] = {P2(0, 0), P2(NAN, 0), P2(0, 3)};
  EXPECT_EQ(key_triple<2>(nan, f, &t, &slot), KeyResult::kNotFinite);
  const P3 line3[3] = {P3(0, 0, 0), P3(1, 1, 1), P3(2, 2, 2)};
  EXPECT_EQ(key_triple<3>(line3, f, &t, &slot), KeyResult::kCollinear);
}

TEST(HypothesisTest, TwoDFramesRecoverTheMotionAndRejectMirrors) {
  const P2 a[3] = {P2(0, 0), P2(3, 0), P2(0.5f, 2)};
  const Se2f m(1.5f, -2.0f, 0.7f);
  P2 b[3], mirror[3];
  for (int i = 0; i < 3; ++i) {
    b[i] = m.transform_point(a[i]);
    mirror[i] = P2(a[i](0), -a[i](1));
  }
  const TripleFilter f{10.0f, 0.1f, 0.0f};
  Triple ta, tb, tm;
  for (int i = 0; i < 3; ++i) ta.v[i] = tb.v[i] = tm.v[i] = static_cast<std::uint32_t>(i);
  tb.v[0] = 2; tb.v[2] = 0;  // other draw order
  std::uint32_t sa, sb, sm;
  ASSERT_EQ(key_triple<2>(a, f, &ta, &sa), KeyResult::kOk);
  ASSERT_EQ(key_triple<2>(b, f, &tb, &sb), KeyResult::kOk);
  ASSERT_EQ(key_triple<2>(mirror, f, &tm, &sm), KeyResult::kOk);
  EXPECT_EQ(sa, sb);
  EXPECT_EQ(sa, sm);  // same side lengths: a collision, but a reflected one
  TriangleFrame<2> fa, fb, fm;
  ASSERT_TRUE(triangle_frame<2>(a[ta.v[0]], a[ta.v[1]], a[ta.v[2]], &fa));
  ASSERT_TRUE(triangle_frame<2>(b[tb.v[0]], b[tb.v[1]], b[tb.v[2]], &fb));
  ASSERT_TRUE(triangle_frame<2>(mirror[tm.v[0]], mirror[tm.v[1]], mirror[tm.v[2]], &fm));
  Hypothesis<2> h;
  ASSERT_TRUE(make_hypothesis<2>(fa, fb, &h));
  const Se2f e = to_se2(h);
  EXPECT_NEAR(e.x, m.x, 1e-4f);
  EXPECT_NEAR(e.y, m.y, 1e-4f);
  EXPECT_NEAR(e.theta, m.theta, 1e-5f);
  EXPECT_FALSE(make_hypothesis<2>(fa, fm, &h)) << "Eq. 5.3: a flipped frame must be rejected";
}

TEST(HypothesisTest, ThreeDFramesRecoverTheMotionAsRpy) {
  const P3 a[3] = {P3(0, 0, 0), P3(3, 0, 0.5f), P3(0.5f, 2, -0.3f)};
  const Eigen::Matrix3f r = (Eigen::AngleAxisf(0.4f, Eigen::Vector3f::UnitZ()) *
                             Eigen::AngleAxisf(-0.2f, Eigen::Vector3f::UnitY()) *
                             Eigen::AngleAxisf(0.1f, Eigen::Vector3f::UnitX())).toRotationMatrix();
  const P3 t(1, 2, 3);
  P3 b[3];
  for (int i = 0; i < 3; ++i) b[i] = r * a[i] + t;
  TriangleFrame<3> fa, fb;
  // Both canonical in the same order (same sides).
  const TripleFilter f{10.0f, 0.1f, 0.0f};
  Triple ta, tb;
  for (int i = 0; i < 3; ++i) ta.v[i] = tb.v[i] = static_cast<std::uint32_t>(i);
  std::uint32_t s;
  ASSERT_EQ(key_triple<3>(a, f, &ta, &s), KeyResult::kOk);
  ASSERT_EQ(key_triple<3>(b, f, &tb, &s), KeyResult::kOk);
  ASSERT_TRUE(triangle_frame<3>(a[ta.v[0]], a[ta.v[1]], a[ta.v[2]], &fa));
  ASSERT_TRUE(triangle_frame<3>(b[tb.v[0]], b[tb.v[1]], b[tb.v[2]], &fb));
  Hypothesis<3> h;
  ASSERT_TRUE(make_hypothesis<3>(fa, fb, &h));
  EXPECT_LT((h.translation - t).norm(), 1e-4f);
  const Eigen::Vector3f e = rpy(h.rotation);
  EXPECT_NEAR(e(0), 0.1f, 1e-4f);
  EXPECT_NEAR(e(1), -0.2f, 1e-4f);
  EXPECT_NEAR(e(2), 0.4f, 1e-4f);
}

// ---------------------------------------------------------------- matcher fixtures

struct World2D {
  std::vector<sim::pransam_scenes::Segment> segs = sim::pransam_scenes::floor_plan(3);
  std::vector<P2> map = sim::pransam_scenes::sample_segments(segs, 0.05f);
};

MatcherOptions small_options(int workers) {
  MatcherOptions o;
  o.num_workers = workers;
  o.max_scene_points = 512;
  o.max_model_points = 40000;
  o.field.resolution = 0.05f;
  o.field.eps_hard = 0.10f;
  o.field.eps_soft = 0.20f;
  o.field.max_cells = 700 * 500;
  o.collect_capacity = 2048;
  return o;
}

class Matcher2DTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    arena_ = new StartupArena();
    ASSERT_TRUE(arena_->init_mapped(std::size_t(64) << 20, false, "pransam test").is_ok());
    world_ = new World2D();
    matcher_ = new Matcher<2>();
    const Status s = matcher_->init(small_options(2), *arena_, nullptr);
    ASSERT_TRUE(s.is_ok()) << s.message();
    ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
  }
  static void TearDownTestSuite() {
    delete matcher_;
    delete world_;
    delete arena_;
  }
  static StartupArena* arena_;
  static World2D* world_;
  static Matcher<2>* matcher_;
};
StartupArena* Matcher2DTest::arena_ = nullptr;
World2D* Matcher2DTest::world_ = nullptr;
Matcher<2>* Matcher2DTest::matcher_ = nullptr;

TEST_F(Matcher2DTest, ContactFieldIsHardThenFuzzyThenZero) {
  const ContactField<2>& f = matcher_->field();
  const P2 on_wall(0.0f, 4.0f);
  EXPECT_EQ(f.contact(on_wall), 255);
  EXPECT_EQ(f.contact(P2(0.15f, 4.0f)), 127);   // halfway between ε_h and ε_s (± one cell)
  EXPECT_EQ(f.contact(P2(0.5f, 4.0f)), 0);
  EXPECT_EQ(f.contact(P2(-50.0f, 4.0f)), 0);    // outside the field
  EXPECT_EQ(f.contact(P2(NAN, 4.0f)), 0);
  EXPECT_NEAR(f.distance(P2(0.5f, 4.0f)), 0.5f, 0.05f);
}

TEST_F(Matcher2DTest, RecoversKnownScanPosesOnline) {
  RandomStream rng(42, 0);
  const Se2f poses[3] = {Se2f(4.0f, 4.0f, 0.3f), Se2f(12.0f, 12.5f, -2.0f), Se2f(20.0f, 9.0f, 1.7f)};
  for (const Se2f& pose : poses) {
    const std::vector<P2> scan = sim::pransam_scenes::cast_scan(world_->segs, pose, 10.0f, 0.01f, rng);
    MatchParams p;
    p.seed = 5;
    p.max_iterations = 200000;
    p.omega_thres = 0.85f;
    MatchResult<2> r;
    const Status s = matcher_->match(scan.data(), scan.size(), p, &r);
    ASSERT_TRUE(s.is_ok()) << s.message();
    ASSERT_TRUE(r.found) << "best Ω " << r.best.quality << " after " << r.stats.iterations;
    const Se2f e = to_se2(r.best);
    EXPECT_LT(std::hypot(e.x - pose.x, e.y - pose.y), 0.15f) << e.x << " " << e.y;
    EXPECT_LT(angle_diff(e.theta, pose.theta), 3.0f * kPi / 180.0f);
    EXPECT_EQ(r.stats.stop, StopReason::kThreshold);
    EXPECT_GT(r.stats.collisions, 0u);
  }
}

// Issue 13: a degenerate map (3 occupied cells) made the start-up fill of a 2-million-triple
// table spin 64 s ("0 of 2000000 triples keyable after 400100000 draws"). It must fail fast with
// an error that names the problem.
TEST_F(Matcher2DTest, DegenerateModelFailsFastInsteadOfSpinning) {
  const P2 collinear[3] = {P2(1.025f, 1.025f), P2(1.075f, 1.025f), P2(1.125f, 1.025f)};  // 3 cells in a row
  const P2 tiny[3] = {P2(1.025f, 1.025f), P2(1.075f, 1.025f), P2(1.025f, 1.075f)};      // an L of 3 cells
  for (const P2* pts : {collinear, tiny}) {
    ASSERT_TRUE(matcher_->set_model(pts, 3, "three cells").is_ok());
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = matcher_->fill_model_table(7, 2000000, 10.0f, 0.1f);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(s.is_ok());
    EXPECT_NE(std::strstr(s.message(), "too few occupied points"), nullptr) << s.message();
    EXPECT_NE(std::strstr(s.message(), "no keyable triple"), nullptr) << s.message();
    EXPECT_LT(seconds, 2.0) << s.message();
  }
  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
}

TEST(FillBoundTest, GivesUpOnlyWhenHopelesslyBehindThePace) {
  const std::uint64_t triples = 2000000, cap = triples * kFillDrawsPerTriple + kFillMinDraws;
  // Nothing keyable after the first check: hopeless.
  EXPECT_TRUE(fill_behind_pace(0, kFillCheckEvery, triples, cap));
  // Exactly on the pace the cap needs (0.5 %), or better: keep drawing.
  EXPECT_FALSE(fill_behind_pace(21, kFillCheckEvery, triples, cap));
  EXPECT_FALSE(fill_behind_pace(400, kFillCheckEvery, triples, cap));
  // Half the needed rate, measured over a million draws: hopeless.
  EXPECT_TRUE(fill_behind_pace(2500, 1000000, triples, cap));
  // Small tables are never refused early for a slow start.
  EXPECT_FALSE(fill_behind_pace(0, kFillCheckEvery, 10, 10 * kFillDrawsPerTriple + kFillMinDraws));
  EXPECT_FALSE(fill_behind_pace(5, 0, triples, cap));
}

TEST_F(Matcher2DTest, RecoversKnownScanPoseWithPrecomputedTableAndSectionRoundTrip) {
  std::vector<float> xy;
  for (const P2& p : world_->map) { xy.push_back(p(0)); xy.push_back(p(1)); }
  // Offline fill of R_B (Theorem 2), serialised and used in place as a map image section would be.
  ASSERT_TRUE(matcher_->fill_model_table(11, 300000, 10.0f, 0.1f).is_ok());
  const RelationTableStats& st = matcher_->model_table().stats();
  EXPECT_EQ(st.inserts, 300000u);
  EXPECT_EQ(st.filled + st.overwrites, st.inserts);
  EXPECT_EQ(st.filled, matcher_->model_table().count_filled());
  EXPECT_GT(st.overwrites, 0u);
  std::vector<std::uint8_t> section(relation_table_section_bytes() + 16);
  std::uint8_t* aligned = section.data() + (16 - reinterpret_cast<std::uintptr_t>(section.data()) % 16) % 16;
  ASSERT_TRUE(write_relation_table_section(matcher_->model_table(), 2, 0.1f, xy.data(),
                                           static_cast<std::uint32_t>(world_->map.size()), 300000, aligned,
                                           relation_table_section_bytes())
                  .is_ok());
  RelationTableSection view;
  ASSERT_TRUE(parse_relation_table_section(aligned, relation_table_section_bytes(), 2, xy.data(),
                                           static_cast<std::uint32_t>(world_->map.size()), &view)
                  .is_ok());
  EXPECT_EQ(view.filled, st.filled);
  // A table for another map, a 3-D reader and a truncated payload are refused.
  std::vector<float> other = xy;
  other[0] += 1.0f;
  RelationTableSection bad;
  EXPECT_FALSE(parse_relation_table_section(aligned, relation_table_section_bytes(), 2, other.data(),
                                            static_cast<std::uint32_t>(world_->map.size()), &bad).is_ok());
  EXPECT_FALSE(parse_relation_table_section(aligned, relation_table_section_bytes(), 3, xy.data(),
                                            static_cast<std::uint32_t>(world_->map.size()), &bad).is_ok());
  EXPECT_FALSE(parse_relation_table_section(aligned, 100, 2, xy.data(),
                                            static_cast<std::uint32_t>(world_->map.size()), &bad).is_ok());

  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
  ASSERT_TRUE(matcher_->use_precomputed_table(view.slots, view.extent).is_ok());
  RandomStream rng(43, 0);
  const Se2f pose(5.0f, 12.0f, 2.5f);
  const std::vector<P2> scan = sim::pransam_scenes::cast_scan(world_->segs, pose, 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 9;
  p.max_iterations = 100000;
  p.omega_thres = 0.85f;
  MatchResult<2> r;
  ASSERT_TRUE(matcher_->match(scan.data(), scan.size(), p, &r).is_ok());
  ASSERT_TRUE(r.found);
  const Se2f e = to_se2(r.best);
  EXPECT_LT(std::hypot(e.x - pose.x, e.y - pose.y), 0.15f);
  EXPECT_LT(angle_diff(e.theta, pose.theta), 3.0f * kPi / 180.0f);
  // Corrupt index in the section: refused before use.
  std::vector<Triple> corrupt(view.slots, view.slots + kNumSlots);
  for (Triple& t : corrupt) if (!t.empty()) { t.v[1] = 0xFFFFFFF0u; break; }
  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
  EXPECT_EQ(matcher_->use_precomputed_table(corrupt.data(), view.extent).code(), Errc::kCorruptData);
  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
}

// reset(): the online tables are emptied (with their statistics) and a match after other matches
// and reset() repeats the first one bit-identically; a precomputed R_B filled at start-up survives.
TEST_F(Matcher2DTest, ResetEmptiesOnlineTablesKeepsPrecomputedOne) {
  RandomStream rng(51, 0);
  const std::vector<P2> x = sim::pransam_scenes::cast_scan(world_->segs, Se2f(6.0f, 5.0f, 0.4f), 10.0f, 0.01f, rng);
  const std::vector<P2> y = sim::pransam_scenes::cast_scan(world_->segs, Se2f(18.0f, 11.0f, -1.2f), 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 3;
  p.max_iterations = 30000;
  p.omega_thres = 0.6f;
  p.collect_all = true;
  auto run = [&](const std::vector<P2>& scene, std::vector<Hypothesis<2>>* hyps) {
    MatchResult<2> r;
    ASSERT_TRUE(matcher_->match(scene.data(), scene.size(), p, &r).is_ok());
    hyps->assign(r.hypotheses, r.hypotheses + r.num_hypotheses);
  };
  std::vector<Hypothesis<2>> first, other, again;
  run(x, &first);
  ASSERT_FALSE(first.empty());
  run(y, &other);
  EXPECT_GT(matcher_->scene_table().stats().inserts, 0u);
  matcher_->reset();
  EXPECT_EQ(matcher_->scene_table().count_filled(), 0u);
  EXPECT_EQ(matcher_->model_table().count_filled(), 0u);
  EXPECT_EQ(matcher_->scene_table().stats().inserts, 0u);
  run(x, &again);
  ASSERT_EQ(first.size(), again.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(first[i].quality, again[i].quality) << i;
    EXPECT_EQ(first[i].iteration, again[i].iteration) << i;
    EXPECT_TRUE(first[i].translation == again[i].translation) << i;
  }
  // Start-up fill used in place (MML without a map-image table): reset() must keep it.
  ASSERT_TRUE(matcher_->fill_model_table(13, 100000, 10.0f, 0.1f).is_ok());
  ASSERT_TRUE(matcher_->use_precomputed_table(matcher_->model_table().data(), 10.0f).is_ok());
  const std::size_t filled = matcher_->model_table().count_filled();
  matcher_->reset();
  EXPECT_TRUE(matcher_->has_precomputed_table());
  EXPECT_EQ(matcher_->model_table().count_filled(), filled);
  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
}

// Deadline mode (Sec. 4.4.3, issue 14): with a clock that advances 1 ms per reading, the first
// round takes "1 ms"; the second (twice the batch) is predicted at 2 ms, so a deadline 1 ms after
// its start stops the match after one round; a distant deadline changes nothing.
TEST_F(Matcher2DTest, DeadlineModeStopsWhenTheNextRoundWouldNotFit) {
  struct StepClock final : hal::Clock {
    mutable std::uint64_t t = 0;
    std::uint64_t now_ns() const override { return t += 1000000; }
  };
  RandomStream rng(51, 0);
  const std::vector<P2> x = sim::pransam_scenes::cast_scan(world_->segs, Se2f(6.0f, 5.0f, 0.4f), 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 3;
  p.max_iterations = 30000;
  p.omega_thres = 0.6f;
  p.collect_all = true;
  MatchResult<2> full;
  ASSERT_TRUE(matcher_->match(x.data(), x.size(), p, &full).is_ok());
  EXPECT_EQ(full.stats.stop, StopReason::kMaxIterations);
  StepClock clock;
  p.clock = &clock;
  p.deadline_ns = 4000000;  // round 1: 1..2 ms; round 2 would start at 3 ms and need 2 ms
  MatchResult<2> cut;
  ASSERT_TRUE(matcher_->match(x.data(), x.size(), p, &cut).is_ok());
  EXPECT_EQ(cut.stats.stop, StopReason::kDeadline);
  EXPECT_EQ(cut.stats.rounds, 1u);
  EXPECT_LT(cut.stats.iterations, full.stats.iterations);
  clock.t = 0;
  p.deadline_ns = 1000000000000ull;
  MatchResult<2> late;
  ASSERT_TRUE(matcher_->match(x.data(), x.size(), p, &late).is_ok());
  EXPECT_EQ(late.stats.stop, StopReason::kMaxIterations);
  EXPECT_EQ(late.stats.iterations, full.stats.iterations);
}

// Issue 60: a deadline stop replayed without a clock (MatchParams::stop_after_rounds, the black
// box's recorded rounds) gives the same hypotheses, stats and stop reason as the clock did.
TEST_F(Matcher2DTest, DeadlineStopReplaysByItsRoundCount) {
  struct StepClock final : hal::Clock {
    mutable std::uint64_t t = 0;
    std::uint64_t now_ns() const override { return t += 1000000; }
  };
  RandomStream rng(51, 0);
  const std::vector<P2> x = sim::pransam_scenes::cast_scan(world_->segs, Se2f(6.0f, 5.0f, 0.4f), 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 3;
  p.max_iterations = 30000;
  p.omega_thres = 0.3f;  // low: the cut run collects hypotheses to compare
  p.collect_all = true;
  StepClock clock;
  p.clock = &clock;
  p.deadline_ns = 20000000;  // a few rounds, then the deadline
  MatchResult<2> cut;
  ASSERT_TRUE(matcher_->match(x.data(), x.size(), p, &cut).is_ok());
  ASSERT_EQ(cut.stats.stop, StopReason::kDeadline);
  std::vector<Hypothesis<2>> want(cut.hypotheses, cut.hypotheses + cut.num_hypotheses);
  MatchParams r = p;
  r.clock = nullptr;
  r.deadline_ns = 0;
  r.stop_after_rounds = cut.stats.rounds;
  MatchResult<2> again;
  ASSERT_TRUE(matcher_->match(x.data(), x.size(), r, &again).is_ok());
  EXPECT_EQ(again.stats.stop, StopReason::kDeadline);
  EXPECT_EQ(again.stats.rounds, cut.stats.rounds);
  EXPECT_EQ(again.stats.iterations, cut.stats.iterations);
  EXPECT_LT(cut.stats.iterations, 30000u);
  ASSERT_TRUE(cut.best_valid);
  EXPECT_EQ(again.best.quality, cut.best.quality);
  EXPECT_TRUE(again.best.translation == cut.best.translation);
  ASSERT_EQ(again.num_hypotheses, want.size());
  EXPECT_GT(want.size(), 0u);
  for (std::size_t i = 0; i < want.size(); ++i) {
    EXPECT_EQ(again.hypotheses[i].quality, want[i].quality) << i;
    EXPECT_EQ(again.hypotheses[i].iteration, want[i].iteration) << i;
    EXPECT_TRUE(again.hypotheses[i].translation == want[i].translation) << i;
  }
  std::printf("deadline stop after %u rounds (%llu iterations, %zu hypotheses) replayed identical\n",
              cut.stats.rounds, static_cast<unsigned long long>(cut.stats.iterations), want.size());
}

TEST_F(Matcher2DTest, RefinementAndFreeSpaceGateKeepTheRightAnswer) {
  RandomStream rng(47, 0);
  const Se2f pose(20.0f, 13.0f, -0.8f);
  const std::vector<P2> scan = sim::pransam_scenes::cast_scan(world_->segs, pose, 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 21;
  p.max_iterations = 200000;
  p.omega_thres = 0.97f;
  p.refine_iterations = 5;
  p.refine_min_quality = 0.8f;
  p.scene_origin_is_sensor = true;
  MatchResult<2> r;
  ASSERT_TRUE(matcher_->match(scan.data(), scan.size(), p, &r).is_ok());
  ASSERT_TRUE(r.found) << r.best.quality;
  EXPECT_GT(r.stats.refined, 0u);
  const Se2f e = to_se2(r.best);
  // Refined: much tighter than the raw triangle hypothesis.
  EXPECT_LT(std::hypot(e.x - pose.x, e.y - pose.y), 0.05f);
  EXPECT_LT(angle_diff(e.theta, pose.theta), 1.0f * kPi / 180.0f);
}

TEST_F(Matcher2DTest, MalformedInputsReturnAStatus) {
  MatchParams p;
  MatchResult<2> r;
  EXPECT_EQ(matcher_->match(nullptr, 0, p, &r).code(), Errc::kInvalidArgument);
  const P2 two[2] = {P2(0, 0), P2(1, 1)};
  EXPECT_EQ(matcher_->match(two, 2, p, &r).code(), Errc::kInvalidArgument);
  std::vector<P2> line;
  for (int i = 0; i < 50; ++i) line.push_back(P2(0.1f * static_cast<float>(i), 0.02f * static_cast<float>(i)));
  const Status sl = matcher_->match(line.data(), line.size(), p, &r);
  EXPECT_EQ(sl.code(), Errc::kInvalidArgument);
  EXPECT_NE(std::strstr(sl.message(), "collinear"), nullptr) << sl.message();
  std::vector<P2> nan = line;
  nan[7] = P2(NAN, 1.0f);
  const Status sn = matcher_->match(nan.data(), nan.size(), p, &r);
  EXPECT_EQ(sn.code(), Errc::kInvalidArgument);
  EXPECT_NE(std::strstr(sn.message(), "point 7"), nullptr) << sn.message();
  std::vector<P2> big(600, P2(1, 1));
  EXPECT_EQ(matcher_->match(big.data(), big.size(), p, &r).code(), Errc::kCapacityExceeded);
  MatchParams bad = p;
  bad.omega_thres = 1.5f;
  const P2 tri[3] = {P2(0, 0), P2(1, 0), P2(0, 1)};
  EXPECT_EQ(matcher_->match(tri, 3, bad, &r).code(), Errc::kInvalidArgument);
  MatchParams badtau = p;
  badtau.tau = 2;  // T = 2: tau must leave a worker for R_B
  EXPECT_EQ(matcher_->match(tri, 3, badtau, &r).code(), Errc::kInvalidArgument);
  // Model errors.
  Matcher<2> fresh;
  EXPECT_EQ(fresh.match(tri, 3, p, &r).code(), Errc::kNotInitialized);
  EXPECT_EQ(matcher_->set_model(nan.data(), nan.size(), "nan map").code(), Errc::kInvalidArgument);
  EXPECT_EQ(matcher_->set_model(two, 2, "tiny map").code(), Errc::kInvalidArgument);
  EXPECT_EQ(matcher_->match(tri, 3, p, &r).code(), Errc::kNotInitialized);
  ASSERT_TRUE(matcher_->set_model(world_->map.data(), world_->map.size(), "floor plan").is_ok());
}

// Same seed and T ⇒ identical hypothesis set, whether the pool has 1 or 2 threads (or none).
TEST(MatcherDeterminismTest, SameSeedSameHypothesesOnOneAndTwoPoolWorkers) {
  World2D world;
  RandomStream rng(44, 0);
  const Se2f pose(10.0f, 3.0f, 0.9f);
  const std::vector<P2> scan = sim::pransam_scenes::cast_scan(world.segs, pose, 10.0f, 0.01f, rng);
  MatchParams p;
  p.seed = 77;
  p.max_iterations = 30000;
  p.omega_thres = 0.6f;
  p.collect_all = true;
  std::vector<std::vector<Hypothesis<2>>> runs;
  for (int pool_size : {0, 1, 2, 2}) {
    StartupArena arena;
    ASSERT_TRUE(arena.init_mapped(std::size_t(48) << 20, false, "det").is_ok());
    WorkerPool pool;
    if (pool_size > 0) {
      WorkerPoolOptions po;
      po.num_workers = pool_size;
      po.pin = false;
      ASSERT_TRUE(pool.start(po).is_ok());
    }
    Matcher<2> m;
    ASSERT_TRUE(m.init(small_options(4), arena, pool_size > 0 ? &pool : nullptr).is_ok());
    ASSERT_TRUE(m.set_model(world.map.data(), world.map.size()).is_ok());
    MatchResult<2> r;
    ASSERT_TRUE(m.match(scan.data(), scan.size(), p, &r).is_ok());
    EXPECT_EQ(r.stats.iterations, 30000u);
    EXPECT_GT(r.num_hypotheses, 0u);
    runs.emplace_back(r.hypotheses, r.hypotheses + r.num_hypotheses);
  }
  for (std::size_t k = 1; k < runs.size(); ++k) {
    ASSERT_EQ(runs[k].size(), runs[0].size()) << "run " << k;
    for (std::size_t i = 0; i < runs[0].size(); ++i) {
      const Hypothesis<2>& x = runs[k][i];
      const Hypothesis<2>& y = runs[0][i];
      EXPECT_EQ(std::memcmp(x.rotation.data(), y.rotation.data(), sizeof(float) * 4), 0) << "run " << k << " hyp " << i;
      EXPECT_EQ(std::memcmp(x.translation.data(), y.translation.data(), sizeof(float) * 2), 0) << k << " " << i;
      EXPECT_EQ(std::memcmp(&x.quality, &y.quality, sizeof(float)), 0) << k << " " << i;
      EXPECT_EQ(x.iteration, y.iteration);
      EXPECT_EQ(x.worker, y.worker);
    }
  }
}

TEST(MatcherCollectTest, BoundedBufferCountsDropped) {
  World2D world;
  RandomStream rng(45, 0);
  const std::vector<P2> scan = sim::pransam_scenes::cast_scan(world.segs, Se2f(4, 12, 0.2f), 10.0f, 0.01f, rng);
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(std::size_t(48) << 20, false, "collect").is_ok());
  MatcherOptions o = small_options(2);
  o.collect_capacity = 4;
  Matcher<2> m;
  ASSERT_TRUE(m.init(o, arena, nullptr).is_ok());
  ASSERT_TRUE(m.set_model(world.map.data(), world.map.size()).is_ok());
  MatchParams p;
  p.max_iterations = 50000;
  p.omega_thres = 0.3f;
  p.collect_all = true;
  MatchResult<2> r;
  ASSERT_TRUE(m.match(scan.data(), scan.size(), p, &r).is_ok());
  EXPECT_EQ(r.num_hypotheses, 4u);
  EXPECT_GT(r.dropped, 0u);
  EXPECT_EQ(r.stats.iterations, 50000u);  // collect-all runs the full I_max
  for (std::size_t i = 0; i < r.num_hypotheses; ++i) EXPECT_GE(r.hypotheses[i].quality, 0.3f);
}

// ---------------------------------------------------------------- 3-D

TEST(Matcher3DTest, RecoversKnownTransformBetweenOverlappingTexturedClouds) {
  RandomStream scan_b(46, 1), scan_a(46, 2);
  const std::vector<P3> b = sim::pransam_scenes::crop(sim::pransam_scenes::textured_room(60.0f, scan_b),
                                                      P3(-1, -1, -1), P3(6.5f, 7, 4));
  const std::vector<P3> a_world = sim::pransam_scenes::crop(sim::pransam_scenes::textured_room(15.0f, scan_a),
                                                            P3(1.5f, -1, -1), P3(9, 7, 4));
  // Subsample A and move it by the inverse of the known transform (so H maps A back onto B).
  const Eigen::Matrix3f r = (Eigen::AngleAxisf(0.6f, Eigen::Vector3f::UnitZ()) *
                             Eigen::AngleAxisf(0.1f, Eigen::Vector3f::UnitY()) *
                             Eigen::AngleAxisf(-0.05f, Eigen::Vector3f::UnitX())).toRotationMatrix();
  const P3 t(0.5f, -0.3f, 0.2f);
  std::vector<P3> a;
  RandomStream rng(46, 0);
  for (std::size_t i = 0; i < a_world.size(); ++i) {
    const P3 noisy = a_world[i] + sim::pransam_scenes::gaussian3f(rng, 0.005f);
    a.push_back(r.transpose() * (noisy - t));
  }
  StartupArena arena;
  ASSERT_TRUE(arena.init_mapped(std::size_t(64) << 20, false, "3d").is_ok());
  MatcherOptions o;
  o.num_workers = 2;
  o.max_scene_points = 4096;
  o.max_model_points = 40000;
  o.field.resolution = 0.05f;
  o.field.eps_hard = 0.10f;
  o.field.eps_soft = 0.20f;
  o.field.max_cells = std::size_t(4) << 20;
  o.field.max_axis = 512;
  Matcher<3> m;
  const Status si = m.init(o, arena, nullptr);
  ASSERT_TRUE(si.is_ok()) << si.message();
  const Status sm = m.set_model(b.data(), b.size(), "room crop B");
  ASSERT_TRUE(sm.is_ok()) << sm.message();
  MatchParams p;
  p.seed = 3;
  p.max_iterations = 200000;
  // The room is nearly symmetric under a 180° turn, and a wrong pose reaches Ω ≈ 0.52 while the
  // true overlap is about 0.6: run the full I_max and keep the best (the "after I_max" stop).
  p.omega_thres = 0.99f;
  p.refine_iterations = 10;  // polish hypotheses with Ω ≥ 0.45 on the voxel distance field
  p.refine_min_quality = 0.45f;
  MatchResult<3> res;
  const Status s = m.match(a.data(), a.size(), p, &res);
  ASSERT_TRUE(s.is_ok()) << s.message();
  ASSERT_TRUE(res.best_valid);
  EXPECT_EQ(res.stats.iterations, 200000u);
  EXPECT_LT((res.best.translation - t).norm(), 0.25f);
  const Eigen::Vector3f e = rpy(res.best.rotation), g = rpy(r);
  for (int k = 0; k < 3; ++k) EXPECT_LT(angle_diff(e(k), g(k)), 3.0f * kPi / 180.0f) << k;
}

}  // namespace
}  // namespace fw::pransam
