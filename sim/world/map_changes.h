// "The map is not the world" (issue 55): from one plan, the world the laser sees and the map the
// localizer is given, differing by unmapped clutter, doors flipped, furniture moved and a wing of the
// map drawn bent (a SLAM map's own error). People walking through are added by the run
// (SyntheticRunOptions::people). Errors are judged in the map's frame: against where the map draws
// the robot's place (MapDrawing), as the bench logs' references judge by local relations.
#pragma once

#include <cstdint>
#include <string>

#include "sim/world/building_generator.h"
#include "sim/world/world.h"

namespace sim {

struct MapChangeOptions {
  double clutter_per_100m2 = 0;    // unmapped boxes and chairs (0.3–1 m) per 100 m² of floor, off the route lines
  double door_flip_fraction = 0;   // share of doors whose state in the world differs from the map
  double rearranged_fraction = 0;  // share of furniture moved ≥ 0.5 m (within one area of the building)
  // A wing of the map bent: turned by this angle at its far end (0.5–1° typical), capped so that the
  // map's local scale error stays ≤ 0.5 % (map_changes.cpp, kMaxMapStrain).
  double distortion_deg = 0;

  std::string validate() const;
  bool clean() const { return clutter_per_100m2 == 0 && door_flip_fraction == 0 && rearranged_fraction == 0 && distortion_deg == 0; }
};

// How the map draws the world. Bent: beyond the joint x = joint_x the map turns by an angle growing
// linearly from 0 at the joint to angle_rad at x = far_x — the heading drift a SLAM map accumulates
// along a wing, continuous everywhere (map_changes.cpp, MapDrawing::point). A rigid turn of the
// whole wing about the pivot, as first drawn, tore the map at the joint by up to the angle × half
// the building's height: 0.7 m in an 80 m tall building, a tear no SLAM map has.
struct MapDrawing {
  bool bent = false;
  Vec2 pivot = Vec2::Zero();
  double joint_x = 0, far_x = 0, angle_rad = 0;

  Vec2 point(const Vec2& p) const;  // where the map draws a point of the world
  // Where the map draws a robot standing at (x, y) facing theta: the position drawn as a point, the
  // heading turned as the drawing turns there.
  void pose(double x, double y, double theta, double* mx, double* my, double* mtheta) const;
};

struct MapChangeReport {
  int clutter_items = 0, doors_flipped = 0, furniture_moved = 0;
  bool distorted = false;
  Box distorted_region;  // the wing drawn bent (empty when not distorted)
  Vec2 pivot = Vec2::Zero();
  MapDrawing drawing;    // identity unless distorted
};

// world: what the laser sees (its route graph: edges through doors closed in the world removed);
// map: what the map is drawn from (the plan, distorted if asked). Same inputs + seed ⇒ the same.
bool apply_map_changes(const BuildingPlan& plan, const MapChangeOptions& opt, std::uint64_t seed, World* world,
                       World* map, MapChangeReport* report, std::string* err);

}  // namespace sim
