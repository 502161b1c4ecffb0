// GraphRefine (graph_refine.h): the final refinement of the whole fragment graph. On a ring of
// frames it must find the least-squares frames — checked against a dense Gauss–Newton solve of the
// same problem — spread a closure's error over the loop instead of leaving it on one edge, never
// raise W, refuse edges that name a frame it was not given, and allocate nothing.
#include "firmware/antslam/graph_refine.h"

#include <gtest/gtest.h>

#include <Eigen/Cholesky>
#include <cmath>
#include <vector>

#include "tests/alloc_counter.h"

namespace fw::antslam {
namespace {

constexpr std::uint32_t kFrames = 12;
constexpr std::uint32_t kOptions = 4;

// A ring of kFrames frames (10 m radius), adjacent edges i → i+1 and one closure 11 → 0. `drift`:
// every adjacent edge is measured 3 % too long and turned 1.5° too far, the closure exactly.
struct Ring {
  std::vector<Se2d> truth;
  std::vector<SampledEdge> edges;
  std::vector<Se2d> options;
  std::vector<double> costs;

  explicit Ring(bool drift) : edges(kFrames), options(kFrames * kOptions), costs(kFrames * kOptions) {
    RandomStream rng(3, 0);
    const double step = 2 * M_PI / kFrames;
    for (std::uint32_t i = 0; i < kFrames; ++i) {
      truth.emplace_back(10 * std::cos(i * step), 10 * std::sin(i * step), wrap_angle(i * step + M_PI / 2));
    }
    for (std::uint32_t i = 0; i < kFrames; ++i) {
      const std::uint32_t j = (i + 1) % kFrames;
      const bool closure = j == 0;
      Se2d mean = truth[i].between(truth[j]);
      Mat3 cov = Mat3::Zero();
      if (closure) {
        cov.diagonal() << 0.02 * 0.02, 0.02 * 0.02, std::pow(0.5 * M_PI / 180, 2);
      } else {
        if (drift) mean = Se2d(mean.x * 1.03, mean.y * 1.03, wrap_angle(mean.theta + 1.5 * M_PI / 180));
        cov.diagonal() << 0.05 * 0.05, 0.05 * 0.05, std::pow(1.5 * M_PI / 180, 2);
      }
      EXPECT_TRUE(init_sampled_edge(i, j, mean, cov, &options[i * kOptions], &costs[i * kOptions], kOptions, rng,
                                    &edges[i])
                      .is_ok());
      edges[i].closure = closure;
    }
  }
  // The frames by chaining the adjacent edges' means from frame 0: every bit of the drift ends
  // up on the closure, as after a loop whose correction was frozen before it.
  std::vector<Se2d> chained() const {
    std::vector<Se2d> p{truth[0]};
    for (std::uint32_t i = 0; i + 1 < kFrames; ++i) p.push_back(p.back().compose(edges[i].mean));
    return p;
  }
};

struct Arena {
  std::vector<unsigned char> bytes = std::vector<unsigned char>(1 << 16);
  StartupArena arena;
  Arena() { EXPECT_TRUE(arena.init(bytes.data(), bytes.size(), "test").is_ok()); }
};

// Dense Gauss–Newton on the same cost (frame 0 held), fixed-size: the reference answer.
std::vector<Se2d> dense_solution(const Ring& r, std::vector<Se2d> p) {
  constexpr int kN = 3 * (kFrames - 1);
  using MatN = Eigen::Matrix<double, kN, kN>;
  using VecN = Eigen::Matrix<double, kN, 1>;
  for (int it = 0; it < 30; ++it) {
    MatN h = MatN::Zero();
    VecN g = VecN::Zero();
    for (const SampledEdge& e : r.edges) {
      // Numerical Jacobian of r_e = (P_from ⊖ P_to) − μ.
      Eigen::Matrix<double, 3, 6> j;
      const auto res = [&](const std::vector<Se2d>& q) {
        return se2_difference(q[e.from].between(q[e.to]), e.mean);
      };
      const Vec3 r0 = res(p);
      for (int k = 0; k < 6; ++k) {
        std::vector<Se2d> q = p;
        Se2d& f = q[k < 3 ? e.from : e.to];
        const double eps = 1e-7;
        if (k % 3 == 0) f.x += eps;
        if (k % 3 == 1) f.y += eps;
        if (k % 3 == 2) f.theta += eps;
        j.col(k) = (res(q) - r0) / eps;
      }
      const int idx[2] = {static_cast<int>(e.from) - 1, static_cast<int>(e.to) - 1};
      for (int a = 0; a < 2; ++a) {
        if (idx[a] < 0) continue;
        g.segment<3>(3 * idx[a]) += j.block<3, 3>(0, 3 * a).transpose() * e.info * r0;
        for (int b = 0; b < 2; ++b) {
          if (idx[b] < 0) continue;
          h.block<3, 3>(3 * idx[a], 3 * idx[b]) +=
              j.block<3, 3>(0, 3 * a).transpose() * e.info * j.block<3, 3>(0, 3 * b);
        }
      }
    }
    const VecN d = h.ldlt().solve(-g);
    for (std::uint32_t i = 1; i < kFrames; ++i) {
      p[i] = Se2d(p[i].x + d(3 * (i - 1)), p[i].y + d(3 * (i - 1) + 1), wrap_angle(p[i].theta + d(3 * (i - 1) + 2)));
    }
  }
  return p;
}

TEST(GraphRefineTest, FindsTheConsistentFramesFromAPerturbedStart) {
  const Ring r(false);
  std::vector<Se2d> p = r.truth;
  for (std::uint32_t i = 1; i < kFrames; ++i) p[i] = Se2d(p[i].x + 0.3 * std::sin(i), p[i].y - 0.2, p[i].theta + 0.05);
  Arena a;
  GraphRefine g;
  ASSERT_TRUE(g.init(GraphRefineOptions(), kFrames, kFrames, a.arena).is_ok());
  GraphRefineReport rep;
  ASSERT_TRUE(g.refine(r.edges.data(), kFrames, p.data(), kFrames, &rep).is_ok());
  EXPECT_GT(rep.initial_cost, 100.0);
  EXPECT_LT(rep.final_cost, 1e-10);
  for (std::uint32_t i = 0; i < kFrames; ++i) {
    EXPECT_NEAR(p[i].x, r.truth[i].x, 1e-6) << i;
    EXPECT_NEAR(p[i].y, r.truth[i].y, 1e-6) << i;
    EXPECT_NEAR(wrap_angle(p[i].theta - r.truth[i].theta), 0.0, 1e-7) << i;
  }
}

TEST(GraphRefineTest, SpreadsTheClosureErrorLikeTheDenseSolution) {
  const Ring r(true);
  std::vector<Se2d> p = r.chained();
  const double gap0 = std::hypot(p.back().between(p[0]).x - r.edges.back().mean.x,
                                 p.back().between(p[0]).y - r.edges.back().mean.y);
  ASSERT_GT(gap0, 1.0);  // the drift really opens the ring
  const std::vector<Se2d> want = dense_solution(r, p);
  Arena a;
  GraphRefine g;
  ASSERT_TRUE(g.init(GraphRefineOptions(), kFrames, kFrames, a.arena).is_ok());
  GraphRefineReport rep;
  const bool count = mmlfw_test::AllocCounter::available();
  if (count) mmlfw_test::AllocCounter::begin();
  const Status st = g.refine(r.edges.data(), kFrames, p.data(), kFrames, &rep);
  const long allocations = count ? mmlfw_test::AllocCounter::end() : 0;
  ASSERT_TRUE(st.is_ok()) << st.message();
  EXPECT_EQ(allocations, 0) << "refine allocated";
  EXPECT_LT(rep.final_cost, 0.05 * rep.initial_cost);
  EXPECT_NEAR(rep.final_cost, graph_cost(r.edges.data(), kFrames, want.data()), 1e-6 * rep.initial_cost);
  for (std::uint32_t i = 0; i < kFrames; ++i) {
    EXPECT_NEAR(p[i].x, want[i].x, 1e-5) << i;
    EXPECT_NEAR(p[i].y, want[i].y, 1e-5) << i;
    EXPECT_NEAR(wrap_angle(p[i].theta - want[i].theta), 0.0, 1e-6) << i;
  }
  // Spread: no adjacent edge is left with most of the error, as a frozen loop would leave it.
  double worst = 0.0, total = 0.0;
  for (std::uint32_t i = 0; i < kFrames; ++i) {
    const SampledEdge& e = r.edges[i];
    const double w = mahalanobis2(p[e.from].between(p[e.to]), e.mean, e.info);
    worst = std::max(worst, w);
    total += w;
  }
  EXPECT_LT(worst, 0.5 * total);
}

TEST(GraphRefineTest, RefusesEdgesBeyondItsFramesAndNeverRaisesTheCost) {
  Ring r(true);
  Arena a;
  GraphRefine g;
  std::vector<Se2d> p = r.chained();
  GraphRefineReport rep;
  EXPECT_FALSE(g.refine(r.edges.data(), kFrames, p.data(), kFrames, &rep).is_ok());  // before init
  ASSERT_TRUE(g.init(GraphRefineOptions(), kFrames, kFrames, a.arena).is_ok());
  const Status few = g.refine(r.edges.data(), kFrames, p.data(), kFrames - 1, &rep);
  ASSERT_FALSE(few.is_ok());
  EXPECT_NE(std::string(few.message()).find("edge 10"), std::string::npos) << few.message();
  EXPECT_FALSE(g.refine(r.edges.data(), kFrames, p.data(), kFrames + 1, &rep).is_ok());  // capacity
  GraphRefineOptions bad;
  bad.max_iterations = 0;
  GraphRefine g2;
  EXPECT_FALSE(g2.init(bad, kFrames, kFrames, a.arena).is_ok());
  // Already at the minimum: nothing moves, W stays.
  std::vector<Se2d> q = r.truth;
  Ring exact(false);
  ASSERT_TRUE(g.refine(exact.edges.data(), kFrames, q.data(), kFrames, &rep).is_ok());
  EXPECT_LE(rep.final_cost, rep.initial_cost);
  EXPECT_EQ(rep.iterations, 0u);
}

}  // namespace
}  // namespace fw::antslam
