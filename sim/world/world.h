// Synthetic line-segment worlds for the simulator: walls and furniture as segments, people as
// moving circles, an "unknown area" that exists in the world but is erased from the map the
// localizer gets, and a route graph (corridor centre lines, doors, room centres) for the robot
// path generator. Coordinates in metres, world frame = map frame.
#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

namespace sim {

using Vec2 = Eigen::Vector2d;

struct Segment {
  Vec2 a, b;
};

struct Box {  // axis-aligned rectangle, min/max corners
  Vec2 min, max;
  bool contains(const Vec2& p) const { return p.x() >= min.x() && p.x() <= max.x() && p.y() >= min.y() && p.y() <= max.y(); }
};

// A person walking back and forth along a polyline (ping-pong) at constant speed.
struct Person {
  std::vector<Vec2> path;  // ≥ 2 points
  double radius = 0.25;    // m
  double speed = 0.8;      // m/s
  double phase_s = 0.0;    // time offset along the path
};

// Position at time t (seconds since the run started).
Vec2 person_position(const Person& p, double t);

// Route graph: nodes where the robot may drive, edges are straight free lines between them.
struct RouteGraph {
  enum Kind { kCorridor = 0, kDoorway = 1, kRoom = 2 };
  std::vector<Vec2> nodes;
  std::vector<std::vector<int>> adjacent;
  std::vector<int> kinds;
  // Returns the existing node at p (within 1 µm) or a new one of `kind`.
  int add_node(const Vec2& p, int kind = kCorridor);
  void connect(int a, int b);
};

struct World {
  std::string name;
  Box bounds;                  // the building outline (walls lie on or inside it)
  std::vector<Segment> walls;  // static structure, in the map
  // Glass panes: in the map (drawn from the plan), but a laser beam may pass through them and return
  // from what is behind, or not return at all (LaserModelOptions::glass_return_probability).
  std::vector<Segment> glass;
  std::vector<Box> unknown_areas;  // in the world, erased from the map (Sec. 5.6)
  std::vector<Person> people;  // dynamic obstacles, never in the map
  RouteGraph route;
  double default_resolution = 0.05;  // m per map cell
};

// Builder helpers used by the built-in worlds (and tests).
void add_segment(World* w, double x0, double y0, double x1, double y1);
// Closed rectangle outline.
void add_rect(World* w, double x0, double y0, double x1, double y1);
// A wall from (x0,y) to (x1,y) or (x,y0)–(x,y1) with door gaps [centre − width/2, centre + width/2].
void add_wall_with_doors(World* w, const Vec2& from, const Vec2& to, const std::vector<double>& door_centres,
                         double door_width);

}  // namespace sim
