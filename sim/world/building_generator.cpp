#include "sim/world/building_generator.h"

#include <cmath>

#include "sim/world/building_geometry.h"

namespace sim {

namespace {

constexpr const char* kFamilyNames[kBuildingFamilyCount] = {"office",    "hospital", "hall",
                                                            "warehouse", "lab",      "multi-wing"};

struct SizeRange {
  double w0, w1, h0, h1;
};

// Sizes a family is drawn in (all within 20 × 20 m to 150 × 100 m): a hospital wing long and
// narrow, a warehouse large, a hall large enough for its far walls to leave a 12–30 m laser's range.
SizeRange family_sizes(BuildingFamily f) {
  switch (f) {
    case BuildingFamily::kHospitalWing:
      return {50, 150, 20, 30};
    case BuildingFamily::kOpenHall:
      return {30, 90, 25, 70};
    case BuildingFamily::kWarehouse:
      return {40, 150, 30, 100};
    case BuildingFamily::kLab:
      return {20, 60, 20, 40};
    case BuildingFamily::kMultiWing:
      return {60, 150, 40, 100};
    case BuildingFamily::kOffice:
      break;
  }
  return {25, 90, 20, 60};
}

}  // namespace

const char* building_family_name(BuildingFamily f) {
  const int i = static_cast<int>(f);
  return i >= 0 && i < kBuildingFamilyCount ? kFamilyNames[i] : "unknown";
}

bool parse_building_family(const std::string& name, BuildingFamily* out) {
  for (int i = 0; i < kBuildingFamilyCount; ++i) {
    if (name == kFamilyNames[i]) {
      *out = static_cast<BuildingFamily>(i);
      return true;
    }
  }
  return false;
}

std::string BuildingOptions::validate() const {
  const int f = static_cast<int>(family);
  if (f < 0 || f >= kBuildingFamilyCount) return "building family " + std::to_string(f) + " unknown";
  if (!(width_m == 0 || (width_m >= 20 && width_m <= 150))) return "building width must be 0 (drawn) or in [20, 150] m";
  if (!(height_m == 0 || (height_m >= 20 && height_m <= 100)))
    return "building height must be 0 (drawn) or in [20, 100] m";
  if (!(glass_fraction >= 0 && glass_fraction <= 1)) return "building glass_fraction must be in [0, 1]";
  if (!(closed_door_fraction >= 0 && closed_door_fraction <= 1))
    return "building closed_door_fraction must be in [0, 1]";
  return {};
}

bool generate_building(const BuildingOptions& opt, std::uint64_t seed, BuildingPlan* out, std::string* err) {
  const std::string bad = opt.validate();
  if (!bad.empty()) {
    if (err) *err = bad;
    return false;
  }
  *out = BuildingPlan{};
  out->family = opt.family;
  fw::RandomStream rng(seed, 55);
  building::PlanBuilder b{out, &opt, &rng};
  const SizeRange range = family_sizes(opt.family);
  // Both sizes are drawn even when given, so an explicit width leaves the rest of the plan as drawn.
  const double w_drawn = b.uniform(range.w0, range.w1);
  const double h_drawn = b.uniform(range.h0, range.h1);
  const double w = opt.width_m > 0 ? opt.width_m : std::round(w_drawn);
  const double h = opt.height_m > 0 ? opt.height_m : std::round(h_drawn);
  World& s = out->structure;
  s.name = std::string("gen-") + building_family_name(opt.family) + "-" + std::to_string(seed);
  s.bounds = {Vec2(0, 0), Vec2(w, h)};
  s.default_resolution = 0.05;
  const building::Rect r{0, 0, w, h};
  switch (opt.family) {
    case BuildingFamily::kOpenHall:
      building::build_open_hall(&b, r, false);
      break;
    case BuildingFamily::kWarehouse:
      building::build_warehouse(&b, r, false);
      break;
    case BuildingFamily::kMultiWing:
      building::build_multi_wing(&b, r);
      break;
    default:
      building::build_corridor_family(&b, r, opt.family, false);
      break;
  }
  // The layouts keep their route lines clear by construction; this guard keeps the promise of the
  // route graph (every edge ≥ 0.4 m from every wall, pane and piece of furniture) should a layout
  // not, dropping the edge rather than letting a robot drive through a wall.
  const std::vector<Segment> obstacles = building::plan_obstacles(*out, [](const Door&) { return false; });
  s.route = building::filter_route(s.route, [&](const Segment& e) {
    return !s.bounds.contains(e.a) || !s.bounds.contains(e.b) ||
           building::clearance(e, obstacles) < building::kRouteClearance;
  });
  return true;
}

World compose_world(const BuildingPlan& plan) {
  World w = plan.structure;
  std::vector<Segment> closed;
  for (const Door& d : plan.doors) {
    if (d.closed) closed.push_back(d.leaf);
  }
  w.walls.insert(w.walls.end(), closed.begin(), closed.end());
  for (const Furniture& f : plan.furniture) w.walls.insert(w.walls.end(), f.outline.begin(), f.outline.end());
  w.glass = plan.glass;
  // Rooms behind closed doors drop out of the route entirely (route.cpp draws start nodes from
  // every connected node, so a node must be reachable to stay).
  w.route = building::filter_route(plan.structure.route, [&](const Segment& e) {
    return building::clearance(e, closed) < building::kRouteClearance;
  });
  return w;
}

}  // namespace sim
