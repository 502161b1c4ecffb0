// The grounding estimator on synthetic trajectories with known scale errors and known noise: it must
// recover them. Also the map distance and the residual summary on a tiny grid, and the verdict rule.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "sim/eval/grounding/grounding.h"

namespace sim::ground {
namespace {

struct Noise {
  double dist_scale = 0, turn_scale = 0;
  double sigma_xy = 0, sigma_theta = 0;  // per step
};

// A long drive of 0.1 m steps: straight runs of 20 m joined by 90° turns of 10 steps (in place plus
// a little forward motion). Odometry = truth increments with the scale errors and the noise.
void drive(const Noise& n, std::size_t steps, std::vector<fw::Se2d>* odom, std::vector<fw::Se2d>* ref) {
  std::mt19937_64 rng(7);
  std::normal_distribution<double> g(0.0, 1.0);
  fw::Se2d t, o;
  odom->push_back(o);
  ref->push_back(t);
  for (std::size_t i = 0; i < steps; ++i) {
    const bool turning = (i % 210) >= 200;
    const double dx = turning ? 0.01 : 0.1, dth = turning ? (M_PI / 2) / 10 : 0.0;
    t = t.compose(fw::Se2d(dx, 0, dth));
    const double nx = g(rng), ny = g(rng), nt = g(rng);
    o = o.compose(fw::Se2d(dx * (1 + n.dist_scale) + n.sigma_xy * nx, n.sigma_xy * ny,
                           dth * (1 + n.turn_scale) + n.sigma_theta * nt));
    odom->push_back(o);
    ref->push_back(t);
  }
}

TEST(OdometryWindows, RecoversSystematicScaleErrors) {
  Noise n;
  n.dist_scale = 0.03;
  n.turn_scale = -0.05;
  n.sigma_xy = 0.001;
  n.sigma_theta = 0.0005;
  std::vector<fw::Se2d> odom, ref;
  drive(n, 20000, &odom, &ref);
  WindowOptions w;
  w.window_m = 1.0;
  const OdometryErrorSummary s = summarize(odometry_windows(odom, ref, w));
  ASSERT_GT(s.straight_windows, 1000u);
  EXPECT_NEAR(s.dist_scale_median, 0.03, 0.003);
  ASSERT_GT(s.turning_windows, 50u);
  EXPECT_NEAR(s.turn_scale_median, -0.05, 0.005);
  // A turn of 90° with a 5 % turn-scale error: 0.05 rad per rad.
  EXPECT_NEAR(s.head_per_rad_p50, 0.05, 0.01);
}

TEST(OdometryWindows, RecoversHeadingNoise) {
  // Straight driving, heading noise only: after N steps the heading error is N(0, σ²N), so the
  // median of its absolute value per metre is 0.6745 σ √N / L.
  Noise n;
  n.sigma_theta = 0.002;
  std::vector<fw::Se2d> odom, ref;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> g(0.0, 1.0);
  fw::Se2d t, o;
  odom.push_back(o);
  ref.push_back(t);
  for (int i = 0; i < 50000; ++i) {
    t = t.compose(fw::Se2d(0.1, 0, 0));
    o = o.compose(fw::Se2d(0.1, 0, n.sigma_theta * g(rng)));
    odom.push_back(o);
    ref.push_back(t);
  }
  WindowOptions w;
  w.window_m = 1.0;
  const OdometryErrorSummary s = summarize(odometry_windows(odom, ref, w));
  ASSERT_GT(s.windows, 4000u);
  const double expected_deg = 0.6745 * n.sigma_theta * std::sqrt(10.0) / 1.0 * 180.0 / M_PI;
  EXPECT_NEAR(s.head_deg_per_m_p50, expected_deg, 0.08 * expected_deg);
  EXPECT_EQ(s.turning_windows, 0u);
}

TEST(OdometryWindows, RecoversTranslationNoise) {
  // Straight driving, xy noise only (σ per step in x and y): the error after N steps is a 2-D
  // Gaussian of σ√N per axis, its length Rayleigh with median 1.1774 σ √N.
  std::vector<fw::Se2d> odom, ref;
  std::mt19937_64 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  const double sigma = 0.004;
  fw::Se2d t, o;
  odom.push_back(o);
  ref.push_back(t);
  for (int i = 0; i < 50000; ++i) {
    t = t.compose(fw::Se2d(0.1, 0, 0));
    const double nx = g(rng), ny = g(rng);
    o = o.compose(fw::Se2d(0.1 + sigma * nx, sigma * ny, 0));
    odom.push_back(o);
    ref.push_back(t);
  }
  WindowOptions w;
  w.window_m = 5.0;
  const OdometryErrorSummary s = summarize(odometry_windows(odom, ref, w));
  ASSERT_GT(s.windows, 900u);
  const double expected = 1.1774 * sigma * std::sqrt(50.0) / 5.0;
  EXPECT_NEAR(s.trans_p50, expected, 0.08 * expected);
  EXPECT_NEAR(s.dist_scale_median, 0.0, 0.002);
}

TEST(OdometryWindows, PerfectOdometryHasNoError) {
  std::vector<fw::Se2d> odom, ref;
  drive(Noise{}, 3000, &odom, &ref);
  // The odometry frame may differ from the map frame: errors are frame-free.
  for (fw::Se2d& p : odom) p = fw::Se2d(3, -2, 1.0).compose(p);
  const OdometryErrorSummary s = summarize(odometry_windows(odom, ref, WindowOptions{}));
  ASSERT_GT(s.windows, 100u);
  EXPECT_LT(s.trans_p95, 1e-9);
  EXPECT_LT(s.head_deg_per_m_p95, 1e-9);
  EXPECT_TRUE(odometry_windows({}, {}, WindowOptions{}).empty());
}

TEST(OdometryWindows, GapsInTheReferenceAreDropped) {
  std::vector<fw::Se2d> odom = {fw::Se2d(), fw::Se2d(0.5, 0, 0), fw::Se2d(10, 0, 0)};
  const std::vector<OdometryWindow> w = odometry_windows(odom, odom, WindowOptions{});
  EXPECT_TRUE(w.empty());  // 10 m > 2 × 1 m: a gap, not a window
}

TEST(ScanResiduals, DistanceToTheNearestOccupiedCell) {
  OccupancyGrid grid;
  grid.geometry.resolution = 0.1f;
  grid.geometry.width = 40;
  grid.geometry.height = 40;
  grid.cells.assign(1600, 0);
  for (int y = 0; y < 40; ++y) grid.cells[static_cast<std::size_t>(y) * 40 + 30] = 100;  // wall at x = 3.05
  const MapDistance d(grid);
  EXPECT_EQ(d.occupied_cells(), 40u);
  EXPECT_NEAR(d.at(1.05, 2.0), 2.0, 1e-5);
  EXPECT_NEAR(d.at(1.10, 2.0), 1.95, 1e-5);   // between cell centres: interpolated
  EXPECT_NEAR(d.at(-0.95, 2.05), 4.0, 1e-5);  // off the grid: border + distance
  // A scan at (0.5, 2), facing +x, three beams: on the wall, 0.4 m short of it, no return.
  const float ranges[3] = {2.55f, 2.15f, 8.0f};
  ResidualSample s;
  s.add_scan(d, fw::Se2d(0.5, 2.0, 0.0), 0.0f, 0.0f, 0.0f, 8.0f, ranges, 3, ResidualOptions{});
  const ResidualSummary r = summarize(s, ResidualOptions{});
  EXPECT_EQ(r.points, 2u);
  EXPECT_NEAR(r.beyond, 0.5, 1e-9);
  EXPECT_NEAR(r.p50, 0.2, 1e-5);
  EXPECT_NEAR(r.histogram.front(), 0.5, 1e-9);
}

TEST(Verdicts, ResemblanceIsMutualAndNamesTheMisfits) {
  OdometryErrorSummary log, near, far;
  log.trans_p10 = 0.01; log.trans_p50 = 0.02; log.trans_p90 = 0.05;
  log.head_deg_per_m_p10 = 0.2; log.head_deg_per_m_p50 = 0.5; log.head_deg_per_m_p90 = 1.5;
  near = log;
  near.trans_p50 = 0.03;
  far = log;
  far.trans_p10 = 0.2; far.trans_p50 = 0.4; far.trans_p90 = 0.9;
  EXPECT_TRUE(odometry_resembles(near, log));
  EXPECT_FALSE(odometry_resembles(far, log));
  GroundReport r;
  auto measure = [](const std::string& name, bool is_log, const OdometryErrorSummary& s) {
    OdometryMeasure m;
    m.name = name;
    m.is_log = is_log;
    m.measured = true;
    m.short_w = m.long_w = s;
    return m;
  };
  r.odometry = {measure("intel", true, log), measure("near", false, near), measure("far", false, far)};
  add_verdicts(&r);
  ASSERT_EQ(r.verdicts.size(), 2u);
  EXPECT_EQ(r.verdicts[0].resembles, std::vector<std::string>{"intel"});
  EXPECT_TRUE(r.verdicts[1].resembles.empty());
  EXPECT_NE(markdown(r).find("**far**: **no real log resembles it**"), std::string::npos);
}

}  // namespace
}  // namespace sim::ground

namespace sim::ground {
namespace {

TEST(ReferenceNoise, DerivedFromTheReferenceAtRest) {
  OdometryMeasure fr079;
  fr079.rest_pairs = 100;
  fr079.rest_m_p95 = 2.4477 * std::sqrt(2.0) * 0.02;
  fr079.rest_deg_p95 = 1.96 * std::sqrt(2.0) * 0.5;
  double m = 0, deg = 0;
  rest_noise_from(fr079, &m, &deg);
  EXPECT_NEAR(m, 0.02, 1e-9);
  EXPECT_NEAR(deg, 0.5, 1e-9);
  fr079.rest_pairs = 3;  // too few pairs: no figure
  rest_noise_from(fr079, &m, &deg);
  EXPECT_EQ(m, 0.0);
}

}  // namespace
}  // namespace sim::ground
