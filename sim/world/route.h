// Robot path generator: a seeded random walk over the world's route graph (corridor centre lines,
// doorways, room centres), driven as "turn in place, then drive straight" at constant speeds, so the
// ground truth is a continuous function of time (scans and odometry sample it at their own rates).
#pragma once

#include <string>
#include <vector>

#include "firmware/base/rng.h"
#include "firmware/base/se2.h"
#include "sim/world/world.h"

namespace sim {

struct RouteOptions {
  double length_m = 0;        // path length to drive; 0 = a world-dependent default
  double speed = 0.75;        // m/s
  double turn_rate_deg = 60;  // deg/s
  int start_node = -1;        // route-graph node to start from; −1 = drawn from the seed
  bool avoid_unknown = true;  // never enter the world's unknown areas (unless via_unknown)
  // First drive the shortest way into the nearest unknown area, then walk on at random (for
  // unknown-region experiments, Sec. 5.6: the localizer must report outside-map there).
  bool via_unknown = false;
  // Choice weights at a junction: continuing straight (long corridor runs), a node not visited
  // yet (explore the building instead of pacing), entering a room (rooms are dead ends).
  double straight_weight = 3.0;
  double unvisited_weight = 4.0;
  double room_weight = 0.35;
  // Issue 55 (off by default; a default route is bit for bit what it was). Speed per leg: every
  // drive from node to node at a speed drawn uniformly in [speed_min, speed_max] m/s (both 0 =
  // every leg at `speed`). Stops: on arriving at a node the robot stands still with probability
  // stop_probability for a time drawn uniformly in [stop_min_s, stop_max_s]. Their draws come from
  // a stream of their own (seeded from a copy of the route's stream), so the path is the same with
  // or without them; only its timing changes.
  double speed_min = 0, speed_max = 0;
  double stop_probability = 0;
  double stop_min_s = 2, stop_max_s = 10;

  bool varied_motion() const { return speed_max > 0 || stop_probability > 0; }
  std::string validate() const;
};

// A piecewise motion: segments of pure rotation, pure straight driving or standing still.
class RouteTrajectory {
 public:
  struct Piece {
    double t0, t1;      // time span, s
    fw::Se2d start;     // pose at t0
    double v, omega;    // forward speed, turn rate during the piece (both 0: a stop)
  };
  void add_stop(double duration_s);
  void add_turn(double target_heading, double turn_rate);
  void add_drive(const Vec2& to, double speed);
  void start_at(const fw::Se2d& pose);
  fw::Se2d pose_at(double t) const;  // clamped to [0, duration]
  double duration() const { return pieces_.empty() ? 0.0 : pieces_.back().t1; }
  double length() const { return length_; }
  const std::vector<Piece>& pieces() const { return pieces_; }
  const fw::Se2d& end_pose() const { return end_; }

 private:
  std::vector<Piece> pieces_;
  fw::Se2d end_;
  double length_ = 0;
};

// Random walk over the route graph from a seeded start node until length_m is driven.
// `exclude_near`/`exclude_radius`: the drawn start node must be farther than that from the point
// (used to kidnap the robot somewhere else).
bool generate_route(const World& world, const RouteOptions& opt, fw::RandomStream* rng, RouteTrajectory* out,
                    std::vector<int>* visited_nodes, std::string* err, const Vec2* exclude_near = nullptr,
                    double exclude_radius = 0);

double default_route_length(const World& world);

}  // namespace sim
