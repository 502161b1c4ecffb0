#include "sim/world/map_changes.h"

#include <algorithm>
#include <cmath>
#include <numeric>

#include "firmware/base/rng.h"
#include "sim/world/building_geometry.h"

namespace sim {

namespace {

constexpr double kMovedRouteGap = 0.5;    // furniture moved keeps this far from every route edge
constexpr double kClutterRouteGap = 0.6;  // unmapped clutter: the robot never drives into it
constexpr double kObstacleGap = 0.05;     // nothing is placed into a wall or another object
// A bent map's local scale error stays within this (5 mm per metre): what a SLAM map closed by loop
// constraints keeps locally, and the product's stated assumption on its maps (sim/cli/corpus/README.md).
// Uncapped, a 1° bend over a 40 m wing strained the far side of an 84 m tall building by 1.7 %:
// walls 10 m away drawn 17 cm closer, a local error no localizer can see or bound.
constexpr double kMaxMapStrain = 0.005;

// One random stream per kind of change, so that switching one on leaves the others as they were.
enum MapChangeStream : std::uint64_t { kDistortStream = 56, kDoorStream = 57, kMoveStream = 58, kClutterStream = 59 };

Vec2 turn_about(const Vec2& p, const Vec2& pivot, double angle) {
  const double c = std::cos(angle), s = std::sin(angle);
  const Vec2 d = p - pivot;
  return pivot + Vec2(c * d.x() - s * d.y(), s * d.x() + c * d.y());
}

// Wall pieces at most this long are bent as straight lines: the chord of a bent 1 m piece is off
// the bend by < 1 mm, far below the map's 5 cm cells.
constexpr double kBendPieceM = 1.0;

// The map of a wing drawn bent (MapDrawing): walls and glass cut into short pieces where they reach
// into the wing, so that a long wall follows the bend instead of its chord.
void distort_map(World* map, const MapDrawing& d) {
  for (std::vector<Segment>* v : {&map->walls, &map->glass}) {
    std::vector<Segment> out;
    out.reserve(v->size());
    for (const Segment& s : *v) {
      if (std::max(s.a.x(), s.b.x()) <= d.joint_x) {
        out.push_back(s);
        continue;
      }
      const int n = std::max(1, static_cast<int>(std::ceil((s.b - s.a).norm() / kBendPieceM)));
      for (int k = 0; k < n; ++k) {
        const Vec2 a = s.a + (s.b - s.a) * (static_cast<double>(k) / n);
        const Vec2 b = s.a + (s.b - s.a) * (static_cast<double>(k + 1) / n);
        out.push_back(Segment{d.point(a), d.point(b)});
      }
    }
    v->swap(out);
  }
  for (Vec2& n : map->route.nodes) n = d.point(n);
  // The outline grows to hold the bent wing (else the raster would clip its walls).
  for (const std::vector<Segment>* v : {&map->walls, &map->glass}) {
    for (const Segment& s : *v) {
      for (const Vec2& p : {s.a, s.b}) {
        map->bounds.min = map->bounds.min.cwiseMin(p);
        map->bounds.max = map->bounds.max.cwiseMax(p);
      }
    }
  }
}

std::vector<Segment> door_leaves(const BuildingPlan& plan) {
  std::vector<Segment> out;
  for (const Door& d : plan.doors) out.push_back(d.leaf);
  return out;
}

// Whether an outline may stand here in the world: ≥ route_gap from every route edge (of the plan:
// with all doors open, so no state of the doors makes a path through it), no route node inside,
// ≥ kObstacleGap from everything else, inside the outline of the building.
bool may_stand_in_world(const std::vector<Segment>& outline, const std::vector<Segment>& edges, double route_gap,
                        const std::vector<Segment>& obstacles, const Box& bounds) {
  for (const Segment& s : outline) {
    if (!bounds.contains(s.a) || building::clearance(s, edges) < route_gap ||
        building::clearance(s, obstacles) < kObstacleGap)
      return false;
  }
  for (const Segment& e : edges) {
    if (building::point_in_outline(e.a, outline) || building::point_in_outline(e.b, outline)) return false;
  }
  return true;
}

int flip_doors(BuildingPlan* plan, double fraction, std::uint64_t seed) {
  fw::RandomStream rng(seed, kDoorStream);
  int flipped = 0;
  for (Door& d : plan->doors) {
    if (rng.uniform01() < fraction) {
      d.closed = !d.closed;
      ++flipped;
    }
  }
  return flipped;
}

// Tries to move piece `i` by 0.5–1.5 m (turned a little at times) within its own room.
bool move_piece(BuildingPlan* plan, size_t i, const std::vector<Segment>& edges, fw::RandomStream* rng) {
  const Furniture old = plan->furniture[i];
  // What the piece may meet within its reach (a move of ≤ 1.5 m, turned ≤ 0.5 rad, kept ≤ 0.6 m
  // off): without the piece itself, whose own outline is among the furniture's.
  building::Rect reach{1e300, 1e300, -1e300, -1e300};
  for (const Segment& s : old.outline) {
    for (const Vec2& p : {s.a, s.b}) {
      reach = {std::min(reach.x0, p.x()), std::min(reach.y0, p.y()), std::max(reach.x1, p.x()),
               std::max(reach.y1, p.y())};
    }
  }
  const double grow = 2.5 + 0.5 * std::max(reach.w(), reach.h());
  reach = {reach.x0 - grow, reach.y0 - grow, reach.x1 + grow, reach.y1 + grow};
  auto within = [&](const Segment& s) {
    return std::max(s.a.x(), s.b.x()) >= reach.x0 && std::min(s.a.x(), s.b.x()) <= reach.x1 &&
           std::max(s.a.y(), s.b.y()) >= reach.y0 && std::min(s.a.y(), s.b.y()) <= reach.y1;
  };
  std::vector<Segment> others, near_edges;
  for (const Segment& s : plan->structure.walls) {
    if (within(s)) others.push_back(s);
  }
  for (const Segment& s : plan->glass) {
    if (within(s)) others.push_back(s);
  }
  for (const Segment& s : door_leaves(*plan)) {
    if (within(s)) others.push_back(s);
  }
  for (size_t k = 0; k < plan->furniture.size(); ++k) {
    for (const Segment& s : plan->furniture[k].outline) {
      if (k != i && within(s)) others.push_back(s);
    }
  }
  for (const Segment& e : edges) {
    if (within(e)) near_edges.push_back(e);
  }
  for (int attempt = 0; attempt < 30; ++attempt) {
    const double dist = 0.5 + rng->uniform01();
    const double dir = rng->uniform01() * 2 * M_PI;
    const bool turns = rng->uniform01() < 0.3;
    const double turn_draw = rng->uniform01();  // drawn either way: one draw per attempt, same order
    const double turn = turns ? turn_draw - 0.5 : 0.0;
    const Vec2 to = old.centre + dist * Vec2(std::cos(dir), std::sin(dir));
    // Stay in the room: the way there crosses no wall, pane or other piece.
    if (building::clearance(Segment{old.centre, to}, others) < kObstacleGap) continue;
    std::vector<Segment> moved = old.outline;
    for (Segment& s : moved) {
      s.a = turn_about(s.a, old.centre, turn) + (to - old.centre);
      s.b = turn_about(s.b, old.centre, turn) + (to - old.centre);
    }
    if (!may_stand_in_world(moved, near_edges, kMovedRouteGap, others, plan->structure.bounds)) continue;
    plan->furniture[i].outline = moved;
    plan->furniture[i].centre = to;
    return true;
  }
  return false;
}

// The rearranged area: the pieces nearest one piece drawn at random, moved until the share is met.
int rearrange_furniture(BuildingPlan* plan, double fraction, std::uint64_t seed) {
  const size_t n = plan->furniture.size();
  if (fraction <= 0 || n == 0) return 0;
  fw::RandomStream rng(seed, kMoveStream);
  const int want = std::max(1, static_cast<int>(std::lround(fraction * static_cast<double>(n))));
  const Vec2 area = plan->furniture[rng.uniform_index(static_cast<std::uint32_t>(n))].centre;
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) {
    return (plan->furniture[a].centre - area).norm() < (plan->furniture[b].centre - area).norm();
  });
  const std::vector<Segment> edges = building::route_edges(plan->structure.route);
  int moved = 0;
  for (size_t k = 0; k < n && moved < want; ++k) moved += move_piece(plan, order[k], edges, &rng) ? 1 : 0;
  return moved;
}

// Boxes (0.3–1 m, any heading) and chairs (octagons) near the route, where a robot sees them, yet
// never on its lines.
int add_clutter(const BuildingPlan& plan, double per_100m2, std::uint64_t seed, World* world) {
  const std::vector<Segment> edges = building::route_edges(plan.structure.route);
  if (per_100m2 <= 0 || edges.empty()) return 0;
  fw::RandomStream rng(seed, kClutterStream);
  const Vec2 size = plan.structure.bounds.max - plan.structure.bounds.min;
  const int want = static_cast<int>(std::lround(per_100m2 * size.x() * size.y() / 100.0));
  std::vector<Segment> obstacles = world->walls;
  obstacles.insert(obstacles.end(), world->glass.begin(), world->glass.end());
  for (const Segment& s : door_leaves(plan)) obstacles.push_back(s);
  int placed = 0;
  for (int attempt = 0; attempt < 40 * want && placed < want; ++attempt) {
    const Segment& e = edges[rng.uniform_index(static_cast<std::uint32_t>(edges.size()))];
    const double along = rng.uniform01();
    const double side = rng.uniform01() < 0.5 ? -1.0 : 1.0;
    const double off = 0.9 + 2.0 * rng.uniform01();
    const bool chair = rng.uniform01() < 0.4;
    const double size_draw = rng.uniform01();
    const double item = chair ? 0.4 + 0.3 * size_draw : 0.3 + 0.7 * size_draw;
    const double heading = rng.uniform01() * M_PI / 2;
    const Vec2 from = e.a + along * (e.b - e.a);
    const Vec2 normal = Vec2(-(e.b - e.a).y(), (e.b - e.a).x()).normalized();
    const Vec2 c = from + side * off * normal;
    if (building::clearance(Segment{from, c}, obstacles) < kObstacleGap) continue;  // seen from the route
    std::vector<Segment> outline =
        chair ? building::octagon_outline(c, item / 2) : building::box_outline(c, item, item, heading);
    if (!may_stand_in_world(outline, edges, kClutterRouteGap, obstacles, plan.structure.bounds)) continue;
    obstacles.insert(obstacles.end(), outline.begin(), outline.end());
    world->walls.insert(world->walls.end(), outline.begin(), outline.end());
    ++placed;
  }
  return placed;
}

}  // namespace

namespace {
// The heading the drawing has turned by at `along` metres beyond the joint (linear up to far_x).
double drawn_turn(const MapDrawing& d, double along) {
  const double w = d.far_x - d.joint_x;
  return w > 0 ? d.angle_rad * std::min(1.0, along / w) : d.angle_rad;
}
}  // namespace

Vec2 MapDrawing::point(const Vec2& p) const {
  if (!bent || p.x() <= joint_x) return p;
  // The line through the pivot along x is drawn as an arc whose heading grows with the distance
  // along it (∫ (cos κu, sin κu) du, then straight beyond far_x); a point off the line keeps its
  // offset across it, turned with the arc. So the drawing turns by drawn_turn() locally (no shear),
  // with a scale error along x of κ × the offset from the line (capped at 0.5 %, kMaxMapStrain).
  const double w = far_x - joint_x, along = p.x() - joint_x, s = std::min(along, w);
  const double k = w > 0 ? angle_rad / w : 0;
  Vec2 on_line = std::fabs(k) > 1e-12 ? Vec2(std::sin(k * s) / k, (1 - std::cos(k * s)) / k) : Vec2(s, 0);
  const double a = drawn_turn(*this, along);
  on_line += (along - s) * Vec2(std::cos(a), std::sin(a));
  const double off = p.y() - pivot.y();
  return pivot + on_line + off * Vec2(-std::sin(a), std::cos(a));
}

void MapDrawing::pose(double x, double y, double theta, double* mx, double* my, double* mtheta) const {
  const Vec2 m = point(Vec2(x, y));
  *mx = m.x();
  *my = m.y();
  *mtheta = bent && x > joint_x ? theta + drawn_turn(*this, x - joint_x) : theta;
}

std::string MapChangeOptions::validate() const {
  if (!(clutter_per_100m2 >= 0 && clutter_per_100m2 <= 50)) return "map change clutter_per_100m2 must be in [0, 50]";
  if (!(door_flip_fraction >= 0 && door_flip_fraction <= 1)) return "map change door_flip_fraction must be in [0, 1]";
  if (!(rearranged_fraction >= 0 && rearranged_fraction <= 1))
    return "map change rearranged_fraction must be in [0, 1]";
  if (!(std::fabs(distortion_deg) <= 5)) return "map change distortion_deg must be in [-5, 5]";
  return {};
}

bool apply_map_changes(const BuildingPlan& plan, const MapChangeOptions& opt, std::uint64_t seed, World* world,
                       World* map, MapChangeReport* report, std::string* err) {
  const std::string bad = opt.validate();
  if (!bad.empty()) {
    if (err) *err = bad;
    return false;
  }
  report->clutter_items = report->doors_flipped = report->furniture_moved = 0;
  report->distorted = false;
  report->distorted_region = Box{Vec2::Zero(), Vec2::Zero()};  // empty unless distorted
  report->pivot = Vec2::Zero();
  report->drawing = MapDrawing{};
  *map = compose_world(plan);
  if (opt.distortion_deg != 0) {
    fw::RandomStream rng(seed, kDistortStream);
    const Box& b = plan.structure.bounds;
    const double cut = b.min.x() + (b.max.x() - b.min.x()) * (0.4 + 0.3 * rng.uniform01());
    report->pivot = Vec2(cut, 0.5 * (b.min.y() + b.max.y()));
    report->distorted = true;
    report->distorted_region = Box{Vec2(cut, b.min.y()), b.max};
    MapDrawing& d = report->drawing;
    d.bent = true;
    d.pivot = report->pivot;
    d.joint_x = cut;
    d.far_x = b.max.x();
    // The bend's scale error along x is κ × the offset from the pivot's line (MapDrawing::point);
    // the angle is capped so that it stays ≤ kMaxMapStrain everywhere in the building.
    const double half_height = std::max(b.max.y() - report->pivot.y(), report->pivot.y() - b.min.y());
    const double cap = kMaxMapStrain * (d.far_x - d.joint_x) / std::max(half_height, 1.0);
    d.angle_rad = std::copysign(std::min(std::fabs(opt.distortion_deg) * M_PI / 180.0, cap), opt.distortion_deg);
    distort_map(map, d);
  }
  BuildingPlan seen = plan;
  report->doors_flipped = opt.door_flip_fraction > 0 ? flip_doors(&seen, opt.door_flip_fraction, seed) : 0;
  report->furniture_moved = rearrange_furniture(&seen, opt.rearranged_fraction, seed);
  *world = compose_world(seen);
  report->clutter_items = add_clutter(seen, opt.clutter_per_100m2, seed, world);
  return true;
}

}  // namespace sim
