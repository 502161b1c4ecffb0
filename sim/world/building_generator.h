// Generated buildings (issue 55): seeded, deterministic floor plans in the families our users' robots
// drive in, each with its route graph, so that a rule can be measured on buildings nobody tuned on.
// A plan keeps its parts apart (structure, doors, furniture, glass) because the world the laser sees
// may differ from the map in exactly those parts (map_changes.h).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "sim/world/world.h"

namespace sim {

enum class BuildingFamily {
  kOffice = 0,        // rooms off corridors, doors, desks and cabinets
  kHospitalWing = 1,  // long corridors, periodic doors, look-alike rooms (fr-clinic)
  kOpenHall = 2,      // halls and atria, walls partly beyond the laser's range, pillars
  kWarehouse = 3,     // long rows of identical racks
  kLab = 4,           // labs / workshops with dense clutter
  kMultiWing = 5,     // wings of the families above joined by corridors
};
constexpr int kBuildingFamilyCount = 6;
const char* building_family_name(BuildingFamily f);  // "office", "hospital", "hall", "warehouse", "lab", "multi-wing"
// False for an unknown name.
bool parse_building_family(const std::string& name, BuildingFamily* out);

// A door leaf: the segment that closes a door gap (in the walls when closed).
struct Door {
  Segment leaf;
  bool closed = false;  // in the plan (as mapped)
};

// A piece of furniture (desk, cabinet, rack, pillar-free clutter): closed outline, movable as one.
struct Furniture {
  std::vector<Segment> outline;
  Vec2 centre = Vec2::Zero();
};

struct BuildingPlan {
  BuildingFamily family = BuildingFamily::kOffice;
  // The structure: outer and inner walls, pillars (never change between map and world); its route
  // graph and bounds. structure.walls holds no door leaf, furniture or glass.
  World structure;
  std::vector<Door> doors;
  std::vector<Furniture> furniture;
  std::vector<Segment> glass;  // glass panes (in the plan and the map; the laser may not see them)
};

struct BuildingOptions {
  BuildingFamily family = BuildingFamily::kOffice;
  // Outline; 0 = drawn from the seed within the family's range (all families within 20 × 20 m to
  // 150 × 100 m).
  double width_m = 0, height_m = 0;
  double glass_fraction = 0.1;       // share of the inner partition walls built as glass
  double closed_door_fraction = 0.2; // share of doors closed in the plan (the route never passes them)

  std::string validate() const;
};

// False with *err for bad options. Same options + seed ⇒ the same plan.
bool generate_building(const BuildingOptions& opt, std::uint64_t seed, BuildingPlan* out, std::string* err);

// The World of a plan: structure walls + closed doors' leaves + furniture outlines as walls, glass as
// World::glass, the route graph without edges through closed doors.
World compose_world(const BuildingPlan& plan);

}  // namespace sim
