// Freiburg SLAM-benchmark relations and the metric of Kümmerle et al. 2009 ("On measuring the
// accuracy of SLAM algorithms", Auton. Robots 27(4)). A relation (t1, t2, δ) states the pose at t2
// expressed in the frame of the pose at t1 (δ = x_{t1} ⊖ x_{t2}). For an estimated trajectory x̂ the
// error of one relation is e = δ ⊖ (x̂_{t1} ⊖ x̂_{t2}); its translational part |e_xy| (m; equal to
// the distance between the estimated and the reference displacement vectors) and rotational part
// |wrap(e_θ)| are averaged over all relations (Eq. 2 of the paper, split into translation and
// rotation as in its tables: mean ± std of absolute and of squared errors). Standard deviations are
// population deviations (divide by N). Angular figures are in degrees (squared ones in deg²).
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "firmware/base/se2.h"

namespace sim {

struct Relation {
  double t1 = 0, t2 = 0;
  fw::Se2d delta;
};

// Reads "t1 t2 x y z roll pitch yaw" lines ('#' comments and blank lines skipped). z, roll and pitch
// must be 0 (2D data); timestamps, x, y and yaw finite and within the plausible bounds of carmen_log.h
// (±1e10 s, ±1e6 m, ±1e4 rad); errors name "path:line" and the field.
bool read_relations(const std::string& path, std::vector<Relation>* out, std::string* error);
// Writes relations in the same format (timestamps with 6 decimals, values shortest round-trip).
bool write_relations(const std::string& path, const std::vector<Relation>& rel, std::string* error);

struct TimedPose {
  double t = 0;
  fw::Se2d pose;
};
using Trajectory = std::vector<TimedPose>;

struct RelationsMetric {
  size_t used = 0, missing = 0;  // relations evaluated / skipped because a timestamp has no pose
  double trans_mean = 0, trans_std = 0;      // m
  double trans2_mean = 0, trans2_std = 0;    // m²
  double rot_mean_deg = 0, rot_std_deg = 0;  // deg
  double rot2_mean = 0, rot2_std = 0;        // deg²
  double trans_max = 0, rot_max_deg = 0;     // (addition) worst relation
};

// Poses are looked up by timestamp: the trajectory pose whose t is nearest to the relation's t1/t2,
// accepted when within time_tolerance seconds (no interpolation; the relations' timestamps are scan
// timestamps). The trajectory need not be sorted (intel's timestamps are not monotonic); for equal
// timestamps the first pose in trajectory order is used.
RelationsMetric evaluate_relations(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                   double time_tolerance = 1e-4);

// Per-relation errors (same lookup): translational (m) and rotational (rad, wrapped, signed) error,
// NaN when a pose is missing.
struct RelationError {
  double trans = 0, rot = 0;
};
std::vector<RelationError> relation_errors(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                           double time_tolerance = 1e-4);

std::string to_string(const RelationsMetric& m);

// The metric split by relation length (issue 15): relations whose timestamps are at most
// split_s apart measure the precision of single alignments (scan-to-scan, short drift); the
// longer ones measure accumulated drift. Kümmerle et al. report both kinds of relation in one
// mean, which hides a matcher that is locally imprecise but globally consistent (or the reverse).
struct RelationsMetricSplit {
  double split_s = 10.0;
  RelationsMetric all, short_rel, long_rel;  // |t2 − t1| ≤ split_s / > split_s
};
RelationsMetricSplit evaluate_relations_split(const std::vector<Relation>& relations, const Trajectory& trajectory,
                                              double split_s = 10.0, double time_tolerance = 1e-4);
// Three lines: "all: …", "short (<= 10 s, N): …", "long (> 10 s, N): …".
std::string to_string(const RelationsMetricSplit& m);

// Plain trajectory files for tools: one "t x y theta" per line (blanks or commas between fields,
// '#' comments; values within the bounds of carmen_log.h). Errors name "path:line". The writer prints t with 6 decimals (like the logs' ipc
// timestamps, so relation lookups with the default tolerance still match) and poses shortest
// round-trip.
bool read_trajectory(const std::string& path, Trajectory* out, std::string* error);
bool write_trajectory(const std::string& path, const Trajectory& traj, std::string* error);

}  // namespace sim
