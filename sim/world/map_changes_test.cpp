#include "sim/world/map_changes.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sim/world/building_geometry.h"

namespace sim {
namespace {

BuildingPlan plan_of(BuildingFamily f, std::uint64_t seed, double closed_doors = 0.2) {
  BuildingOptions opt;
  opt.family = f;
  opt.closed_door_fraction = closed_doors;
  BuildingPlan plan;
  std::string err;
  EXPECT_TRUE(generate_building(opt, seed, &plan, &err)) << err;
  return plan;
}

struct Changed {
  World world, map;
  MapChangeReport report;
};

Changed apply(const BuildingPlan& plan, const MapChangeOptions& opt, std::uint64_t seed) {
  Changed c;
  std::string err;
  EXPECT_TRUE(apply_map_changes(plan, opt, seed, &c.world, &c.map, &c.report, &err)) << err;
  return c;
}

bool same_segments(const std::vector<Segment>& a, const std::vector<Segment>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i) {
    if (a[i].a != b[i].a || a[i].b != b[i].b) return false;
  }
  return true;
}

bool same_route(const RouteGraph& a, const RouteGraph& b) {
  return a.nodes == b.nodes && a.adjacent == b.adjacent && a.kinds == b.kinds;
}

// The world's route keeps ≥ 0.4 m from everything in the world (moved furniture and clutter too).
void expect_route_clear(const World& w) {
  std::vector<Segment> obstacles = w.walls;
  obstacles.insert(obstacles.end(), w.glass.begin(), w.glass.end());
  for (const Segment& e : building::route_edges(w.route)) {
    EXPECT_GE(building::clearance(e, obstacles), building::kRouteClearance) << w.name;
  }
}

TEST(MapChanges, CleanOptionsGiveTheMapAsTheWorld) {
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    const BuildingPlan plan = plan_of(static_cast<BuildingFamily>(f), 3);
    const Changed c = apply(plan, MapChangeOptions{}, 9);
    EXPECT_TRUE(same_segments(c.world.walls, c.map.walls));
    EXPECT_TRUE(same_segments(c.world.glass, c.map.glass));
    EXPECT_TRUE(same_route(c.world.route, c.map.route));
    EXPECT_TRUE(same_segments(c.map.walls, compose_world(plan).walls));
    EXPECT_EQ(c.report.clutter_items + c.report.doors_flipped + c.report.furniture_moved, 0);
    EXPECT_FALSE(c.report.distorted);
  }
}

MapChangeOptions everything() {
  MapChangeOptions opt;
  opt.clutter_per_100m2 = 2;
  opt.door_flip_fraction = 0.3;
  opt.rearranged_fraction = 0.2;
  opt.distortion_deg = 0.8;
  return opt;
}

TEST(MapChanges, SameSeedSameChanges) {
  const BuildingPlan plan = plan_of(BuildingFamily::kOffice, 5);
  const Changed a = apply(plan, everything(), 21), b = apply(plan, everything(), 21), c = apply(plan, everything(), 22);
  EXPECT_TRUE(same_segments(a.world.walls, b.world.walls));
  EXPECT_TRUE(same_segments(a.map.walls, b.map.walls));
  EXPECT_TRUE(same_route(a.world.route, b.world.route));
  EXPECT_EQ(a.report.clutter_items, b.report.clutter_items);
  EXPECT_EQ(a.report.pivot, b.report.pivot);
  EXPECT_FALSE(same_segments(a.world.walls, c.world.walls));
}

TEST(MapChanges, ClutterStaysOffTheRouteAndOutOfWalls) {
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    const BuildingPlan plan = plan_of(static_cast<BuildingFamily>(f), 6);
    MapChangeOptions opt;
    opt.clutter_per_100m2 = 3;
    const Changed c = apply(plan, opt, 4);
    const Vec2 size = plan.structure.bounds.max - plan.structure.bounds.min;
    SCOPED_TRACE(c.world.name);
    // Most of the asked-for clutter finds a place (the rest of the tries met walls or the route).
    EXPECT_GE(c.report.clutter_items, static_cast<int>(0.5 * 3 * size.x() * size.y() / 100));
    ASSERT_GT(c.world.walls.size(), c.map.walls.size());
    EXPECT_TRUE(same_route(c.world.route, c.map.route));
    const std::vector<Segment> clutter(c.world.walls.begin() + static_cast<long>(c.map.walls.size()),
                                       c.world.walls.end());
    const std::vector<Segment> edges = building::route_edges(plan.structure.route);
    for (const Segment& s : clutter) EXPECT_GE(building::clearance(s, edges), 0.6);
    std::vector<Segment> fixed = c.map.walls;
    fixed.insert(fixed.end(), c.map.glass.begin(), c.map.glass.end());
    for (const Segment& s : clutter) EXPECT_GT(building::clearance(s, fixed), 0.0);
    expect_route_clear(c.world);
  }
}

TEST(MapChanges, FlippedDoorsChangeTheWorldsRoute) {
  const BuildingPlan plan = plan_of(BuildingFamily::kOffice, 8, 0.0);  // all open in the map
  MapChangeOptions opt;
  opt.door_flip_fraction = 1;
  const Changed c = apply(plan, opt, 2);
  EXPECT_EQ(c.report.doors_flipped, static_cast<int>(plan.doors.size()));
  EXPECT_EQ(c.world.walls.size(), c.map.walls.size() + plan.doors.size());  // every leaf now closed
  int rooms_world = 0, rooms_map = 0;
  for (int k : c.world.route.kinds) rooms_world += k == RouteGraph::kRoom ? 1 : 0;
  for (int k : c.map.route.kinds) rooms_map += k == RouteGraph::kRoom ? 1 : 0;
  EXPECT_EQ(rooms_world, 0);
  EXPECT_EQ(rooms_map, static_cast<int>(plan.doors.size()));
  // And the other way: closed in the map, open in the world, the world's route goes through.
  const BuildingPlan closed = plan_of(BuildingFamily::kOffice, 8, 1.0);
  const Changed d = apply(closed, opt, 2);
  EXPECT_EQ(d.world.route.nodes.size(), c.map.route.nodes.size());
  expect_route_clear(c.world);
  expect_route_clear(d.world);
}

TEST(MapChanges, RearrangedFurnitureMovesWithinOneArea) {
  for (BuildingFamily f : {BuildingFamily::kOffice, BuildingFamily::kLab, BuildingFamily::kOpenHall}) {
    const BuildingPlan plan = plan_of(f, 4);
    MapChangeOptions opt;
    opt.rearranged_fraction = 0.2;
    const Changed c = apply(plan, opt, 5);
    SCOPED_TRACE(c.world.name);
    EXPECT_GE(c.report.furniture_moved, static_cast<int>(0.1 * static_cast<double>(plan.furniture.size())));
    ASSERT_EQ(c.world.walls.size(), c.map.walls.size());
    // Each moved piece's outline left its place: four (or eight) segments not in the map.
    int changed = 0;
    for (size_t i = 0; i < c.world.walls.size(); ++i) {
      changed += c.world.walls[i].a != c.map.walls[i].a || c.world.walls[i].b != c.map.walls[i].b ? 1 : 0;
    }
    EXPECT_GE(changed, 4 * c.report.furniture_moved);
    EXPECT_LE(changed, 8 * c.report.furniture_moved);
    expect_route_clear(c.world);
  }
}

TEST(MapChanges, DistortionBendsOneWingOfTheMapOnly) {
  const BuildingPlan plan = plan_of(BuildingFamily::kMultiWing, 2);
  MapChangeOptions opt;
  opt.distortion_deg = 1.0;
  const Changed c = apply(plan, opt, 3);
  ASSERT_TRUE(c.report.distorted);
  const MapDrawing& d = c.report.drawing;
  ASSERT_TRUE(d.bent);
  const double cut = d.joint_x;
  EXPECT_GT(cut, plan.structure.bounds.min.x());
  EXPECT_LT(cut, plan.structure.bounds.max.x());
  EXPECT_TRUE(same_segments(c.world.walls, compose_world(plan).walls));  // the world is as built
  // Walls left of the joint are drawn as built; every map wall piece beyond it lies on the drawing
  // of a world wall (its end-points are drawn points of the world, ≤ 1 m apart).
  int bent = 0;
  for (const Segment& m : c.map.walls) {
    if (std::max(m.a.x(), m.b.x()) <= cut) continue;
    ++bent;
    EXPECT_LE((m.b - m.a).norm(), 1.0 + 0.005 + 1e-6);  // 1 m pieces, drawn with the bend's scale error (≤ 0.5 %)
  }
  EXPECT_GT(bent, 10);
  // The drawing: identity before the joint, continuous across it, and locally a turn by the angle
  // reached there (a short cross drawn turned, its arms kept at right angles), the full angle at
  // the far end.
  const Vec2 at_joint(cut, d.pivot.y() + 30);
  EXPECT_EQ(d.point(Vec2(cut - 1, 5)), Vec2(cut - 1, 5));
  EXPECT_LT((d.point(at_joint + Vec2(0.01, 0)) - (at_joint + Vec2(0.01, 0))).norm(), 1e-3);
  auto turn_of = [&](const Vec2& p, const Vec2& u) {
    const Vec2 g = d.point(p + 0.05 * u) - d.point(p - 0.05 * u);
    return std::atan2(u.x() * g.y() - u.y() * g.x(), u.dot(g)) * 180 / M_PI;
  };
  const Vec2 far(d.far_x - 0.1, d.pivot.y() + 10), mid(0.5 * (cut + d.far_x), d.pivot.y() - 20);
  const double full = d.angle_rad * 180 / M_PI;
  EXPECT_GT(full, 0.1);
  EXPECT_LE(full, 1.0);
  EXPECT_NEAR(turn_of(far, Vec2(1, 0)), full, 0.01);
  EXPECT_NEAR(turn_of(far, Vec2(0, 1)), full, 0.01);
  EXPECT_NEAR(turn_of(mid, Vec2(1, 0)), 0.5 * full, 0.01);
  EXPECT_NEAR(turn_of(mid, Vec2(0, 1)), 0.5 * full, 0.01);
  // The local scale error stays ≤ 0.5 % everywhere, also at the building's far corners.
  for (const Vec2& p : {Vec2(0.5 * (cut + d.far_x), plan.structure.bounds.max.y()), Vec2(d.far_x - 1, plan.structure.bounds.min.y())}) {
    const double drawn_len = (d.point(p + Vec2(0.5, 0)) - d.point(p - Vec2(0.5, 0))).norm();
    EXPECT_NEAR(drawn_len, 1.0, 0.005 + 1e-6);
  }
  // A robot's pose is drawn with its heading turned as the map turns around it.
  double mx, my, mt;
  d.pose(mid.x(), mid.y(), 0.3, &mx, &my, &mt);
  EXPECT_NEAR((mt - 0.3) * 180 / M_PI, 0.5 * full, 1e-6);
  EXPECT_NEAR((Vec2(mx, my) - d.point(mid)).norm(), 0, 1e-12);
  d.pose(cut - 2, d.pivot.y(), 0.3, &mx, &my, &mt);
  EXPECT_DOUBLE_EQ(mt, 0.3);
}

TEST(MapChanges, BadOptionsAreRefused) {
  MapChangeOptions opt;
  opt.door_flip_fraction = -0.1;
  EXPECT_FALSE(opt.validate().empty());
  opt = {};
  opt.distortion_deg = 20;
  World w, m;
  MapChangeReport r;
  std::string err;
  EXPECT_FALSE(apply_map_changes(plan_of(BuildingFamily::kLab, 1), opt, 1, &w, &m, &r, &err));
  EXPECT_NE(err.find("distortion_deg"), std::string::npos);
  EXPECT_TRUE(MapChangeOptions{}.clean());
}

}  // namespace
}  // namespace sim
