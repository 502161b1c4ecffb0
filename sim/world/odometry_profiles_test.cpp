// Odometry profiles and the odometry model's issue-55 wheel errors: profiles validate and state
// tracker keys, the white model's draws are untouched, every new term has its configured statistics.
#include "sim/world/odometry_profiles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <vector>

namespace sim {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Drives a sequence of scan steps, each sampled `k` times, and returns per step the error of the
// reported increment against the true one: (along, lateral, heading) and the true increment.
struct StepError {
  fw::Se2d truth, reported;
};

std::vector<StepError> drive(const OdometryNoiseOptions& opt, std::uint64_t seed, const std::vector<fw::Se2d>& steps,
                             int k, OdometrySimulator* sim_out = nullptr) {
  OdometrySimulator sim(opt, seed);
  fw::Se2d truth(1, 2, 0.3);
  std::uint64_t t = 1000;
  hal::Odometry o = sim.start(truth, t);
  std::vector<StepError> out;
  for (const fw::Se2d& step : steps) {
    const fw::Se2d odom0d = sim.odom_pose();
    const fw::Se2d truth0 = truth;
    for (int j = 1; j <= k; ++j) {
      const double f = static_cast<double>(j) / k;
      const fw::Se2d part(step.x * f, step.y * f, step.theta * f);
      t += 100'000'000 / k;
      o = sim.next(truth0.compose(part), t, 1.0 / k);
    }
    truth = truth0.compose(step);
    out.push_back({truth0.between(truth), odom0d.between(sim.odom_pose())});
  }
  if (sim_out != nullptr) *sim_out = sim;
  return out;
}

std::vector<fw::Se2d> straight(int n, double m) { return std::vector<fw::Se2d>(n, fw::Se2d(m, 0, 0)); }
std::vector<fw::Se2d> spins(int n, double rad) { return std::vector<fw::Se2d>(n, fw::Se2d(0, 0, rad)); }

double sd(const std::vector<double>& v) {
  double s = 0, s2 = 0;
  for (double x : v) s += x, s2 += x * x;
  const double m = s / v.size();
  return std::sqrt(s2 / v.size() - m * m);
}
double mean(const std::vector<double>& v) {
  double s = 0;
  for (double x : v) s += x;
  return s / v.size();
}

OdometryNoiseOptions quiet() {
  OdometryNoiseOptions o;
  o.sigma_trans = 0;
  o.sigma_rot_deg = 0;
  return o;
}

TEST(OdometryProfiles, EveryProfileValidatesAndStatesTrackerKeys) {
  const char* names[] = {"diff-calibrated", "diff-poor", "skid-steer", "slip-events", "white", "turn-spin"};
  ASSERT_EQ(odometry_profiles().size(), 6u);
  for (const char* n : names) {
    const OdometryProfile* p = find_odometry_profile(n);
    ASSERT_NE(p, nullptr) << n;
    EXPECT_EQ(p->wheels.validate(), "") << n;
    EXPECT_FALSE(p->description.empty());
    double a[4], m, deg;
    if (!p->tracker_odom_noise.empty()) {
      EXPECT_EQ(std::sscanf(p->tracker_odom_noise.c_str(), "%lf,%lf,%lf,%lf", &a[0], &a[1], &a[2], &a[3]), 4) << n;
      for (double x : a) EXPECT_TRUE(x >= 0 && x <= 10) << n;
    }
    ASSERT_EQ(std::sscanf(p->tracker_odom_noise_per_step.c_str(), "%lf,%lf", &m, &deg), 2) << n;
    EXPECT_TRUE(m >= 0 && m <= 1 && deg >= 0 && deg <= 28) << n;
  }
  const OdometryProfile& white = *find_odometry_profile("white");
  EXPECT_FALSE(white.wheels.wheel_errors());
  EXPECT_DOUBLE_EQ(white.wheels.sigma_trans, 0.04);
  EXPECT_DOUBLE_EQ(white.wheels.sigma_rot_deg, 4.0);
  EXPECT_EQ(white.tracker_odom_noise, "");
  EXPECT_EQ(white.tracker_odom_noise_per_step, "0,4");
  EXPECT_DOUBLE_EQ(find_odometry_profile("diff-poor")->wheels.scale_dist, 0.03);
  EXPECT_DOUBLE_EQ(find_odometry_profile("diff-poor")->wheels.scale_turn, -0.04);
  EXPECT_EQ(find_odometry_profile("tracked"), nullptr);
}

TEST(OdometryWheelErrors, ValidateNamesEveryNewField) {
  auto bad = [](auto set, const char* field) {
    OdometryNoiseOptions o;
    set(&o);
    EXPECT_NE(o.validate().find(field), std::string::npos) << field << ": " << o.validate();
  };
  bad([](OdometryNoiseOptions* o) { o->sigma_trans_per_m = -1; }, "sigma_trans_per_m");
  bad([](OdometryNoiseOptions* o) { o->sigma_rot_per_rad = NAN; }, "sigma_rot_per_rad");
  bad([](OdometryNoiseOptions* o) { o->sigma_rot_deg_per_m = 100; }, "sigma_rot_deg_per_m");
  bad([](OdometryNoiseOptions* o) { o->scale_dist = 0.9; }, "scale_dist");
  bad([](OdometryNoiseOptions* o) { o->scale_turn = -0.9; }, "scale_turn");
  bad([](OdometryNoiseOptions* o) { o->turn_slip_min = -0.1; }, "turn_slip_min");
  bad([](OdometryNoiseOptions* o) { o->turn_slip_min = 0.1, o->turn_slip_max = 0.05; }, "turn_slip_max");
  bad([](OdometryNoiseOptions* o) { o->sigma_lateral_per_m = -1; }, "sigma_lateral_per_m");
  bad([](OdometryNoiseOptions* o) { o->slip_events_per_100m = -1; }, "slip_events_per_100m");
  bad([](OdometryNoiseOptions* o) { o->slip_min_m = -1; }, "slip_min_m");
  bad([](OdometryNoiseOptions* o) { o->slip_max_m = 0.1; }, "slip_max_m");
  bad([](OdometryNoiseOptions* o) { o->turn_spin_events_per_rad = -1; }, "turn_spin_events_per_rad");
  bad([](OdometryNoiseOptions* o) { o->turn_spin_min_deg = NAN; }, "turn_spin_min_deg");
  bad([](OdometryNoiseOptions* o) { o->turn_spin_max_deg = 5; }, "turn_spin_max_deg");
  EXPECT_EQ(OdometryNoiseOptions().validate(), "");
}

// The white model before issue 55, verbatim (per sample): the defaults must give the same odometry.
TEST(OdometryWheelErrors, DefaultsAreBitIdenticalAndTheWhiteDrawsNeverMove) {
  const OdometryNoiseOptions opt;
  OdometrySimulator sim(opt, 17);
  fw::RandomStream ref_rng(17, 2);
  fw::Se2d truth(0, 0, 0), ref = opt.odom_origin;
  sim.start(truth, 0);
  for (int i = 1; i <= 200; ++i) {
    const fw::Se2d next = truth.compose(fw::Se2d(0.07, 0.001 * (i % 3), 0.05 * ((i / 10) % 3 - 1)));
    const hal::Odometry o = sim.next(next, i * 100'000'000ull, 0.25);
    const fw::Se2d u = truth.between(next);
    const double k = std::sqrt(0.25);
    const double nx = ref_rng.gaussian() * opt.sigma_trans * k;
    const double ny = ref_rng.gaussian() * opt.sigma_trans * k;
    const double nt = ref_rng.gaussian() * opt.sigma_rot_deg * M_PI / 180.0 * k;
    ref = ref.compose(fw::Se2d(u.x + nx, u.y + ny, fw::wrap_angle(u.theta + nt)));
    ASSERT_EQ(o.x, static_cast<float>(ref.x)) << i;
    ASSERT_EQ(o.y, static_cast<float>(ref.y)) << i;
    ASSERT_EQ(o.theta, static_cast<float>(ref.theta)) << i;
    truth = next;
  }
  // Wheel errors on (a turn scale on a straight drive changes nothing there): the white draws stay.
  OdometryNoiseOptions with = opt;
  with.scale_turn = 0.1;
  with.slip_events_per_100m = 0.001;
  const auto a = drive(opt, 4, straight(50, 0.3), 4), b = drive(with, 4, straight(50, 0.3), 4);
  for (size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].reported.x, b[i].reported.x);
    EXPECT_EQ(a[i].reported.theta, b[i].reported.theta);
  }
}

TEST(OdometryWheelErrors, SameSeedSameOdometryForEveryProfile) {
  std::vector<fw::Se2d> path = straight(30, 0.3);
  const auto turns = spins(10, 0.4);
  path.insert(path.end(), turns.begin(), turns.end());
  path.insert(path.end(), path.begin(), path.begin() + 30);
  for (const OdometryProfile& p : odometry_profiles()) {
    const auto a = drive(p.wheels, 9, path, 4), b = drive(p.wheels, 9, path, 4), c = drive(p.wheels, 10, path, 4);
    bool differs = false;
    for (size_t i = 0; i < a.size(); ++i) {
      ASSERT_EQ(a[i].reported.x, b[i].reported.x) << p.name;
      ASSERT_EQ(a[i].reported.theta, b[i].reported.theta) << p.name;
      differs |= a[i].reported.x != c[i].reported.x;
    }
    EXPECT_TRUE(differs) << p.name;
  }
}

// Proportional noise per scan step, whatever the odometry rate: σ_trans = a·|Δs|, σ_rot = b·|Δθ| +
// c·|Δs|, each within 10 %.
TEST(OdometryWheelErrors, ProportionalNoiseHasItsSigmaPerScanStep) {
  OdometryNoiseOptions opt = quiet();
  opt.sigma_trans_per_m = 0.02;
  opt.sigma_rot_deg_per_m = 1.0;
  opt.sigma_rot_per_rad = 0.05;
  for (int k : {1, 4}) {
    const auto drv = drive(opt, 3, straight(4000, 0.3), k);
    std::vector<double> ex, et;
    for (const StepError& e : drv) {
      ex.push_back(e.reported.x - e.truth.x);
      et.push_back(e.reported.theta - e.truth.theta);
    }
    EXPECT_NEAR(sd(ex), 0.02 * 0.3, 0.1 * 0.006) << k;
    EXPECT_NEAR(sd(et), 1.0 * kDeg * 0.3, 0.1 * 0.3 * kDeg) << k;
    EXPECT_NEAR(mean(ex), 0, 0.0003);
    const auto spn = drive(opt, 5, spins(4000, 0.5), k);
    std::vector<double> er;
    for (const StepError& e : spn) er.push_back(fw::wrap_angle(e.reported.theta - e.truth.theta));
    EXPECT_NEAR(sd(er), 0.05 * 0.5, 0.1 * 0.025) << k;
    EXPECT_NEAR(std::hypot(spn[7].reported.x, spn[7].reported.y), 0.0, 1e-12);  // a spin does not move
  }
}

TEST(OdometryWheelErrors, SystematicScalesAreExact) {
  OdometryNoiseOptions opt = quiet();
  opt.scale_dist = 0.03;
  opt.scale_turn = -0.04;
  const auto drv = drive(opt, 1, straight(100, 0.3), 4);
  for (const StepError& e : drv) EXPECT_NEAR(e.reported.x / e.truth.x, 1.03, 1e-9);
  const auto spn = drive(opt, 1, spins(100, 0.5), 4);
  for (const StepError& e : spn) EXPECT_NEAR(e.reported.theta / e.truth.theta, 0.96, 1e-9);
  // The diff-poor profile: mean scale errors +3 % and −4 % under its noise.
  const OdometryNoiseOptions& poor = find_odometry_profile("diff-poor")->wheels;
  std::vector<double> sd_, st;
  for (const StepError& e : drive(poor, 2, straight(3000, 0.3), 4)) sd_.push_back(e.reported.x / e.truth.x - 1);
  for (const StepError& e : drive(poor, 2, spins(3000, 0.5), 4)) st.push_back(e.reported.theta / e.truth.theta - 1);
  EXPECT_NEAR(mean(sd_), 0.03, 0.001);
  EXPECT_NEAR(mean(st), -0.04, 0.002);
}

// Skid-steer: per turn (a run of turning samples) the base turns (1 − s) × what the wheels report,
// s uniform in [turn_slip_min, turn_slip_max]; lateral slide σ per metre.
TEST(OdometryWheelErrors, SkidSteerSlipsEveryTurnAndSlidesSideways) {
  OdometryNoiseOptions opt = quiet();
  opt.turn_slip_min = 0.05;
  opt.turn_slip_max = 0.10;
  std::vector<fw::Se2d> path;
  for (int i = 0; i < 2000; ++i) {
    path.push_back(fw::Se2d(0, 0, i % 2 ? 0.6 : -0.6));  // one turn over one scan step...
    path.push_back(fw::Se2d(0.3, 0, 0));                  // ...then a drive ends it
  }
  std::vector<double> s;
  for (const StepError& e : drive(opt, 6, path, 4)) {
    if (e.truth.theta != 0) s.push_back(1 - e.truth.theta / e.reported.theta);
  }
  ASSERT_EQ(s.size(), 2000u);
  for (double x : s) EXPECT_TRUE(x >= 0.05 - 1e-12 && x <= 0.10 + 1e-12) << x;
  EXPECT_NEAR(mean(s), 0.075, 0.1 * 0.025);
  EXPECT_NEAR(sd(s), 0.05 / std::sqrt(12.0), 0.1 * 0.05 / std::sqrt(12.0));
  opt = quiet();
  opt.sigma_lateral_per_m = 0.02;
  std::vector<double> ey;
  for (const StepError& e : drive(opt, 7, straight(4000, 0.3), 4)) ey.push_back(e.reported.y - e.truth.y);
  EXPECT_NEAR(sd(ey), 0.02 * 0.3, 0.1 * 0.006);
  // The skid-steer profile's turns slip 5–10 %.
  const OdometryNoiseOptions& skid = find_odometry_profile("skid-steer")->wheels;
  s.clear();
  for (const StepError& e : drive(skid, 8, path, 4)) {
    if (e.truth.theta != 0) s.push_back(1 - e.truth.theta / e.reported.theta);
  }
  EXPECT_NEAR(mean(s), 0.075, 0.01);
}

// Wheel-slip events: rate per 100 m, each 0.3–1 m of forward motion that did not happen, at once.
TEST(OdometryWheelErrors, SlipEventsHaveTheirRateAndSize) {
  OdometryNoiseOptions opt = quiet();
  opt.slip_events_per_100m = 2.0;
  OdometrySimulator sim(opt, 1);
  // One sample per step (two events never share a step): 30 km, 600 events expected.
  const auto drv = drive(opt, 12, straight(100000, 0.3), 1, &sim);
  std::vector<double> sizes;
  for (const StepError& e : drv) {
    const double extra = e.reported.x - e.truth.x;
    if (extra > 1e-9) sizes.push_back(extra);
    EXPECT_GE(extra, -1e-9);
  }
  EXPECT_EQ(static_cast<int>(sizes.size()), sim.slip_events());
  EXPECT_NEAR(sizes.size(), 600.0, 60.0);  // Poisson sd 24.5
  for (double x : sizes) EXPECT_TRUE(x >= 0.3 - 1e-9 && x <= 1.0 + 1e-9) << x;
  EXPECT_NEAR(mean(sizes), 0.65, 0.065);
  // Standing still or spinning: no slip.
  OdometrySimulator still(opt, 1);
  drive(opt, 13, spins(10000, 0.5), 4, &still);
  EXPECT_EQ(still.slip_events(), 0);
}

// Turn-spin events (issue 56): at 0.25 per radian turned, 8–20° more than the base turned, in the
// turn's direction; a straight drive has none.
TEST(OdometryWheelErrors, TurnSpinEventsOverReportTurnsAtTheirRate) {
  OdometryNoiseOptions opt = quiet();
  opt.turn_spin_events_per_rad = 0.25;
  OdometrySimulator sim(opt, 1);
  // 0.2 rad per step, one sample: 20,000 steps = 4,000 rad turned, 1,000 events expected.
  const auto drv = drive(opt, 14, spins(20000, 0.2), 1, &sim);
  std::vector<double> sizes;
  for (const StepError& e : drv) {
    const double extra = fw::wrap_angle(e.reported.theta - e.truth.theta) / kDeg;
    if (std::fabs(extra) > 1e-6) sizes.push_back(extra);
  }
  EXPECT_EQ(static_cast<int>(sizes.size()), sim.turn_spin_events());
  EXPECT_NEAR(sizes.size(), 1000.0, 100.0);  // Poisson sd 31.6
  for (double x : sizes) EXPECT_TRUE(x >= 8.0 - 1e-6 && x <= 20.0 + 1e-6) << x;
  EXPECT_NEAR(mean(sizes), 14.0, 0.5);
  OdometrySimulator straight_on(opt, 1);
  drive(opt, 15, straight(10000, 0.3), 4, &straight_on);
  EXPECT_EQ(straight_on.turn_spin_events(), 0);
  // The profile: the calibrated wheels plus the events, declared by no key.
  const OdometryProfile& p = *find_odometry_profile("turn-spin");
  EXPECT_DOUBLE_EQ(p.wheels.turn_spin_events_per_rad, 0.25);
  EXPECT_EQ(p.tracker_odom_slip, "");
}

}  // namespace
}  // namespace sim
