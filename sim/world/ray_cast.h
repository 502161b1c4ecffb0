// Ray casting against a World: exact intersections with wall segments and people (circles).
// Used by the laser model and by tests with known geometry.
#pragma once

#include <cstddef>
#include <vector>

#include "sim/world/world.h"

namespace sim {

struct RayHit {
  bool hit = false;
  double range = 0;  // distance to the first surface (≤ max_range when hit)
  bool person = false;
  // The first surface is a glass pane (World::glass): then behind_* is the first surface that is
  // not glass behind it (behind_hit false when none within max_range).
  bool glass = false;
  bool behind_hit = false;
  double behind_range = 0;
};

// A uniform grid (~1 m cells) over a World's walls and glass, each cell listing the segments that
// pass within 1 µm of it, so that a ray tests only the segments of the cells it crosses (walked in
// order, Amanatides & Woo) and stops at the first cell whose far side lies beyond its nearest wall.
// A generated 150 × 100 m building has thousands of segments; the answers are exactly those of the
// brute-force loop (same intersection function, the cells only skip segments that cannot be nearer).
struct WorldIndex {
  WorldIndex() = default;
  explicit WorldIndex(const World& world, double cell_m = 1.0);
  double x0 = 0, y0 = 0, cell = 1;  // grid origin and cell size, m
  int nx = 0, ny = 0;
  std::size_t wall_count = 0, glass_count = 0;  // ids < wall_count are walls, the rest glass
  std::vector<int> cell_start;                  // CSR: cell c lists ids[cell_start[c] .. cell_start[c+1])
  std::vector<int> ids;
};

// First surface along origin + t·(cos a, sin a), 0 < t ≤ max_range, at time t_s (people move).
// Static walls only when include_people is false. Every segment is tested; a caller casting many
// rays in one large world builds a WorldIndex once and uses the overload below (SyntheticRun).
RayHit cast_ray(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                bool include_people = true);
// The same through an index built from this world.
RayHit cast_ray(const World& world, const WorldIndex& index, const Vec2& origin, double angle, double max_range,
                double t_s, bool include_people = true);
// Every segment tested: the oracle of the indexed cast in tests.
RayHit cast_ray_brute_force(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                            bool include_people = true);

// Distance along a ray to a segment (∞ if it misses); exposed for tests.
double ray_segment_distance(const Vec2& origin, const Vec2& dir, const Segment& s);
// Distance along a ray to a circle's boundary from outside (∞ if it misses or the origin is inside).
double ray_circle_distance(const Vec2& origin, const Vec2& dir, const Vec2& centre, double radius);

}  // namespace sim
