// Shared pieces of the building generator (building_*.cpp) and the map changes: rectangles,
// segment distances (the route's clearance), furniture outlines, the plan being built and the
// route graph clean-up. Internal to sim/world.
#pragma once

#include <cstdint>
#include <vector>

#include "firmware/base/rng.h"
#include "sim/world/building_generator.h"

namespace sim::building {

// The robot is ~0.5 m wide: every route edge keeps this far from every obstacle segment.
constexpr double kRouteClearance = 0.4;
constexpr double kDoorWidth = 1.0;  // door gap, m (0.5 m each side of a route edge through it)
constexpr double kDoorInset = 1.0;  // a room's doorway node this far inside the room

struct Rect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
  double w() const { return x1 - x0; }
  double h() const { return y1 - y0; }
  Vec2 centre() const { return Vec2(0.5 * (x0 + x1), 0.5 * (y0 + y1)); }
};

double point_segment_distance(const Vec2& p, const Segment& s);
bool segments_intersect(const Segment& a, const Segment& b);
double segment_distance(const Segment& a, const Segment& b);
// Smallest distance from `edge` to any of `obstacles` (∞ when empty).
double clearance(const Segment& edge, const std::vector<Segment>& obstacles);
// Whether every segment of `outline` keeps ≥ gap from all `obstacles`.
bool clearance_ok(const std::vector<Segment>& outline, const std::vector<Segment>& obstacles, double gap);

// Closed outlines: a box of size sx × sy turned by `angle` about its centre; an octagon of radius r.
std::vector<Segment> box_outline(const Vec2& centre, double sx, double sy, double angle = 0);
std::vector<Segment> octagon_outline(const Vec2& centre, double r);
Furniture make_furniture(std::vector<Segment> outline);
bool point_in_outline(const Vec2& p, const std::vector<Segment>& outline);  // even-odd rule

// Route edges of a graph as segments (each once, a < b).
std::vector<Segment> route_edges(const RouteGraph& g);
// Drops the edges for which `blocked(edge)` holds, then every node outside the largest connected
// component (ties: the component of the lowest node id), renumbering the rest in order.
template <class Blocked>
RouteGraph filter_route(const RouteGraph& g, Blocked blocked);
RouteGraph largest_component(const RouteGraph& g);

// A plan under construction: the family generators add to it through these calls so that the
// glass and door draws are made in one place, in the order of the calls (same seed ⇒ same plan).
struct PlanBuilder {
  BuildingPlan* plan;
  const BuildingOptions* opt;
  fw::RandomStream* rng;

  double uniform(double lo, double hi) { return lo + (hi - lo) * rng->uniform01(); }
  int uniform_int(int lo, int hi) {
    return lo + static_cast<int>(rng->uniform_index(static_cast<std::uint32_t>(hi - lo + 1)));
  }
  bool chance(double p) { return rng->uniform01() < p; }

  void wall(const Vec2& a, const Vec2& b) { plan->structure.walls.push_back({a, b}); }
  void rect_walls(const Rect& r);
  // An inner partition: glass when `as_glass`, else a wall.
  void partition(const Vec2& a, const Vec2& b, bool as_glass);
  // A straight wall from `a` to `b` with door gaps of kDoorWidth centred at the given distances from
  // `a`; each gap gets a Door (closed per closed_door_fraction). `as_glass` builds the wall of glass.
  void wall_with_doors(const Vec2& a, const Vec2& b, const std::vector<double>& door_at, bool as_glass,
                       bool real_doors = true, double gap = kDoorWidth);
  void furniture(std::vector<Segment> outline) { plan->furniture.push_back(make_furniture(std::move(outline))); }
  int node(const Vec2& p, int kind = RouteGraph::kCorridor) { return plan->structure.route.add_node(p, kind); }
  void connect(int a, int b) { plan->structure.route.connect(a, b); }
  // Links the nodes lying on one straight line in order along it.
  void chain(std::vector<int> nodes);
  // Whether a box outline may stand here: within `room` (inset by `margin`), ≥ `route_gap` from
  // every route edge in `edges`, no route node inside, and ≥ 0.1 m from the walls, glass and
  // furniture placed so far — all of them, or only `nearby` when given (a room's own, see
  // obstacles_near: a large building has thousands).
  bool free_for_furniture(const std::vector<Segment>& outline, const Rect& room, const std::vector<Segment>& edges,
                          double route_gap, double margin = 0.05, const std::vector<Segment>* nearby = nullptr) const;
  // The walls, glass and furniture segments whose bounding boxes come within `grow` of `r`.
  std::vector<Segment> obstacles_near(const Rect& r, double grow) const;
};

// Every obstacle of a plan as segments: structure walls, glass, furniture outlines, and the door
// leaves for which `leaf(door)` holds.
template <class LeafPred>
std::vector<Segment> plan_obstacles(const BuildingPlan& plan, LeafPred leaf) {
  std::vector<Segment> out = plan.structure.walls;
  out.insert(out.end(), plan.glass.begin(), plan.glass.end());
  for (const Furniture& f : plan.furniture) out.insert(out.end(), f.outline.begin(), f.outline.end());
  for (const Door& d : plan.doors) {
    if (leaf(d)) out.push_back(d.leaf);
  }
  return out;
}

template <class Blocked>
RouteGraph filter_route(const RouteGraph& g, Blocked blocked) {
  RouteGraph cut;
  cut.nodes = g.nodes;
  cut.kinds = g.kinds;
  cut.adjacent.assign(g.nodes.size(), {});
  for (size_t a = 0; a < g.nodes.size(); ++a) {
    for (int b : g.adjacent[a]) {
      if (static_cast<int>(a) < b && !blocked(Segment{g.nodes[a], g.nodes[b]})) cut.connect(static_cast<int>(a), b);
    }
  }
  return largest_component(cut);
}

// Family generators (one per file): each fills `r` of the plan. With `entrance`, the bottom wall
// of `r` gets a gap and a route node 1 m inside it, returned (−1 without an entrance).
int build_corridor_family(PlanBuilder* b, const Rect& r, BuildingFamily style, bool entrance);
int build_open_hall(PlanBuilder* b, const Rect& r, bool entrance);
int build_warehouse(PlanBuilder* b, const Rect& r, bool entrance);
void build_multi_wing(PlanBuilder* b, const Rect& r);

}  // namespace sim::building
