#include "sim/world/building_generator.h"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>

#include "firmware/base/rng.h"
#include "firmware/map/global_map.h"
#include "sim/world/building_geometry.h"
#include "sim/world/raster.h"
#include "sim/world/ray_cast.h"

namespace sim {
namespace {

BuildingPlan generate(BuildingFamily f, std::uint64_t seed, BuildingOptions opt = {}) {
  opt.family = f;
  BuildingPlan plan;
  std::string err;
  EXPECT_TRUE(generate_building(opt, seed, &plan, &err)) << err;
  return plan;
}

// Every node reached from node 0.
bool connected(const RouteGraph& g) {
  if (g.nodes.empty()) return false;
  std::vector<bool> seen(g.nodes.size(), false);
  std::vector<int> stack{0};
  seen[0] = true;
  size_t count = 0;
  while (!stack.empty()) {
    const int u = stack.back();
    stack.pop_back();
    ++count;
    for (int v : g.adjacent[u]) {
      if (!seen[v]) {
        seen[v] = true;
        stack.push_back(v);
      }
    }
  }
  return count == g.nodes.size();
}

int count_kind(const RouteGraph& g, int kind) {
  int n = 0;
  for (int k : g.kinds) n += k == kind ? 1 : 0;
  return n;
}

bool corridor_family(BuildingFamily f) {
  return f == BuildingFamily::kOffice || f == BuildingFamily::kHospitalWing || f == BuildingFamily::kLab;
}

TEST(BuildingGenerator, RouteEdgesKeepClearOfEveryObstacleInEveryFamily) {
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    for (std::uint64_t seed = 1; seed <= 5; ++seed) {
      const BuildingPlan plan = generate(static_cast<BuildingFamily>(f), seed);
      const World w = compose_world(plan);
      SCOPED_TRACE(w.name);
      std::vector<Segment> obstacles = w.walls;
      obstacles.insert(obstacles.end(), w.glass.begin(), w.glass.end());
      ASSERT_GE(w.route.nodes.size(), 8u);
      EXPECT_TRUE(connected(w.route));
      EXPECT_TRUE(connected(plan.structure.route));
      for (const Vec2& n : w.route.nodes) EXPECT_TRUE(w.bounds.contains(n)) << n.transpose();
      for (const Segment& e : building::route_edges(w.route)) {
        EXPECT_GE(building::clearance(e, obstacles), building::kRouteClearance)
            << e.a.transpose() << " → " << e.b.transpose();
      }
    }
  }
}

TEST(BuildingGenerator, EveryRoomIsReachedWhenItsDoorIsOpen) {
  BuildingOptions opt;
  opt.closed_door_fraction = 0;
  for (BuildingFamily f : {BuildingFamily::kOffice, BuildingFamily::kHospitalWing, BuildingFamily::kLab}) {
    for (std::uint64_t seed = 1; seed <= 3; ++seed) {
      const BuildingPlan plan = generate(f, seed, opt);
      const World w = compose_world(plan);
      // One door per room, and a room node behind every door.
      EXPECT_EQ(count_kind(w.route, RouteGraph::kRoom), static_cast<int>(plan.doors.size())) << w.name;
      EXPECT_EQ(count_kind(w.route, RouteGraph::kDoorway), static_cast<int>(plan.doors.size())) << w.name;
    }
  }
  // All doors closed: the rooms drop out of the route, the corridors stay.
  opt.closed_door_fraction = 1;
  const World closed = compose_world(generate(BuildingFamily::kOffice, 2, opt));
  EXPECT_EQ(count_kind(closed.route, RouteGraph::kRoom), 0);
  EXPECT_TRUE(connected(closed.route));
  EXPECT_GE(closed.route.nodes.size(), 4u);
}

TEST(BuildingGenerator, SameSeedSamePlanOtherSeedOtherPlan) {
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    const auto fam = static_cast<BuildingFamily>(f);
    const BuildingPlan a = generate(fam, 7), b = generate(fam, 7), c = generate(fam, 8);
    const World wa = compose_world(a), wb = compose_world(b), wc = compose_world(c);
    ASSERT_EQ(wa.walls.size(), wb.walls.size());
    for (size_t i = 0; i < wa.walls.size(); ++i) {
      ASSERT_EQ(wa.walls[i].a, wb.walls[i].a);
      ASSERT_EQ(wa.walls[i].b, wb.walls[i].b);
    }
    ASSERT_EQ(wa.glass.size(), wb.glass.size());
    ASSERT_EQ(a.doors.size(), b.doors.size());
    for (size_t i = 0; i < a.doors.size(); ++i) EXPECT_EQ(a.doors[i].closed, b.doors[i].closed);
    ASSERT_EQ(wa.route.nodes.size(), wb.route.nodes.size());
    for (size_t i = 0; i < wa.route.nodes.size(); ++i) {
      EXPECT_EQ(wa.route.nodes[i], wb.route.nodes[i]);
      EXPECT_EQ(wa.route.adjacent[i], wb.route.adjacent[i]);
    }
    EXPECT_EQ(wa.name, std::string("gen-") + building_family_name(fam) + "-7");
    EXPECT_TRUE(wa.walls.size() != wc.walls.size() || wa.bounds.max != wc.bounds.max) << wa.name;
  }
}

TEST(BuildingGenerator, SizesWithinRangeAndExplicitSizesHonoured) {
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    for (std::uint64_t seed = 1; seed <= 6; ++seed) {
      const Box b = generate(static_cast<BuildingFamily>(f), seed).structure.bounds;
      EXPECT_GE(b.max.x() - b.min.x(), 20.0);
      EXPECT_LE(b.max.x() - b.min.x(), 150.0);
      EXPECT_GE(b.max.y() - b.min.y(), 20.0);
      EXPECT_LE(b.max.y() - b.min.y(), 100.0);
    }
    BuildingOptions opt;
    opt.width_m = 64.5;
    opt.height_m = 41;
    const BuildingPlan plan = generate(static_cast<BuildingFamily>(f), 3, opt);
    EXPECT_EQ(plan.structure.bounds.max, Vec2(64.5, 41));
    EXPECT_TRUE(connected(compose_world(plan).route));
  }
  BuildingOptions bad;
  bad.width_m = 10;
  EXPECT_FALSE(bad.validate().empty());
  bad = {};
  bad.glass_fraction = 1.5;
  EXPECT_FALSE(bad.validate().empty());
  BuildingPlan plan;
  std::string err;
  EXPECT_FALSE(generate_building(bad, 1, &plan, &err));
  EXPECT_NE(err.find("glass_fraction"), std::string::npos);
  BuildingFamily parsed;
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    ASSERT_TRUE(parse_building_family(building_family_name(static_cast<BuildingFamily>(f)), &parsed));
    EXPECT_EQ(static_cast<int>(parsed), f);
  }
  EXPECT_FALSE(parse_building_family("castle", &parsed));
}

TEST(BuildingGenerator, GlassAndDoorsFollowTheirFractions) {
  BuildingOptions opt;
  opt.glass_fraction = 0;
  opt.closed_door_fraction = 0;
  const BuildingPlan clear = generate(BuildingFamily::kOffice, 4, opt);
  EXPECT_TRUE(clear.glass.empty());
  for (const Door& d : clear.doors) EXPECT_FALSE(d.closed);
  opt.glass_fraction = 0.5;
  opt.closed_door_fraction = 1;
  const BuildingPlan glassy = generate(BuildingFamily::kOffice, 4, opt);
  EXPECT_GT(glassy.glass.size(), 10u);
  for (const Door& d : glassy.doors) EXPECT_TRUE(d.closed);
  // Closed leaves are walls of the world, glass is not.
  const World w = compose_world(glassy);
  size_t furniture_segments = 0;
  for (const Furniture& f : glassy.furniture) furniture_segments += f.outline.size();
  EXPECT_EQ(w.walls.size(), glassy.structure.walls.size() + glassy.doors.size() + furniture_segments);
  EXPECT_EQ(w.glass.size(), glassy.glass.size());
}

TEST(BuildingGenerator, FamiliesLookTheirPart) {
  std::printf("%-12s %9s %6s %6s %6s %9s %6s %6s\n", "family", "size m", "walls", "glass", "doors", "furniture",
              "nodes", "rooms");
  for (int f = 0; f < kBuildingFamilyCount; ++f) {
    const auto fam = static_cast<BuildingFamily>(f);
    const BuildingPlan plan = generate(fam, 1);
    const World w = compose_world(plan);
    const Vec2 size = w.bounds.max - w.bounds.min;
    std::printf("%-12s %4.0fx%-4.0f %6zu %6zu %6zu %9zu %6zu %6d\n", building_family_name(fam), size.x(), size.y(),
                plan.structure.walls.size(), plan.glass.size(), plan.doors.size(), plan.furniture.size(),
                w.route.nodes.size(), count_kind(w.route, RouteGraph::kRoom));
    if (corridor_family(fam)) EXPECT_GE(plan.doors.size(), 6u) << w.name;
    if (fam == BuildingFamily::kWarehouse) {
      // Identical racks: every piece of furniture has the same outline, shifted.
      ASSERT_GE(plan.furniture.size(), 6u);
      const Vec2 ext0 = plan.furniture[0].outline[1].a - plan.furniture[0].outline[0].a;
      for (const Furniture& r : plan.furniture) EXPECT_LT((r.outline[1].a - r.outline[0].a - ext0).norm(), 1e-9);
    }
    if (fam == BuildingFamily::kOpenHall) EXPECT_GE(size.x(), 30.0);  // far walls beyond a 12–30 m range
  }
  // A hospital wing is long and narrow; its rooms on one side are identical.
  const Box h = generate(BuildingFamily::kHospitalWing, 1).structure.bounds;
  EXPECT_GT(h.max.x() - h.min.x(), 1.5 * (h.max.y() - h.min.y()));
}

TEST(BuildingGenerator, HospitalRoomsLookAlike) {
  BuildingOptions opt;
  opt.glass_fraction = 0;
  const BuildingPlan plan = generate(BuildingFamily::kHospitalWing, 2, opt);
  // Door leaves of one row share their width and the spacing between them repeats.
  std::vector<double> xs;
  const double y_row = plan.doors.front().leaf.a.y();
  for (const Door& d : plan.doors) {
    if (d.leaf.a.y() == y_row) xs.push_back(d.leaf.a.x());
  }
  ASSERT_GE(xs.size(), 4u);
  std::sort(xs.begin(), xs.end());
  // One room width everywhere: consecutive doors a room apart, or a room and the vertical corridor.
  const double room = xs[1] - xs[0];
  int across_corridor = 0;
  for (size_t i = 1; i < xs.size(); ++i) {
    const double gap = xs[i] - xs[i - 1];
    if (std::fabs(gap - room) > 1e-9) ++across_corridor;
  }
  EXPECT_EQ(across_corridor, 1);
  // And one furniture layout in every room.
  EXPECT_EQ(plan.furniture.size() % plan.doors.size(), 0u);
  EXPECT_GT(plan.furniture.size(), plan.doors.size());
}

TEST(RayCast, GlassReturnsThePaneAndWhatIsBehindIt) {
  World w;
  w.bounds = {Vec2(-10, -10), Vec2(10, 10)};
  add_segment(&w, 5, -1, 5, 1);
  w.glass.push_back({Vec2(2, -1), Vec2(2, 1)});
  RayHit h = cast_ray(w, Vec2(0, 0), 0.0, 20, 0);
  EXPECT_TRUE(h.hit && h.glass && h.behind_hit);
  EXPECT_NEAR(h.range, 2.0, 1e-12);
  EXPECT_NEAR(h.behind_range, 5.0, 1e-12);
  h = cast_ray(w, Vec2(0, 0), 0.0, 4, 0);  // the wall behind is out of range
  EXPECT_TRUE(h.hit && h.glass);
  EXPECT_FALSE(h.behind_hit);
  h = cast_ray(w, Vec2(3, 0), 0.0, 20, 0);  // past the pane: the wall, no glass
  EXPECT_TRUE(h.hit);
  EXPECT_FALSE(h.glass);
  EXPECT_NEAR(h.range, 2.0, 1e-12);
  h = cast_ray(w, Vec2(6, 0), M_PI, 20, 0);  // the wall first: the pane behind it is not seen
  EXPECT_FALSE(h.glass);
  EXPECT_NEAR(h.range, 1.0, 1e-12);
  // A person behind the pane is what is behind it.
  w.people.push_back(Person{{Vec2(3.5, 0), Vec2(3.5, 0.001)}, 0.25, 0.0, 0.0});
  h = cast_ray(w, Vec2(0, 0), 0.0, 20, 0);
  EXPECT_TRUE(h.glass && h.behind_hit);
  EXPECT_NEAR(h.behind_range, 3.25, 1e-9);
  EXPECT_FALSE(h.person);
}

void expect_same(const RayHit& a, const RayHit& b) {
  ASSERT_EQ(a.hit, b.hit);
  ASSERT_EQ(a.range, b.range);
  ASSERT_EQ(a.person, b.person);
  ASSERT_EQ(a.glass, b.glass);
  ASSERT_EQ(a.behind_hit, b.behind_hit);
  ASSERT_EQ(a.behind_range, b.behind_range);
}

TEST(RayCast, IndexAnswersExactlyAsTheBruteForceLoop) {
  BuildingOptions opt;
  opt.glass_fraction = 0.3;
  for (BuildingFamily f : {BuildingFamily::kOffice, BuildingFamily::kWarehouse, BuildingFamily::kMultiWing,
                           BuildingFamily::kOpenHall, BuildingFamily::kLab}) {
    opt.family = f;
    opt.width_m = 150;
    opt.height_m = 100;
    World w = compose_world(generate(f, 11, opt));
    w.people.push_back(Person{{w.route.nodes[0], w.route.nodes[w.route.adjacent[0][0]]}, 0.25, 0.8, 0.0});
    const WorldIndex index(w);
    fw::RandomStream rng(3, 0);
    for (int i = 0; i < 6000; ++i) {
      // Rays from route nodes (where a robot is), from anywhere, and from outside the building.
      const Vec2 node = w.route.nodes[rng.uniform_index(static_cast<std::uint32_t>(w.route.nodes.size()))];
      const double ux = rng.uniform01(), uy = rng.uniform01();
      const Vec2 anywhere(-5 + 160 * ux, -5 + 110 * uy);
      const Vec2 o = i % 2 == 0 ? node : anywhere;
      const double a = rng.uniform01() * 2 * M_PI;
      // Axis-parallel rays too (the grid's degenerate case).
      const double angle = i % 7 == 0 ? M_PI / 2 * (i % 4) : a;
      const double max_range = i % 3 == 0 ? 30.0 : 80.0 + 100 * rng.uniform01();
      const RayHit brute = cast_ray_brute_force(w, o, angle, max_range, 1.0);
      expect_same(cast_ray(w, index, o, angle, max_range, 1.0), brute);
      expect_same(cast_ray(w, o, angle, max_range, 1.0), brute);
      if (HasFatalFailure()) {
        ADD_FAILURE() << w.name << " ray " << i << " from " << o.transpose() << " at " << angle;
        return;
      }
    }
  }
}

TEST(RayCast, IndexSpeedUpOnALargeBuilding) {
  BuildingOptions opt;
  opt.family = BuildingFamily::kOffice;
  opt.width_m = 150;
  opt.height_m = 100;
  const World w = compose_world(generate(BuildingFamily::kOffice, 5, opt));
  const WorldIndex index(w);
  std::vector<Vec2> origins;
  for (size_t i = 0; i < w.route.nodes.size(); i += 20) origins.push_back(w.route.nodes[i]);
  auto time_casts = [&](auto cast) {
    const auto t0 = std::chrono::steady_clock::now();
    double sum = 0;
    int n = 0;
    for (const Vec2& o : origins) {
      for (int k = 0; k < 361; ++k, ++n) sum += cast(o, k * M_PI / 180.0 - M_PI / 2).range;
    }
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    return std::make_pair(s / n * 1e6, sum);
  };
  const auto brute = time_casts([&](const Vec2& o, double a) { return cast_ray_brute_force(w, o, a, 30.0, 0); });
  const auto indexed = time_casts([&](const Vec2& o, double a) { return cast_ray(w, index, o, a, 30.0, 0); });
  EXPECT_EQ(brute.second, indexed.second);
  std::printf("ray cast on %s (%zu segments): brute force %.2f us/ray, indexed %.3f us/ray, speed-up %.0fx\n",
              w.name.c_str(), w.walls.size() + w.glass.size(), brute.first, indexed.first, brute.first / indexed.first);
}

TEST(Raster, GlassIsDrawnLikeWalls) {
  World w;
  w.bounds = {Vec2(0, 0), Vec2(10, 10)};
  add_rect(&w, 0, 0, 10, 10);
  w.glass.push_back({Vec2(5, 1), Vec2(5, 9)});
  OccupancyGrid g;
  std::string err;
  ASSERT_TRUE(rasterize_world(w, RasterOptions{}, &g, &err)) << err;
  std::int32_t cx, cy;
  ASSERT_TRUE(g.geometry.world_to_cell(5.0f, 5.0f, &cx, &cy));
  EXPECT_EQ(g.cells[g.geometry.index(cx, cy)], fw::kCellOccupied);
}

}  // namespace
}  // namespace sim
