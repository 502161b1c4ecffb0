// "The map is not the world" (issue 55): from one plan, the world the laser sees and the map the
// localizer is given, differing by unmapped clutter, doors flipped, furniture moved and a wing of the
// map drawn turned (a SLAM map's own error). People walking through are added by the run
// (SyntheticRunOptions::people). Errors are judged in the world's frame.
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
  double distortion_deg = 0;       // a wing of the map turned by this angle about its joint (0.5–1° typical)

  std::string validate() const;
  bool clean() const { return clutter_per_100m2 == 0 && door_flip_fraction == 0 && rearranged_fraction == 0 && distortion_deg == 0; }
};

struct MapChangeReport {
  int clutter_items = 0, doors_flipped = 0, furniture_moved = 0;
  bool distorted = false;
  Box distorted_region;  // the wing drawn turned (empty when not distorted)
  Vec2 pivot = Vec2::Zero();
};

// world: what the laser sees (its route graph: edges through doors closed in the world removed);
// map: what the map is drawn from (the plan, distorted if asked). Same inputs + seed ⇒ the same.
bool apply_map_changes(const BuildingPlan& plan, const MapChangeOptions& opt, std::uint64_t seed, World* world,
                       World* map, MapChangeReport* report, std::string* err);

}  // namespace sim
