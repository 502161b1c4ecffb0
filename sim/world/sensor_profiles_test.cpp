// Sensor profiles and the laser model's issue-55 extensions: profiles against their data sheets,
// default scans bit for bit as before, each new noise term's statistics, glass, 360° scans and the
// resampling of irregular angles.
#include "sim/world/sensor_profiles.h"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

#include "sim/world/ray_cast.h"
#include "sim/world/synthetic_run.h"
#include "sim/world/builtin_worlds.h"

namespace sim {
namespace {

World room(double w, double h) {
  World r;
  r.name = "room";
  r.bounds = {Vec2(0, 0), Vec2(w, h)};
  add_rect(&r, 0, 0, w, h);
  return r;
}

// The laser model before issue 55, verbatim: the default options must give the same scans.
void reference_scan(const World& world, const fw::Se2d& sensor_pose, double t_s, const LaserModelOptions& opt,
                    fw::RandomStream* rng, hal::LaserScan* out) {
  const double fov = opt.fov_deg * M_PI / 180.0;
  const double inc = opt.beams > 1 ? fov / (opt.beams - 1) : 0.0;
  out->beam_count = static_cast<std::uint32_t>(opt.beams);
  out->angle_min = static_cast<float>(-fov / 2);
  out->angle_increment = static_cast<float>(inc);
  const Vec2 origin(sensor_pose.x, sensor_pose.y);
  for (int i = 0; i < opt.beams; ++i) {
    const double a = sensor_pose.theta - fov / 2 + i * inc;
    const RayHit h = cast_ray(world, origin, a, opt.max_range, t_s, opt.people_visible);
    const double noise = rng->gaussian() * opt.sigma_range;
    const bool drop = rng->uniform01() < opt.dropout_rate;
    double r = opt.max_range;
    if (h.hit && !drop) {
      r = h.range + noise;
      if (r >= opt.max_range) r = opt.max_range - 1e-3;
      if (r < opt.min_range) r = opt.min_range;
    }
    out->ranges[i] = static_cast<float>(r);
  }
}

TEST(SensorProfiles, EveryProfileValidatesAndFollowsItsDataSheet) {
  struct Sheet {
    const char* name;
    int beams;
    double fov, step_deg, max_range, rate;
  };
  const Sheet sheets[] = {{"lms200", 361, 180, 0.5, 81.91, 37.5},
                          {"utm30lx", 1081, 270, 0.25, 30, 40},
                          {"tim571", 811, 270, 1.0 / 3.0, 25, 15},
                          {"rplidar-a1", 360, 360, 1.0, 12, 5.5}};
  ASSERT_EQ(sensor_profiles().size(), 4u);
  for (const Sheet& s : sheets) {
    const SensorProfile* p = find_sensor_profile(s.name);
    ASSERT_NE(p, nullptr) << s.name;
    EXPECT_EQ(p->laser.validate(), "") << s.name;
    EXPECT_FALSE(p->source.empty());
    EXPECT_EQ(p->laser.beams, s.beams) << s.name;
    EXPECT_LE(p->laser.beams, static_cast<int>(hal::LaserScan::kMaxBeams));
    EXPECT_DOUBLE_EQ(p->laser.fov_deg, s.fov) << s.name;
    EXPECT_NEAR(p->laser.angle_increment() * 180.0 / M_PI, s.step_deg, 1e-9) << s.name;
    EXPECT_DOUBLE_EQ(p->laser.max_range, s.max_range) << s.name;
    EXPECT_DOUBLE_EQ(p->rate_hz, s.rate) << s.name;
  }
  EXPECT_TRUE(find_sensor_profile("rplidar-a1")->laser.irregular_angles());
  EXPECT_FALSE(find_sensor_profile("lms200")->laser.irregular_angles());
  EXPECT_EQ(find_sensor_profile("velodyne"), nullptr);
}

TEST(LaserExtensions, ValidateNamesEveryNewField) {
  const LaserModelOptions ok;
  auto bad = [&](auto set, const char* field) {
    LaserModelOptions o = ok;
    set(&o);
    EXPECT_NE(o.validate().find(field), std::string::npos) << field << ": " << o.validate();
  };
  bad([](LaserModelOptions* o) { o->sigma_range_per_m = -0.1; }, "sigma_range_per_m");
  bad([](LaserModelOptions* o) { o->range_quantum_m = NAN; }, "range_quantum_m");
  bad([](LaserModelOptions* o) { o->glass_return_probability = 1.5; }, "glass_return_probability");
  bad([](LaserModelOptions* o) { o->far_dropout_from = -1; }, "far_dropout_from");
  bad([](LaserModelOptions* o) { o->far_dropout_max = 2; }, "far_dropout_max");
  bad([](LaserModelOptions* o) { o->far_dropout_max = 0.5; }, "far_dropout_from");  // from = 1 with a ramp
  bad([](LaserModelOptions* o) { o->angle_jitter_deg = -1; }, "angle_jitter_deg");
  EXPECT_EQ(ok.validate(), "");
}

// Default options (and the extensions at their defaults) give the scans of the model before issue
// 55 bit for bit, and the extensions never move the per-beam stream.
TEST(LaserExtensions, DefaultsAreBitIdenticalAndTheBeamStreamNeverMoves) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("small-office", &w, &err)) << err;
  LaserModelOptions opt;
  for (int k = 0; k < 2; ++k) {
    if (k == 1) {  // the bench's other setting
      opt.beams = 181;
      opt.max_range = 80;
      opt.dropout_rate = 0.05;
    }
    fw::RandomStream a(11, 3), b(11, 3);
    hal::LaserScan sa, sb;
    for (int s = 0; s < 20; ++s) {
      const fw::Se2d pose(3 + 0.5 * s, 6, 0.1 * s);
      simulate_scan(w, pose, 0.1 * s, opt, &a, &sa);
      reference_scan(w, pose, 0.1 * s, opt, &b, &sb);
      ASSERT_EQ(sa.beam_count, sb.beam_count);
      EXPECT_EQ(sa.angle_increment, sb.angle_increment);
      for (std::uint32_t i = 0; i < sa.beam_count; ++i) ASSERT_EQ(sa.ranges[i], sb.ranges[i]) << s << " " << i;
    }
  }
  // Every extension on: the per-beam stream advances exactly as without them.
  LaserModelOptions all = find_sensor_profile("rplidar-a1")->laser;
  all.far_dropout_from = 0.3;
  all.far_dropout_max = 0.5;
  LaserModelOptions none = all;
  none.glass_return_probability = 1;
  none.far_dropout_max = 0;
  none.angle_jitter_deg = 0;
  none.revolution_offset = false;
  fw::RandomStream a(5, 3), b(5, 3), extra(5, 7);
  hal::LaserScan sa, sb;
  simulate_scan(w, fw::Se2d(4, 6, 0), 0, all, &a, &sa, &extra);
  simulate_scan(w, fw::Se2d(4, 6, 0), 0, none, &b, &sb);
  EXPECT_EQ(a.next_u32(), b.next_u32());
  simulate_scan(w, fw::Se2d(4, 6, 0), 0, all, &a, &sa);  // no extra stream: seeded from a copy
  simulate_scan(w, fw::Se2d(4, 6, 0), 0, none, &b, &sb);
  EXPECT_EQ(a.next_u32(), b.next_u32());
}

TEST(LaserExtensions, SameSeedSameScansForEveryProfile) {
  World w;
  std::string err;
  ASSERT_TRUE(make_builtin_world("small-office", &w, &err)) << err;
  for (const SensorProfile& p : sensor_profiles()) {
    SyntheticRunOptions opt;
    opt.seed = 21;
    opt.laser = p.laser;
    opt.max_scans = 15;
    SyntheticRun r1, r2, r3;
    ASSERT_TRUE(r1.init(w, opt, &err)) << err;
    ASSERT_TRUE(r2.init(w, opt, &err));
    opt.seed = 22;
    ASSERT_TRUE(r3.init(w, opt, &err));
    SyntheticFrame f1, f2, f3;
    std::size_t differ = 0;
    while (r1.next(&f1)) {
      ASSERT_TRUE(r2.next(&f2));
      ASSERT_TRUE(r3.next(&f3));
      ASSERT_EQ(f1.scan.beam_count, static_cast<std::uint32_t>(p.laser.beams));
      for (std::uint32_t i = 0; i < f1.scan.beam_count; ++i) {
        ASSERT_EQ(f1.scan.ranges[i], f2.scan.ranges[i]) << p.name;
        differ += f1.scan.ranges[i] != f3.scan.ranges[i];
      }
    }
    EXPECT_GT(differ, 0u) << p.name;
  }
}

// σ = sigma_range + sigma_range_per_m · r: the errors divided by their σ have unit deviation.
TEST(LaserExtensions, RangeProportionalNoiseHasItsSigma) {
  const World w = room(40, 40);
  LaserModelOptions opt;
  opt.max_range = 60;
  opt.dropout_rate = 0;
  opt.sigma_range = 0.002;
  opt.sigma_range_per_m = 0.01;
  fw::RandomStream rng(3, 3);
  hal::LaserScan scan;
  const fw::Se2d pose(3, 5, 0);
  double s1 = 0, s2 = 0, near2 = 0, far2 = 0;
  std::size_t n = 0, n_near = 0, n_far = 0;
  for (int k = 0; k < 100; ++k) {
    simulate_scan(w, pose, 0, opt, &rng, &scan);
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      const double a = pose.theta + scan.angle_min + i * static_cast<double>(scan.angle_increment);
      const double truth = cast_ray(w, Vec2(pose.x, pose.y), a, 60, 0).range;
      const double e = scan.ranges[i] - truth;
      const double z = e / (opt.sigma_range + opt.sigma_range_per_m * truth);
      s1 += z;
      s2 += z * z;
      ++n;
      if (truth < 10) near2 += e * e, ++n_near;
      if (truth > 30) far2 += e * e, ++n_far;
    }
  }
  EXPECT_NEAR(s1 / n, 0.0, 0.01);
  EXPECT_NEAR(std::sqrt(s2 / n), 1.0, 0.02);
  ASSERT_GT(n_near, 1000u);
  ASSERT_GT(n_far, 1000u);
  EXPECT_GT(std::sqrt(far2 / n_far), 3 * std::sqrt(near2 / n_near));  // it grows with the range
}

TEST(LaserExtensions, EchoesAreOnTheSensorsRangeGrid) {
  const World w = room(40, 40);
  for (const SensorProfile& p : sensor_profiles()) {
    fw::RandomStream rng(4, 3), extra(4, 7);
    hal::LaserScan scan;
    simulate_scan(w, fw::Se2d(7, 19, 0.4), 0, p.laser, &rng, &scan, &extra);
    const double q = p.laser.range_quantum_m;
    ASSERT_GT(q, 0) << p.name;
    std::size_t echoes = 0;
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      if (scan.ranges[i] >= scan.range_max) continue;
      ++echoes;
      const double steps = scan.ranges[i] / q;
      EXPECT_NEAR(steps, std::round(steps), 2e-3 * std::max(1.0, steps * 1e-4)) << p.name << " " << scan.ranges[i];
    }
    EXPECT_GT(echoes, scan.beam_count / 8) << p.name;
  }
}

// Beyond far_dropout_from × max_range a hit is lost with a probability rising linearly to
// far_dropout_max at max_range: TiM571 (8 m at 10 %, 25 m) at 16.5 m loses half.
TEST(LaserExtensions, FarDropoutFollowsItsRamp) {
  World w;
  add_segment(&w, 16.5, -50, 16.5, 50);
  add_segment(&w, -5, -50, -5, 50);  // 5 m behind: below the ramp, never lost
  LaserModelOptions opt = find_sensor_profile("tim571")->laser;
  opt.dropout_rate = 0;
  opt.fov_deg = 1;
  opt.beams = 2;
  fw::RandomStream rng(8, 3), extra(8, 7);
  hal::LaserScan scan;
  std::size_t lost = 0, n = 0;
  for (int k = 0; k < 10000; ++k) {
    simulate_scan(w, fw::Se2d(0, 0, 0), 0, opt, &rng, &scan, &extra);
    for (int i = 0; i < 2; ++i) lost += scan.ranges[i] >= scan.range_max, ++n;
  }
  EXPECT_NEAR(static_cast<double>(lost) / n, (16.5 - 8.0) / (25.0 - 8.0), 0.015);  // binomial sd 0.0035
  lost = 0;
  for (int k = 0; k < 1000; ++k) {
    simulate_scan(w, fw::Se2d(0, 0, M_PI), 0, opt, &rng, &scan, &extra);
    for (int i = 0; i < 2; ++i) lost += scan.ranges[i] >= scan.range_max;
  }
  EXPECT_EQ(lost, 0u);
}

// A pane 2 m ahead of a wall at 5 m. Needs cast_ray's glass support (RayHit::glass, behind_*).
TEST(LaserExtensions, GlassReturnsFromThePaneOrFromBehind) {
  World w;
  w.name = "glass";
  add_segment(&w, 5, -10, 5, 10);
  w.glass.push_back({Vec2(2, -10), Vec2(2, 10)});
  w.glass.push_back({Vec2(-2, -10), Vec2(-2, 10)});  // behind the sensor: a pane with nothing behind
  const RayHit h = cast_ray(w, Vec2(0, 0), 0.0, 20, 0);
  ASSERT_TRUE(h.hit);
  ASSERT_TRUE(h.glass) << "cast_ray does not report glass yet (ray_cast.cpp)";
  LaserModelOptions opt;
  opt.max_range = 20;
  opt.sigma_range = 0;
  opt.dropout_rate = 0;
  opt.fov_deg = 20;
  opt.beams = 21;
  auto count = [&](double p, double heading, std::size_t* pane, std::size_t* behind, std::size_t* none) {
    opt.glass_return_probability = p;
    fw::RandomStream rng(2, 3), extra(2, 7);
    hal::LaserScan scan;
    *pane = *behind = *none = 0;
    for (int k = 0; k < 200; ++k) {
      simulate_scan(w, fw::Se2d(0, 0, heading), 0, opt, &rng, &scan, &extra);
      for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
        const double a = scan.angle_min + i * static_cast<double>(scan.angle_increment);
        const double x = scan.ranges[i] * std::cos(a);
        if (scan.ranges[i] >= scan.range_max) {
          ++*none;
        } else if (std::fabs(x - 2) < 1e-4) {
          ++*pane;
        } else {
          EXPECT_NEAR(x, 5, 1e-4);
          ++*behind;
        }
      }
    }
  };
  std::size_t pane, behind, none;
  count(1.0, 0, &pane, &behind, &none);  // the default: glass is a wall
  EXPECT_EQ(pane, 4200u);
  count(0.0, 0, &pane, &behind, &none);
  EXPECT_EQ(behind, 4200u);
  count(0.3, 0, &pane, &behind, &none);
  EXPECT_NEAR(pane / 4200.0, 0.3, 0.03);  // binomial sd 0.007
  EXPECT_EQ(pane + behind, 4200u);
  count(0.0, M_PI, &pane, &behind, &none);  // nothing behind the pane: no return
  EXPECT_EQ(none, 4200u);
}

TEST(LaserExtensions, FullTurnHasNoBeamTwice) {
  const World w = room(10, 10);
  LaserModelOptions opt;
  opt.fov_deg = 360;
  opt.beams = 720;
  opt.sigma_range = 0;
  opt.dropout_rate = 0;
  opt.max_range = 20;
  ASSERT_EQ(opt.validate(), "");
  EXPECT_NEAR(opt.angle_increment(), 2 * M_PI / 720, 1e-15);
  fw::RandomStream rng(1, 3);
  hal::LaserScan scan;
  const fw::Se2d pose(3, 4, 0.3);
  simulate_scan(w, pose, 0, opt, &rng, &scan);
  EXPECT_NEAR(scan.angle_min, -M_PI, 1e-6);
  std::set<long> seen;
  for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
    const double a = scan.angle_min + i * static_cast<double>(scan.angle_increment);
    const long key = std::lround(std::remainder(a, 2 * M_PI) / opt.angle_increment());
    EXPECT_TRUE(seen.insert(((key % 720) + 720) % 720).second) << "beam " << i << " repeats an angle";
    EXPECT_NEAR(scan.ranges[i], cast_ray(w, Vec2(3, 4), pose.theta + a, 20, 0).range, 1e-4) << i;
  }
  EXPECT_EQ(seen.size(), 720u);
  // The last beam is one step short of the first, not on it.
  EXPECT_NEAR(scan.angle_min + 719 * static_cast<double>(scan.angle_increment), M_PI - opt.angle_increment(), 1e-5);
}

// RPLIDAR: measured at irregular angles, resampled onto the 1° grid. Every reading a slot reports
// was measured within half a step of the slot's angle: its range lies among the true ranges over
// [a − step/2, a + step/2] (a convex room: range is continuous in the angle).
TEST(LaserExtensions, IrregularAnglesResampleWithinHalfAStep) {
  const World w = room(10, 6);
  LaserModelOptions opt = find_sensor_profile("rplidar-a1")->laser;
  opt.sigma_range = 0;
  opt.sigma_range_per_m = 0;
  opt.range_quantum_m = 0;
  opt.dropout_rate = 0;
  const double step = opt.angle_increment();
  const fw::Se2d pose(2, 1.5, 0.2);
  auto within_half_step = [&](const hal::LaserScan& scan, std::uint32_t i, double half) {
    const double a = pose.theta + scan.angle_min + i * static_cast<double>(scan.angle_increment);
    double lo = 1e9, hi = 0;
    for (int k = -40; k <= 40; ++k) {
      const double r = cast_ray(w, Vec2(pose.x, pose.y), a + k / 40.0 * half, 20, 0).range;
      lo = std::min(lo, r);
      hi = std::max(hi, r);
    }
    return scan.ranges[i] >= lo - 1e-4 && scan.ranges[i] <= hi + 1e-4;
  };
  fw::RandomStream rng(6, 3), extra(6, 7);
  hal::LaserScan scan;
  std::size_t empty = 0, wrong = 0, off_by_more = 0, total = 0;
  for (int k = 0; k < 50; ++k) {
    simulate_scan(w, pose, 0, opt, &rng, &scan, &extra);
    ASSERT_EQ(scan.beam_count, 360u);
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      ++total;
      if (scan.ranges[i] >= scan.range_max) {
        ++empty;
        continue;
      }
      wrong += !within_half_step(scan, i, step / 2);
      off_by_more += !within_half_step(scan, i, step / 20);  // not all at the nominal angle
    }
  }
  EXPECT_EQ(wrong, 0u);
  EXPECT_GT(off_by_more, total / 4);  // the angles are irregular indeed
  EXPECT_GT(empty, 0u);  // jitter leaves slots empty (two beams in one slot): about 11 % at 0.2°
  EXPECT_LT(empty, total / 5);
  // A per-revolution offset alone: one measurement per slot, none empty.
  opt.angle_jitter_deg = 0;
  for (int k = 0; k < 10; ++k) {
    simulate_scan(w, pose, 0, opt, &rng, &scan, &extra);
    for (std::uint32_t i = 0; i < scan.beam_count; ++i) {
      ASSERT_LT(scan.ranges[i], scan.range_max) << i;
      EXPECT_TRUE(within_half_step(scan, i, step / 2)) << i;
    }
  }
}

}  // namespace
}  // namespace sim
