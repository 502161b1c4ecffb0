// Unit tests of the relations reader and the Kümmerle et al. 2009 metric on synthetic data with
// known answers, and of the reference-trajectory interpolation on a synthetic drifting odometry.
#include "sim/io/relations.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <fstream>

#include "sim/io/reference_trajectory.h"
#include "sim/io/test_files.h"

namespace sim {
namespace {

using test_files::temp_path;
using test_files::write_text;

TEST(Relations, ReadsFileAndSkipsComments) {
  const std::string p = temp_path("rel", "ok.relations");
  write_text(p, "# c\n\n976052905.167303 976052911.885496 -0.056990 -0.128430 0.000000 0.000000 0.000000 -1.682210\n"
                "1 2 1 0 0 0 0 0.5\n");
  std::vector<Relation> r;
  std::string err;
  ASSERT_TRUE(read_relations(p, &r, &err)) << err;
  ASSERT_EQ(r.size(), 2u);
  EXPECT_DOUBLE_EQ(r[0].t1, 976052905.167303);
  EXPECT_DOUBLE_EQ(r[0].delta.y, -0.128430);
  EXPECT_DOUBLE_EQ(r[0].delta.theta, -1.682210);
  std::remove(p.c_str());
}

TEST(Relations, MalformedInputIsAnErrorNamingFileAndLine) {
  const struct {
    const char* name;
    const char* text;
    const char* expect;
  } cases[] = {
      {"truncated", "1 2 1 0 0 0 0 0.5\n1 2 1 0 0\n", "found 5"},
      {"non-numeric", "1 2 1 0 0 0 0 0.5\n1 2 x 0 0 0 0 0\n", "field x is not a finite number"},
      {"NaN", "1 2 1 0 0 0 0 0.5\n1 2 1 nan 0 0 0 0\n", "field y is not a finite number"},
      {"3D", "1 2 1 0 0 0 0 0.5\n1 2 1 0 0.5 0 0 0\n", "z, roll and pitch must be 0"},
      // Issue 13: finite but absurd values were accepted.
      {"t1 1e300", "1 2 1 0 0 0 0 0.5\n1e300 2 1 0 0 0 0 0\n", "field t1 is 1e300, outside the plausible ±1e+10 s"},
      {"x 1e300", "1 2 1 0 0 0 0 0.5\n1 2 1e300 0 0 0 0 0\n", "field x is 1e300, outside the plausible ±1e+06 m"},
      {"yaw 1e300", "1 2 1 0 0 0 0 0.5\n1 2 1 0 0 0 0 -1e300\n", "field yaw is -1e300"},
      {"many fields", "1 2 1 0 0 0 0 0.5\n1 2 1 0 0 0 0 0 0 0 0\n", "expected 8 fields (t1 t2 x y z roll pitch yaw), found more"},
  };
  for (const auto& c : cases) {
    SCOPED_TRACE(c.name);
    const std::string p = temp_path("rel", "bad.relations");
    write_text(p, c.text);
    std::vector<Relation> r;
    std::string err;
    EXPECT_FALSE(read_relations(p, &r, &err));
    EXPECT_NE(err.find(p + ":2: "), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << err;
    std::remove(p.c_str());
  }
  std::vector<Relation> r;
  std::string err;
  EXPECT_FALSE(read_relations("/nonexistent/x.relations", &r, &err));
  EXPECT_NE(err.find("/nonexistent/x.relations"), std::string::npos) << err;
}

TEST(Relations, MetricOfKnownErrors) {
  // Trajectory along x; relations claim 1 m steps, the trajectory has 1.1 m steps and a 2° extra turn
  // at every other step.
  Trajectory traj;
  fw::Se2d x;
  const double extra = 2.0 * M_PI / 180.0;
  for (int i = 0; i < 11; ++i) {
    traj.push_back({10.0 + i, x});
    x = x.compose(fw::Se2d(1.1, 0, (i % 2) ? extra : 0.0));
  }
  std::vector<Relation> rel;
  for (int i = 0; i < 10; ++i) rel.push_back({10.0 + i, 11.0 + i, fw::Se2d(1.0, 0, 0)});
  rel.push_back({100.0, 101.0, fw::Se2d(1.0, 0, 0)});  // not in the trajectory
  const RelationsMetric m = evaluate_relations(rel, traj);
  EXPECT_EQ(m.used, 10u);
  EXPECT_EQ(m.missing, 1u);
  EXPECT_NEAR(m.trans_mean, 0.1, 1e-12);
  EXPECT_NEAR(m.trans_std, 0.0, 1e-12);
  EXPECT_NEAR(m.trans2_mean, 0.01, 1e-12);
  EXPECT_NEAR(m.rot_mean_deg, 1.0, 1e-9);  // half the relations have 2°, half 0°
  EXPECT_NEAR(m.rot_std_deg, 1.0, 1e-9);
  EXPECT_NEAR(m.rot2_mean, 2.0, 1e-9);     // (4 + 0) / 2 deg²
  EXPECT_NEAR(m.rot2_std, 2.0, 1e-9);
  EXPECT_NEAR(m.rot_max_deg, 2.0, 1e-9);
}

TEST(Relations, SplitByRelationLength) {
  // Steps of 1 s along x with 1.1 m instead of 1 m: a relation over k steps is off by 0.1·k m.
  // Short ones (k = 1, 10: ≤ 10 s) and long ones (k = 11, 20) are scored separately; the overall
  // figure is the mean of all four.
  Trajectory traj;
  for (int i = 0; i <= 30; ++i) traj.push_back({100.0 + i, fw::Se2d(1.1 * i, 0, 0)});
  std::vector<Relation> rel;
  for (int k : {1, 10, 11, 20}) rel.push_back({100.0, 100.0 + k, fw::Se2d(1.0 * k, 0, 0)});
  const RelationsMetricSplit m = evaluate_relations_split(rel, traj, 10.0);
  EXPECT_EQ(m.short_rel.used, 2u);
  EXPECT_EQ(m.long_rel.used, 2u);
  EXPECT_EQ(m.all.used, 4u);
  EXPECT_NEAR(m.short_rel.trans_mean, (0.1 + 1.0) / 2, 1e-9);
  EXPECT_NEAR(m.long_rel.trans_mean, (1.1 + 2.0) / 2, 1e-9);
  EXPECT_NEAR(m.all.trans_mean, (0.1 + 1.0 + 1.1 + 2.0) / 4, 1e-9);
  // Reversed timestamps count by |t2 − t1|; a different split moves relations between the halves.
  rel.push_back({110.0, 100.0, fw::Se2d(-10.0, 0, 0)});
  EXPECT_EQ(evaluate_relations_split(rel, traj, 10.0).short_rel.used, 3u);
  EXPECT_EQ(evaluate_relations_split(rel, traj, 5.0).short_rel.used, 1u);
  const std::string text = to_string(evaluate_relations_split(rel, traj, 10.0));
  EXPECT_NE(text.find("short (<= 10 s): used 3"), std::string::npos) << text;
  EXPECT_NE(text.find("long (> 10 s): used 2"), std::string::npos) << text;
}

TEST(Relations, MetricIsFrameInvariantAndZeroOnOwnRelations) {
  // Relations derived from a trajectory score 0 on it, also after moving the whole trajectory
  // (the metric only sees relative motion) and after a write/read round trip.
  Trajectory traj;
  fw::Se2d x(3, -2, 0.3);
  for (int i = 0; i < 200; ++i) {
    traj.push_back({1000.123456 + 0.37 * i, x});
    x = x.compose(fw::Se2d(0.2 + 0.01 * std::sin(i), 0.02 * std::cos(i), 0.05 * std::sin(0.3 * i)));
  }
  std::vector<Relation> rel;
  for (int i = 0; i + 7 < 200; i += 7) rel.push_back({traj[i].t, traj[i + 7].t, traj[i].pose.between(traj[i + 7].pose)});
  const std::string p = temp_path("rel", "own.relations");
  std::string err;
  ASSERT_TRUE(write_relations(p, rel, &err)) << err;
  std::vector<Relation> back;
  ASSERT_TRUE(read_relations(p, &back, &err)) << err;
  std::remove(p.c_str());
  Trajectory moved = traj;
  const fw::Se2d g(-50, 20, 2.5);
  for (auto& tp : moved) tp.pose = g.compose(tp.pose);
  for (const Trajectory* t : {&traj, &moved}) {
    const RelationsMetric m = evaluate_relations(back, *t);
    EXPECT_EQ(m.used, rel.size());
    EXPECT_LT(m.trans_mean, 1e-9);
    EXPECT_LT(m.rot_mean_deg, 1e-7);
  }
  // Perturbing one pose gives errors on exactly the relations that touch it.
  Trajectory bad = traj;
  bad[21].pose.x += 0.5;
  const auto errs = relation_errors(back, bad);
  size_t nonzero = 0;
  for (const auto& e : errs) nonzero += e.trans > 1e-6;
  EXPECT_EQ(nonzero, 2u);  // i = 21 (start) and i = 14 (end)
}

TEST(Relations, LookupToleratesUnsortedAndDuplicateTimestamps) {
  Trajectory traj = {{5.0, fw::Se2d(5, 0, 0)}, {1.0, fw::Se2d(1, 0, 0)}, {3.0, fw::Se2d(3, 0, 0)},
                     {3.0, fw::Se2d(99, 0, 0)}, {2.00005, fw::Se2d(2, 0, 0)}};
  const std::vector<Relation> rel = {{1.0, 3.0, fw::Se2d(2, 0, 0)}, {2.0, 5.0, fw::Se2d(3, 0, 0)},
                                     {1.0, 4.0, fw::Se2d(3, 0, 0)}};
  const auto errs = relation_errors(rel, traj, 1e-4);
  EXPECT_NEAR(errs[0].trans, 0.0, 1e-12);  // first of the duplicates at t=3
  EXPECT_NEAR(errs[1].trans, 0.0, 1e-12);  // 2.0 matched 2.00005 within tolerance
  EXPECT_TRUE(std::isnan(errs[2].trans));  // no pose at t=4
}

TEST(Relations, TrajectoryFileRoundTripAndErrors) {
  Trajectory traj = {{976052857.33753, fw::Se2d(1.0 / 3, -2, 0.1)}, {976052858.5, fw::Se2d(4, 5, -3.1)}};
  const std::string p = temp_path("rel", "traj.txt");
  std::string err;
  ASSERT_TRUE(write_trajectory(p, traj, &err)) << err;
  Trajectory back;
  ASSERT_TRUE(read_trajectory(p, &back, &err)) << err;
  ASSERT_EQ(back.size(), 2u);
  EXPECT_NEAR(back[0].t, traj[0].t, 1e-6);
  EXPECT_EQ(back[0].pose.x, traj[0].pose.x);
  EXPECT_EQ(back[1].pose.theta, traj[1].pose.theta);
  write_text(p, "1,2,3,4\n5 6 7\n");
  EXPECT_FALSE(read_trajectory(p, &back, &err));
  EXPECT_NE(err.find(p + ":2: expected 4 fields"), std::string::npos) << err;
  write_text(p, "1 2 3 inf\n");
  EXPECT_FALSE(read_trajectory(p, &back, &err));
  EXPECT_NE(err.find(p + ":1: theta is not a finite number"), std::string::npos) << err;
  // Issue 13: finite but absurd values, and a line of a million fields (kept to 5 tokens, not 16 MB).
  write_text(p, "1e300 2 3 0\n");
  EXPECT_FALSE(read_trajectory(p, &back, &err));
  EXPECT_NE(err.find(p + ":1: t is 1e300, outside the plausible ±1e+10 s"), std::string::npos) << err;
  write_text(p, "1 2 -3e7 0\n");
  EXPECT_FALSE(read_trajectory(p, &back, &err));
  EXPECT_NE(err.find(p + ":1: y is -3e7, outside the plausible ±1e+06 m"), std::string::npos) << err;
  std::string huge;
  for (int i = 0; i < 1000000; ++i) huge += "1 ";
  write_text(p, huge + "\n");
  EXPECT_FALSE(read_trajectory(p, &back, &err));
  EXPECT_NE(err.find(p + ":1: expected 4 fields (t x y theta), found more"), std::string::npos) << err;
  std::remove(p.c_str());
}

TEST(ReferenceTrajectory, BlendRecoversTruthUnderLinearDrift) {
  // Truth: a curved path. Odometry: the truth increments with a constant scale/heading bias (linear
  // drift). Corrected poses (in a different frame) every 10th scan. The blend removes the first-order
  // drift, so the interpolated poses must be much closer to truth than either one-sided chain.
  const int n = 101;
  std::vector<fw::Se2d> truth(n), odo(n);
  fw::Se2d t(0, 0, 0), o(5, 5, 1.0);
  for (int i = 0; i < n; ++i) {
    truth[i] = t;
    odo[i] = o;
    const fw::Se2d u(0.1, 0.0, 0.03 * std::sin(0.1 * i));
    t = t.compose(u);
    o = o.compose(fw::Se2d(u.x * 1.02, 0.0, u.theta + 0.002));
  }
  const fw::Se2d frame(100, -40, -0.7);
  CarmenLog log;
  for (int i = 0; i < n; ++i) {
    CarmenScan s;
    s.index = static_cast<size_t>(i);
    s.ipc_timestamp = i;
    s.odom = odo[i];
    log.scans.push_back(s);
  }
  std::vector<CorrectedPose> cp;
  for (int i = 5; i < n; i += 10) cp.push_back({static_cast<size_t>(i), double(i), double(i), frame.compose(truth[i])});
  const auto ref = reference_with_bounds(log, cp);
  ASSERT_EQ(ref.size(), static_cast<size_t>(n));
  double worst_blend = 0, worst_forward = 0;
  for (int i = 5; i < 95; ++i) {
    const fw::Se2d want = frame.compose(truth[i]);
    const double e = std::hypot(ref[i].pose.x - want.x, ref[i].pose.y - want.y);
    worst_blend = std::max(worst_blend, e);
    EXPECT_LE(e, ref[i].bound + 1e-9) << i;  // the documented bound holds here
    const size_t a = static_cast<size_t>(5 + (i - 5) / 10 * 10);
    const fw::Se2d f = frame.compose(truth[a]).compose(odo[a].between(odo[i]));
    worst_forward = std::max(worst_forward, std::hypot(f.x - want.x, f.y - want.y));
    if ((i - 5) % 10 == 0) {
      EXPECT_TRUE(ref[i].exact);
      EXPECT_NEAR(e, 0.0, 1e-12);
    }
  }
  EXPECT_GT(worst_forward, 0.015);
  EXPECT_LT(worst_blend, worst_forward / 4);
  // Extrapolated ends have no bound.
  EXPECT_TRUE(std::isinf(ref[0].bound));
  EXPECT_TRUE(std::isinf(ref[100].bound));
  const auto g = reference_gap_stats(log, cp);
  EXPECT_EQ(g.gaps, 9u);
  EXPECT_DOUBLE_EQ(g.mean_gap_scans, 10.0);
  EXPECT_GT(g.mean_closure_m, 0.01);
}

TEST(ReferenceTrajectory, SkippedScanLinesKeepTheIndexMapping) {
  // Scan 2 of 5 is malformed and skipped: corrected poses keyed by file ordinal still land on the
  // right scans, and the pose for the dropped scan is simply absent.
  std::string text;
  for (int i = 0; i < 5; ++i) {
    const std::string x = std::to_string(i);
    text += i == 2 ? "FLASER 2 1 nan 0 0 0 0 0 0 2 h 2\n"
                   : "FLASER 2 1 1 " + x + " 0 0 " + x + " 0 0 " + x + " h " + x + "\n";
  }
  CarmenLog log;
  std::string err;
  CarmenReadOptions o;
  o.skip_bad_lines = true;
  ASSERT_TRUE(parse_carmen_log("m", text.data(), text.size(), o, &log, &err)) << err;
  ASSERT_EQ(log.scans.size(), 4u);
  EXPECT_EQ(log.scans[2].index, 3u);
  const std::vector<CorrectedPose> cp = {{0, 0, 0, fw::Se2d(10, 0, 0)}, {2, 2, 2, fw::Se2d(99, 99, 0)},
                                         {4, 4, 4, fw::Se2d(14, 0, 0)}};
  const auto ref = reference_with_bounds(log, cp);
  ASSERT_EQ(ref.size(), 4u);
  EXPECT_TRUE(ref[0].exact);
  EXPECT_TRUE(ref[3].exact);
  EXPECT_DOUBLE_EQ(ref[3].pose.x, 14.0);
  EXPECT_NEAR(ref[1].pose.x, 11.0, 1e-12);  // odometry chained, the dropped scan's pose unused
  EXPECT_NEAR(ref[2].pose.x, 13.0, 1e-12);
}

TEST(ReferenceTrajectory, CorruptedPosesFileIsAnError) {
  const struct {
    const char* text;
    const char* expect;
  } cases[] = {
      {"1 0 0 1 2 3\n0 0 0 1 2 3\n", "does not increase"},
      {"1 0 0 1 2 3\n2 0 0 1 2\n", "expected 6 fields"},
      {"1 0 0 1 2 3\n-2 0 0 1 2 3\n", "flaser_index"},
      {"1 0 0 1 2 3\n2 0 0 1 nan 3\n", "y is not a finite number"},
      // Issue 13: absurd index, timestamps and poses.
      {"1 0 0 1 2 3\n1000000000000000000 0 0 1 2 3\n", "flaser_index 1000000000000000000 is not a plausible scan index"},
      {"1 0 0 1 2 3\n2 1e300 0 1 2 3\n", "ipc_timestamp is 1e300, outside the plausible ±1e+10 s"},
      {"1 0 0 1 2 3\n2 0 -1e300 1 2 3\n", "logger_timestamp is -1e300"},
      {"1 0 0 1 2 3\n2 0 0 1e7 2 3\n", "x is 1e7, outside the plausible ±1e+06 m"},
      {"1 0 0 1 2 3\n2 0 0 1 2 3e5\n", "theta is 3e5, outside the plausible ±10000 rad"},
  };
  for (const auto& c : cases) {
    const std::string p = temp_path("rel", "cp.txt");
    write_text(p, c.text);
    std::vector<CorrectedPose> out;
    std::string err;
    EXPECT_FALSE(read_corrected_poses(p, &out, &err));
    EXPECT_NE(err.find(p + ":2: "), std::string::npos) << err;
    EXPECT_NE(err.find(c.expect), std::string::npos) << err;
    std::remove(p.c_str());
  }
}

}  // namespace
}  // namespace sim
