// Ray casting against a World: exact intersections with wall segments and people (circles).
// Used by the laser model and by tests with known geometry.
#pragma once

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

// First surface along origin + t·(cos a, sin a), 0 < t ≤ max_range, at time t_s (people move).
// Static walls only when include_people is false.
RayHit cast_ray(const World& world, const Vec2& origin, double angle, double max_range, double t_s,
                bool include_people = true);

// Distance along a ray to a segment (∞ if it misses); exposed for tests.
double ray_segment_distance(const Vec2& origin, const Vec2& dir, const Segment& s);
// Distance along a ray to a circle's boundary from outside (∞ if it misses or the origin is inside).
double ray_circle_distance(const Vec2& origin, const Vec2& dir, const Vec2& centre, double radius);

}  // namespace sim
